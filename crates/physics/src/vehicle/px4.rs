//! A vehicle description from PX4's control-allocation parameters (`CA_ROTOR_COUNT`,
//! `CA_ROTORi_PX/PY/PZ`, `CA_ROTORi_KM`, `CA_ROTORi_CT`, `CA_ROTORi_AX/AY/AZ`, `THR_MDL_FAC`), and
//! what a log's airframe section says ([`inspect_airframe`]): the layout, the coefficients, the
//! allocation's rank, and whether the geometry is only the airframe's defaults.
//!
//! PX4's body frame is FRD; a position or axis `(x, y, z)` is `(x, −y, −z)` here (FLU). PX4's
//! `KM` is signed (positive for a counter-clockwise rotor); here its magnitude is `km` and its
//! sign the [`Spin`] (0 reads as counter-clockwise with km 0).

use std::collections::BTreeMap;

use data::ulog::ParameterTable;
use serde::Serialize;

use super::{CommandMap, Layout, Rotor, Spin, VehicleDescription};
use crate::error::{PhysicsError, Result, readable};

/// PX4's largest `CA_ROTOR_COUNT`.
pub const PX4_MAX_ROTORS: usize = 12;

/// The per-rotor parameters read, in the order they are reported.
const ROTOR_FIELDS: [&str; 8] = ["PX", "PY", "PZ", "AX", "AY", "AZ", "KM", "CT"];

/// What a log's PX4 parameters say about the vehicle.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AirframeInspection {
    /// `SYS_AUTOSTART`.
    pub airframe: Option<i64>,
    pub rotor_count: usize,
    pub layout: Layout,
    /// Horizontal distance of each rotor from the centre of mass, m.
    pub arm_lengths_m: Vec<f64>,
    /// Each rotor's km (m) and spin.
    pub moment_ratios_m: Vec<f64>,
    pub spins: Vec<Spin>,
    pub thrust_coefficients_n: Vec<f64>,
    /// `THR_MDL_FAC` (0 when the log lacks it).
    pub thrust_model_factor: f64,
    pub allocation_rank: usize,
    pub defaults: GeometryDefaults,
}

/// Which geometry parameters the log's declared defaults show to be set for this vehicle.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GeometryDefaults {
    /// Whether the log declares defaults (without them nothing below can be said).
    pub declared: bool,
    /// `CA_ROTOR*` parameters whose value differs from the airframe's default; empty when every
    /// one is the airframe's (the geometry may then not be this vehicle's).
    pub set_for_vehicle: Vec<String>,
    /// Whether every `CT` and `KM` (in magnitude) is PX4's built-in default: thrust and moment
    /// coefficients nobody measured.
    pub builtin_coefficients: bool,
}

impl VehicleDescription {
    /// The vehicle PX4's parameters describe (names in `values`, as a log holds them): rotors
    /// from `CA_ROTOR*` (FRD converted to FLU), the command map PX4's normalised motor command
    /// through `THR_MDL_FAC` (0 when absent). `CA_ROTOR_COUNT`, `PX`, `PY`, `KM` and `CT` are
    /// required; `PZ` (0) and the axis (up) are optional. Errors name the parameter.
    pub fn from_px4_parameters(values: &BTreeMap<String, f64>) -> Result<Self> {
        let count = rotor_count(values)?;
        let mut rotors = Vec::with_capacity(count);
        for i in 0..count {
            let get = |field: &str, default: Option<f64>| {
                let name = format!("CA_ROTOR{i}_{field}");
                match (values.get(&name), default) {
                    (Some(v), _) if v.is_finite() => Ok(*v),
                    (Some(v), _) => Err(bad(&name, format!("{} is not finite", readable(*v)))),
                    (None, Some(d)) => Ok(d),
                    (None, None) => Err(bad(&name, "missing".into())),
                }
            };
            let position = [get("PX", None)?, -get("PY", None)?, -get("PZ", Some(0.0))?];
            let axis = [
                get("AX", Some(0.0))?,
                -get("AY", Some(0.0))?,
                -get("AZ", Some(-1.0))?,
            ];
            let km = get("KM", None)?;
            let ct = get("CT", None)?;
            if ct <= 0.0 {
                let name = format!("CA_ROTOR{i}_CT");
                return Err(bad(
                    &name,
                    format!("{} is not a positive thrust", readable(ct)),
                ));
            }
            let spin = match km < 0.0 {
                true => Spin::Clockwise,
                false => Spin::CounterClockwise,
            };
            rotors.push(Rotor {
                position_m: position,
                spin,
                thrust_coefficient_n: ct,
                moment_ratio_m: km.abs(),
                axis,
            });
        }
        let factor = values.get("THR_MDL_FAC").copied().unwrap_or(0.0);
        if !(0.0..=1.0).contains(&factor) {
            return Err(bad(
                "THR_MDL_FAC",
                format!("{} is outside [0, 1]", readable(factor)),
            ));
        }
        let name = match values.get("SYS_AUTOSTART") {
            Some(airframe) => format!("PX4 airframe {airframe}"),
            None => "PX4 airframe".to_string(),
        };
        VehicleDescription::new(&name, rotors, CommandMap::px4(factor), [0.0; 3]).map_err(|error| {
            match error {
                PhysicsError::Description { field, message } => bad(
                    "CA_ROTOR*",
                    format!("{message} ({field} of the description read)"),
                ),
                other => other,
            }
        })
    }
}

/// The airframe section of a log's inspection: `None` when the log has no `CA_ROTOR_COUNT`
/// (PX4 before control allocation, v1.13, or not PX4); an error names a bad parameter.
pub fn inspect_airframe(table: &ParameterTable) -> Result<Option<AirframeInspection>> {
    if !table.values.contains_key("CA_ROTOR_COUNT") {
        return Ok(None);
    }
    let vehicle = VehicleDescription::from_px4_parameters(&table.values)?;
    let allocation = vehicle.allocation();
    Ok(Some(AirframeInspection {
        airframe: table.values.get("SYS_AUTOSTART").map(|&v| v as i64),
        rotor_count: vehicle.rotors.len(),
        layout: vehicle.layout(),
        arm_lengths_m: vehicle.arm_lengths_m(),
        moment_ratios_m: vehicle.rotors.iter().map(|r| r.moment_ratio_m).collect(),
        spins: vehicle.rotors.iter().map(|r| r.spin).collect(),
        thrust_coefficients_n: vehicle
            .rotors
            .iter()
            .map(|r| r.thrust_coefficient_n)
            .collect(),
        thrust_model_factor: table.values.get("THR_MDL_FAC").copied().unwrap_or(0.0),
        allocation_rank: allocation.rank(),
        defaults: geometry_defaults(table, vehicle.rotors.len()),
    }))
}

/// PX4 writes a default into the log only where the value differs from it: a geometry parameter
/// without an airframe default in the log is the airframe's default.
fn geometry_defaults(table: &ParameterTable, rotors: usize) -> GeometryDefaults {
    let (Some(system), Some(airframe)) = (&table.system_defaults, &table.airframe_defaults) else {
        return GeometryDefaults {
            declared: false,
            set_for_vehicle: Vec::new(),
            builtin_coefficients: false,
        };
    };
    let mut names = vec!["CA_ROTOR_COUNT".to_string()];
    for i in 0..rotors {
        names.extend(ROTOR_FIELDS.iter().map(|f| format!("CA_ROTOR{i}_{f}")));
    }
    let set_for_vehicle = names
        .into_iter()
        .filter(|name| table.values.contains_key(name) && airframe.contains_key(name))
        .collect();
    // A coefficient is built in when it has no system default in the log (it is the default) or
    // differs from it only in sign (a clockwise rotor's KM).
    let builtin = |name: String| match (table.values.get(&name), system.get(&name)) {
        (Some(_), None) => true,
        (Some(value), Some(default)) => value.abs() == default.abs(),
        (None, _) => false,
    };
    let builtin_coefficients = (0..rotors)
        .all(|i| builtin(format!("CA_ROTOR{i}_CT")) && builtin(format!("CA_ROTOR{i}_KM")));
    GeometryDefaults {
        declared: true,
        set_for_vehicle,
        builtin_coefficients,
    }
}

fn rotor_count(values: &BTreeMap<String, f64>) -> Result<usize> {
    let name = "CA_ROTOR_COUNT";
    let count = *values.get(name).ok_or_else(|| {
        bad(
            name,
            "missing (a log from before PX4's control allocation, v1.13, or not a multirotor)"
                .into(),
        )
    })?;
    if count.fract() != 0.0 || !(1.0..=PX4_MAX_ROTORS as f64).contains(&count) {
        return Err(bad(
            name,
            format!(
                "{} is not a rotor count from 1 to {PX4_MAX_ROTORS}",
                readable(count)
            ),
        ));
    }
    Ok(count as usize)
}

fn bad(name: &str, message: String) -> PhysicsError {
    PhysicsError::Parameter {
        name: name.to_string(),
        message,
    }
}
