//! Named layouts: constructors that write a quad X, quad +, hexa, octo or coaxial vehicle in one
//! line, and [`Layout::recognise`], which names the layout a geometry is.

use std::f64::consts::PI;

use serde::Serialize;

use super::{CommandMap, Rotor, Spin, VehicleDescription};
use crate::error::Result;

/// Rotors closer than this fraction of the mean arm (horizontally) share a station (coaxial).
const SAME_STATION: f64 = 0.01;
/// Arms may differ by this fraction of their mean and still be equal.
const ARM_TOLERANCE: f64 = 0.02;
/// Azimuths may be off by this much (radians, 2°) and still be evenly spaced.
const ANGLE_TOLERANCE: f64 = 2.0 * PI / 180.0;

/// The layout a geometry is (rotors thrusting up, arms equal, evenly spaced, spins alternating
/// around the ring or opposite within a coaxial pair).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Layout {
    /// Four rotors at ±45° and ±135° from the nose.
    QuadX,
    /// Four rotors on the body axes.
    QuadPlus,
    /// Four rotors, one per quadrant, in mirror pairs left and right, diagonal rotors spinning
    /// the same way, the front and rear arms unequal (PX4's "Quadrotor Wide", the 3DR Iris).
    QuadXUnequalArms,
    HexaX,
    HexaPlus,
    OctoX,
    OctoPlus,
    /// Pairs of opposite-spinning rotors on `arms` evenly spaced arms (Y6: 3, X8: 4).
    Coaxial {
        arms: usize,
    },
    Unrecognised {
        rotors: usize,
    },
}

impl std::fmt::Display for Layout {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::QuadX => write!(f, "quad X"),
            Self::QuadPlus => write!(f, "quad +"),
            Self::QuadXUnequalArms => write!(f, "quad X with unequal front and rear arms"),
            Self::HexaX => write!(f, "hexa X"),
            Self::HexaPlus => write!(f, "hexa +"),
            Self::OctoX => write!(f, "octo X"),
            Self::OctoPlus => write!(f, "octo +"),
            Self::Coaxial { arms } => write!(f, "coaxial: {arms} arms of two rotors"),
            Self::Unrecognised { rotors } => write!(f, "unrecognised: {rotors} rotors"),
        }
    }
}

/// Rotors at one place in the x-y plane (one, or a coaxial pair).
struct Station {
    x: f64,
    y: f64,
    spins: Vec<Spin>,
}

impl Layout {
    /// The layout of `vehicle`'s geometry (positions relative to the centre of mass).
    pub fn recognise(vehicle: &VehicleDescription) -> Self {
        let unrecognised = Self::Unrecognised {
            rotors: vehicle.rotors.len(),
        };
        let vertical = vehicle
            .rotors
            .iter()
            .all(|r| r.axis[2] >= ANGLE_TOLERANCE.cos());
        let arms = vehicle.arm_lengths_m();
        let mean_arm = arms.iter().sum::<f64>() / arms.len() as f64;
        if !vertical || mean_arm <= 0.0 {
            return unrecognised;
        }
        let stations = stations(vehicle, mean_arm);
        let sizes: Vec<usize> = stations.iter().map(|s| s.spins.len()).collect();
        if sizes.iter().all(|&s| s == 2) {
            let opposite = stations.iter().all(|s| s.spins[0] != s.spins[1]);
            return match opposite && ring_offset(&stations).is_some() && stations.len() >= 2 {
                true => Self::Coaxial {
                    arms: stations.len(),
                },
                false => unrecognised,
            };
        }
        if sizes.iter().any(|&s| s != 1) {
            return unrecognised;
        }
        let Some(offset) = ring_offset(&stations) else {
            return match quad_x_unequal(&stations) {
                true => Self::QuadXUnequalArms,
                false => unrecognised,
            };
        };
        let n = stations.len();
        let step = 2.0 * PI / n as f64;
        let plus = offset.abs() < ANGLE_TOLERANCE;
        let cross = (offset - step / 2.0).abs() < ANGLE_TOLERANCE;
        match (n, plus, cross) {
            (4, true, _) => Self::QuadPlus,
            (4, _, true) => Self::QuadX,
            (6, true, _) => Self::HexaPlus,
            (6, _, true) => Self::HexaX,
            (8, true, _) => Self::OctoPlus,
            (8, _, true) => Self::OctoX,
            _ => unrecognised,
        }
    }
}

fn stations(vehicle: &VehicleDescription, mean_arm: f64) -> Vec<Station> {
    let mut stations: Vec<Station> = Vec::new();
    for (rotor, r) in vehicle.rotors.iter().zip(vehicle.lever_arms_m()) {
        match stations
            .iter_mut()
            .find(|s| (s.x - r[0]).hypot(s.y - r[1]) < SAME_STATION * mean_arm)
        {
            Some(station) => station.spins.push(rotor.spin),
            None => stations.push(Station {
                x: r[0],
                y: r[1],
                spins: vec![rotor.spin],
            }),
        }
    }
    stations
}

/// For stations on one circle, evenly spaced, with spins alternating around it (single rotors)
/// or any (pairs): the smallest azimuth from the nose modulo the spacing, radians.
fn ring_offset(stations: &[Station]) -> Option<f64> {
    let n = stations.len();
    let radii: Vec<f64> = stations.iter().map(|s| s.x.hypot(s.y)).collect();
    let mean = radii.iter().sum::<f64>() / n as f64;
    if radii
        .iter()
        .any(|r| (r - mean).abs() > ARM_TOLERANCE * mean)
    {
        return None;
    }
    let mut order: Vec<(f64, &Station)> = stations
        .iter()
        .map(|s| (s.y.atan2(s.x).rem_euclid(2.0 * PI), s))
        .collect();
    order.sort_by(|a, b| a.0.total_cmp(&b.0));
    let step = 2.0 * PI / n as f64;
    for k in 0..n {
        let (angle, station) = order[k];
        let (next_angle, next) = order[(k + 1) % n];
        let gap = (next_angle - angle).rem_euclid(2.0 * PI);
        if (gap - step).abs() > ANGLE_TOLERANCE && n > 1 {
            return None;
        }
        if station.spins.len() == 1 && station.spins[0] == next.spins[0] {
            return None;
        }
    }
    let offset = order[0].0.rem_euclid(step);
    // An offset just under a full step is one just over zero.
    Some(if step - offset < ANGLE_TOLERANCE {
        offset - step
    } else {
        offset
    })
}

/// Four single rotors, one per quadrant, in left/right mirror pairs, diagonals alike in spin.
fn quad_x_unequal(stations: &[Station]) -> bool {
    if stations.len() != 4 {
        return false;
    }
    let scale = stations.iter().map(|s| s.x.hypot(s.y)).fold(0.0, f64::max);
    let tolerance = ARM_TOLERANCE * scale;
    let find = |front: bool, left: bool| {
        let matching: Vec<&Station> = stations
            .iter()
            .filter(|s| (s.x > tolerance) == front && (s.x < -tolerance) != front)
            .filter(|s| (s.y > tolerance) == left && (s.y < -tolerance) != left)
            .collect();
        (matching.len() == 1).then(|| matching[0])
    };
    let (Some(fl), Some(fr), Some(rl), Some(rr)) = (
        find(true, true),
        find(true, false),
        find(false, true),
        find(false, false),
    ) else {
        return false;
    };
    let mirrored =
        |a: &Station, b: &Station| (a.x - b.x).abs() <= tolerance && (a.y + b.y).abs() <= tolerance;
    mirrored(fl, fr)
        && mirrored(rl, rr)
        && fl.spins[0] == rr.spins[0]
        && fr.spins[0] == rl.spins[0]
        && fl.spins[0] != fr.spins[0]
}

impl VehicleDescription {
    /// A quad X in PX4's order: front right and rear left counter-clockwise, front left and rear
    /// right clockwise; each rotor `arm_m` from the centre; PX4's linear command map.
    pub fn quad_x(arm_m: f64, thrust_coefficient_n: f64, km: f64) -> Result<Self> {
        let d = arm_m / 2f64.sqrt();
        let placed = [
            ([d, -d], Spin::CounterClockwise),
            ([-d, d], Spin::CounterClockwise),
            ([d, d], Spin::Clockwise),
            ([-d, -d], Spin::Clockwise),
        ];
        Self::placed("quad X", &placed, thrust_coefficient_n, km)
    }

    /// A quad + in PX4's order: right and left counter-clockwise, front and rear clockwise.
    pub fn quad_plus(arm_m: f64, thrust_coefficient_n: f64, km: f64) -> Result<Self> {
        let a = arm_m;
        let placed = [
            ([0.0, -a], Spin::CounterClockwise),
            ([0.0, a], Spin::CounterClockwise),
            ([a, 0.0], Spin::Clockwise),
            ([-a, 0.0], Spin::Clockwise),
        ];
        Self::placed("quad +", &placed, thrust_coefficient_n, km)
    }

    /// A hexa X: six rotors from 30° left of the nose, counter-clockwise seen from above,
    /// alternating spin (the first counter-clockwise).
    pub fn hexa_x(arm_m: f64, thrust_coefficient_n: f64, km: f64) -> Result<Self> {
        Self::ring("hexa X", 6, PI / 6.0, arm_m, thrust_coefficient_n, km)
    }

    /// A hexa +: as [`VehicleDescription::hexa_x`] with the first rotor on the nose.
    pub fn hexa_plus(arm_m: f64, thrust_coefficient_n: f64, km: f64) -> Result<Self> {
        Self::ring("hexa +", 6, 0.0, arm_m, thrust_coefficient_n, km)
    }

    /// An octo X: eight rotors from 22.5° left of the nose, alternating spin.
    pub fn octo_x(arm_m: f64, thrust_coefficient_n: f64, km: f64) -> Result<Self> {
        Self::ring("octo X", 8, PI / 8.0, arm_m, thrust_coefficient_n, km)
    }

    /// An octo +: as [`VehicleDescription::octo_x`] with the first rotor on the nose.
    pub fn octo_plus(arm_m: f64, thrust_coefficient_n: f64, km: f64) -> Result<Self> {
        Self::ring("octo +", 8, 0.0, arm_m, thrust_coefficient_n, km)
    }

    /// `arms` arms (3: Y6, 4: X8) from half a spacing left of the nose, each with an upper rotor
    /// `separation_m / 2` above the arm and a lower one below, spinning opposite ways (the upper
    /// counter-clockwise on even arms); rotors listed arm by arm, upper first.
    pub fn coaxial(
        arms: usize,
        arm_m: f64,
        separation_m: f64,
        thrust_coefficient_n: f64,
        km: f64,
    ) -> Result<Self> {
        let step = 2.0 * PI / arms as f64;
        let mut rotors = Vec::new();
        for k in 0..arms {
            let angle = step / 2.0 + k as f64 * step;
            let (x, y) = (arm_m * angle.cos(), arm_m * angle.sin());
            let upper = alternating(k);
            for (z, spin) in [
                (separation_m / 2.0, upper),
                (-separation_m / 2.0, upper.reversed()),
            ] {
                rotors.push(Rotor::upright([x, y, z], spin, thrust_coefficient_n, km));
            }
        }
        Self::new(
            &format!("coaxial, {arms} arms"),
            rotors,
            CommandMap::px4(0.0),
            [0.0; 3],
        )
    }

    /// The same vehicle with another command map.
    pub fn with_command_map(mut self, command_map: CommandMap) -> Result<Self> {
        self.command_map = command_map;
        self.check()?;
        Ok(self)
    }

    pub(super) fn ring(
        name: &str,
        n: usize,
        first: f64,
        arm_m: f64,
        ct: f64,
        km: f64,
    ) -> Result<Self> {
        let placed: Vec<([f64; 2], Spin)> = (0..n)
            .map(|k| {
                let angle = first + k as f64 * 2.0 * PI / n as f64;
                ([arm_m * angle.cos(), arm_m * angle.sin()], alternating(k))
            })
            .collect();
        Self::placed(name, &placed, ct, km)
    }

    pub(super) fn placed(
        name: &str,
        placed: &[([f64; 2], Spin)],
        ct: f64,
        km: f64,
    ) -> Result<Self> {
        let rotors = placed
            .iter()
            .map(|&([x, y], spin)| Rotor::upright([x, y, 0.0], spin, ct, km))
            .collect();
        Self::new(name, rotors, CommandMap::px4(0.0), [0.0; 3])
    }
}

fn alternating(k: usize) -> Spin {
    match k % 2 {
        0 => Spin::CounterClockwise,
        _ => Spin::Clockwise,
    }
}
