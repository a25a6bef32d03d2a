//! Plain words for effects, and the effects without one of them.

use physics::{EffectId, Effects};

/// The effects without one of them (and without the wind when no drag is left for it to act on).
pub fn remove_effect(effects: &Effects, id: EffectId) -> Effects {
    let mut e = *effects;
    e.remove(id);
    if e.quadratic_drag.is_none() && e.linear_drag.is_none() && e.rotor_drag.is_none() {
        e.wind = None;
    }
    if e.wind.is_none() {
        e.wind_gradient = None;
    }
    e
}

fn vector(v: [f64; 3], digits: usize) -> String {
    format!("[{:.digits$}, {:.digits$}, {:.digits$}]", v[0], v[1], v[2])
}

/// One sentence for effect `id` of `e`, in plain words.
pub fn describe(id: EffectId, e: &Effects) -> String {
    match id {
        EffectId::LinearDrag => {
            let d = e.linear_drag.map(|x| x.d).unwrap_or_default();
            format!(
                "Rotor drag: a force against the velocity along each body axis, d = {} 1/s (at 2 m/s forward flight about {:.2} m/s² of deceleration).",
                vector(d, 3),
                2.0 * d[0].max(d[1])
            )
        }
        EffectId::QuadraticDrag => {
            let c = e.quadratic_drag.map(|x| x.c).unwrap_or_default();
            format!(
                "Aerodynamic drag growing with the square of the airspeed, c = {c:.4} 1/m (at 5 m/s airspeed about {:.2} m/s²).",
                25.0 * c
            )
        }
        EffectId::Wind => {
            let w = e.air_velocity();
            format!(
                "The drag acts on the velocity relative to air moving at {} m/s (speed {:.2} m/s): there is wind.",
                vector(w, 2),
                physics::vector::norm(w)
            )
        }
        EffectId::ThrustScale => {
            let k = e.thrust_scale.map(|x| x.k).unwrap_or(1.0);
            format!(
                "The rotors produce {k:.3} times the thrust the model assumes ({:+.1}%).",
                100.0 * (k - 1.0)
            )
        }
        EffectId::MotorLag => format!(
            "Each motor reaches its commanded speed with a first-order lag of time constant {:.1} ms.",
            1000.0 * e.lag_s()
        ),
        EffectId::GroundEffect => {
            let r = e.ground_effect.map(|x| x.r_m).unwrap_or_default();
            format!(
                "Extra thrust near the ground (ground effect), radius r = {r:.3} m: +{:.1}% thrust at 0.3 m height, +{:.2}% at 1.5 m.",
                100.0 * (1.0 / (1.0 - physics::ground_ratio(r, 0.3)) - 1.0),
                100.0 * (1.0 / (1.0 - physics::ground_ratio(r, 1.5)) - 1.0)
            )
        }
        EffectId::TorqueBias => format!(
            "A constant extra angular acceleration {} rad/s² (a torque offset, e.g. an off-centre mass or a tilted motor).",
            vector(e.torque_bias.map(|x| x.b).unwrap_or_default(), 3)
        ),
        EffectId::InertiaScale => format!(
            "The moments of inertia are {} times the model's.",
            vector(e.inertia_scale.map(|x| x.k).unwrap_or([1.0; 3]), 3)
        ),
        EffectId::Delay => format!(
            "The vehicle responds to its commands {:.1} ms late.",
            1000.0 * e.delay_s()
        ),
        EffectId::ThrustMap => {
            let k = e.thrust_map.map(|m| m.k).unwrap_or([1.0, 1.0, 0.0]);
            format!(
                "The thrust does not follow the command in proportion: T / (m g) = {:.3} + {:.3} (x − 1) {:+.3} (x − 1)² for a command asking x m g (at hover {:+.1}%, its slope {:+.0}% from the model's).",
                k[0],
                k[1],
                k[2],
                100.0 * (k[0] - 1.0),
                100.0 * (k[1] - 1.0)
            )
        }
        EffectId::ThrustTilt => {
            let [x, y] = e.thrust_tilt.map(|t| t.angles_rad).unwrap_or([0.0; 2]);
            format!(
                "The thrust axis is tilted from the body z axis by {:.2}° about x and {:.2}° about y ({:.2}° in all; uncalibrated, that reads as a steady sideways force of {:.2} m/s²).",
                x.to_degrees(),
                y.to_degrees(),
                (x.cos() * y.cos()).acos().to_degrees(),
                9.81 * (x.cos() * y.cos()).acos().sin()
            )
        }
        EffectId::RotorDrag => {
            let d = e.rotor_drag.map(|r| r.d).unwrap_or([0.0; 2]);
            format!(
                "Rotor drag proportional to the thrust and linear in the airspeed: {:.3} 1/s edgewise and {:.3} 1/s along the rotor axis (at hover thrust and 5 m/s edgewise airspeed about {:.2} m/s²).",
                d[0],
                d[1],
                5.0 * d[0]
            )
        }
        EffectId::TranslationalLift => {
            let c = e.translational_lift.map(|l| l.c).unwrap_or(0.0);
            format!(
                "Translational lift: the rotors give more thrust in edgewise airflow, by {:+.1}% at 5 m/s and {:+.1}% at 10 m/s (c = {c:.5} s²/m²).",
                100.0 * 25.0 * c,
                100.0 * 100.0 * c
            )
        }
        EffectId::DragLag => format!(
            "The air forces follow the velocity with a first-order lag of {:.2} s (the wake and inflow take time to build up).",
            e.drag_lag_s()
        ),
        EffectId::WindGradient => {
            let g = e.wind_gradient.map(|g| g.per_m).unwrap_or_default();
            let largest = g.iter().flatten().fold(0.0f64, |a, b| a.max(b.abs()));
            format!(
                "The air velocity is not uniform: it changes by up to {largest:.2} m/s per metre moved (gradient {}).",
                serde_json::to_string(&g).unwrap_or_default()
            )
        }
    }
}
