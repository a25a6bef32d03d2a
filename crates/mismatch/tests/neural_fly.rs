//! On a real windy flight the tool names a drag on the relative wind, and improves the held-out fit,
//! from that one flight alone.

use std::path::{Path, PathBuf};

use physics::EffectId;

/// The real data directory (see `data::real_data_dir_for_tests`: skips locally, fails under CI).
fn real_data_dir() -> Option<PathBuf> {
    data::real_data_dir_for_tests(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../.."))
}

#[test]
fn names_drag_on_the_relative_wind_in_the_strongest_wind() {
    let Some(dir) = real_data_dir() else {
        return;
    };
    let workspace = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let model =
        physics::NominalModel::load(&workspace.join("experiments/mismatch/neural-fly.json"))
            .unwrap();
    let log =
        data::FlightLog::read(&dir.join("experiment/custom_figure8_baseline_100wind.csv")).unwrap();
    let analysis = mismatch::analyze(
        &log,
        &model,
        "neural-fly",
        &mismatch::CheckedSettings::standard(),
    )
    .unwrap();
    assert_eq!(analysis.report.rate_frame.used, mismatch::RateFrame::World);
    let ids = analysis.fitted.ids();
    let drag = ids.contains(&EffectId::QuadraticDrag) || ids.contains(&EffectId::LinearDrag);
    assert!(drag && ids.contains(&EffectId::Wind), "{ids:?}");
    // The wind tunnel blows along −x at about 12 m/s.
    let wind = analysis.fitted.air_velocity();
    assert!(wind[0] < -8.0, "{wind:?}");
    let fit = &analysis.report.fit;
    assert!(
        fit.heldout.after.mse < 0.4 * fit.heldout.before.mse,
        "{fit:?}"
    );
}
