//! The nominal Neural-Fly model against the real flights: the `fa` column and the frame of `w`.

mod common;

use physics::{NominalModel, residual_force};

#[test]
fn the_nominal_model_reproduces_the_recorded_residual_force() {
    let Some(dir) = common::real_data_dir() else {
        return;
    };
    let model =
        NominalModel::load(&common::workspace().join("experiments/mismatch/neural-fly.json"))
            .unwrap();
    for condition in ["nowind", "70wind"] {
        let path = dir.join(format!(
            "experiment/custom_figure8_baseline_{condition}.csv"
        ));
        let log = data::FlightLog::read(&path).unwrap();
        let recorded = log.residual_force.as_ref().unwrap();
        let computed = residual_force(&model, &log);
        let worst = recorded
            .iter()
            .zip(&computed)
            .flat_map(|(a, b)| (0..3).map(move |i| (a[i] - b[i]).abs()))
            .fold(0.0, f64::max);
        assert!(worst < 1e-9, "{condition}: worst |fa − computed| = {worst}");
        // `w` matches the world-frame rate implied by R better than the body-frame rate.
        let (frame, body_rms, world_rms) = log.rate_frame();
        assert_eq!(
            frame,
            data::RateFrame::World,
            "{condition}: {body_rms} vs {world_rms}"
        );
    }
}
