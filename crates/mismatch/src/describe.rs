//! Plain words for effects, and the effects without one of them.

use physics::Effects;

/// The effects without one of them (and without the wind when no drag is left for it to act on).
pub fn remove_effect(effects: &Effects, id: &str) -> Effects {
    let mut e = *effects;
    match id {
        "linear_drag" => e.linear_drag = None,
        "quadratic_drag" => e.quadratic_drag = None,
        "wind" => e.wind = None,
        "thrust_scale" => e.thrust_scale = None,
        "motor_lag" => e.motor_lag = None,
        "ground_effect" => e.ground_effect = None,
        "torque_bias" => e.torque_bias = None,
        "inertia_scale" => e.inertia_scale = None,
        "delay" => e.delay = None,
        _ => {}
    }
    if e.quadratic_drag.is_none() && e.linear_drag.is_none() {
        e.wind = None;
    }
    e
}

fn vector(v: [f64; 3], digits: usize) -> String {
    format!("[{:.digits$}, {:.digits$}, {:.digits$}]", v[0], v[1], v[2])
}

/// One sentence per effect, in plain words.
pub fn describe(id: &str, e: &Effects) -> String {
    match id {
        "linear_drag" => {
            let d = e.linear_drag.map(|x| x.d).unwrap_or_default();
            format!(
                "Rotor drag: a force against the velocity along each body axis, d = {} 1/s (at 2 m/s forward flight about {:.2} m/s² of deceleration).",
                vector(d, 3),
                2.0 * d[0].max(d[1])
            )
        }
        "quadratic_drag" => {
            let c = e.quadratic_drag.map(|x| x.c).unwrap_or_default();
            format!(
                "Aerodynamic drag growing with the square of the airspeed, c = {c:.4} 1/m (at 5 m/s airspeed about {:.2} m/s²).",
                25.0 * c
            )
        }
        "wind" => {
            let w = e.air_velocity();
            format!(
                "The drag acts on the velocity relative to air moving at {} m/s (speed {:.2} m/s): there is wind.",
                vector(w, 2),
                physics::vector::norm(w)
            )
        }
        "thrust_scale" => {
            let k = e.thrust_scale.map(|x| x.k).unwrap_or(1.0);
            format!(
                "The rotors produce {k:.3} times the thrust the model assumes ({:+.1}%).",
                100.0 * (k - 1.0)
            )
        }
        "motor_lag" => format!(
            "Each motor reaches its commanded speed with a first-order lag of time constant {:.1} ms.",
            1000.0 * e.lag_s()
        ),
        "ground_effect" => {
            let r = e.ground_effect.map(|x| x.r_m).unwrap_or_default();
            format!(
                "Extra thrust near the ground (ground effect), radius r = {r:.3} m: +{:.1}% thrust at 0.3 m height, +{:.2}% at 1.5 m.",
                100.0 * (1.0 / (1.0 - physics::ground_ratio(r, 0.3)) - 1.0),
                100.0 * (1.0 / (1.0 - physics::ground_ratio(r, 1.5)) - 1.0)
            )
        }
        "torque_bias" => format!(
            "A constant extra angular acceleration {} rad/s² (a torque offset, e.g. an off-centre mass or a tilted motor).",
            vector(e.torque_bias.map(|x| x.b).unwrap_or_default(), 3)
        ),
        "inertia_scale" => format!(
            "The moments of inertia are {} times the model's.",
            vector(e.inertia_scale.map(|x| x.k).unwrap_or([1.0; 3]), 3)
        ),
        "delay" => format!(
            "The vehicle responds to its commands {:.1} ms late.",
            1000.0 * e.delay_s()
        ),
        other => other.to_string(),
    }
}
