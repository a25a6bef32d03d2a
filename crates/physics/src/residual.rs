//! The residual force of a recorded flight against the nominal model, as the Neural-Fly logs
//! compute their `fa` column: `fa = m v̇ − m [0, 0, −g] − R e3 T` with `v̇` the five-point central
//! difference of the recorded velocity (zero on the first and last two rows).

use data::FlightLog;

use crate::model::NominalModel;
use crate::vector::Vec3;

/// Five-point central difference `(−x[k+2] + 8x[k+1] − 8x[k−1] + x[k−2]) / (12 dt)`, zero on the
/// first and last two samples.
pub fn five_point_derivative(x: &[f64], dt: f64) -> Vec<f64> {
    let n = x.len();
    let mut d = vec![0.0; n];
    for k in 2..n.saturating_sub(2) {
        d[k] = (-x[k + 2] + 8.0 * x[k + 1] - 8.0 * x[k - 1] + x[k - 2]) / (12.0 * dt);
    }
    d
}

/// The residual force (N) of every row of a flight against the model.
pub fn residual_force(model: &NominalModel, log: &FlightLog) -> Vec<Vec3> {
    let dt = log.sample_interval();
    let derivatives: Vec<Vec<f64>> = (0..3)
        .map(|axis| {
            let v: Vec<f64> = log.velocity.iter().map(|v| v[axis]).collect();
            five_point_derivative(&v, dt)
        })
        .collect();
    (0..log.len())
        .map(|k| {
            let command = model.actuator_command(
                log.thrust_setpoint[k],
                log.hover_throttle[k],
                log.motor_command.row(k),
                log.battery_voltage.as_ref().map(|v| v[k]),
            );
            let thrust = model.wrench(&command).thrust;
            let acceleration = [derivatives[0][k], derivatives[1][k], derivatives[2][k]];
            model.residual_force(acceleration, &log.rotation[k], thrust)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn five_point_difference_is_exact_on_quartics() {
        let dt = 0.02;
        let x: Vec<f64> = (0..50)
            .map(|k| (k as f64 * dt).powi(4) - 2.0 * (k as f64 * dt))
            .collect();
        let d = five_point_derivative(&x, dt);
        for k in 2..48 {
            let t = k as f64 * dt;
            assert!((d[k] - (4.0 * t.powi(3) - 2.0)).abs() < 1e-9);
        }
        assert_eq!((d[0], d[1], d[48], d[49]), (0.0, 0.0, 0.0, 0.0));
    }
}
