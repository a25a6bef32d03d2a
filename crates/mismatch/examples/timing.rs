fn main() {
    let log = data::FlightLog::read(std::path::Path::new(
        "data/neural-fly/experiment/custom_figure8_baseline_70wind.csv",
    ))
    .unwrap();
    let model =
        physics::NominalModel::load(std::path::Path::new("experiments/mismatch/neural-fly.json"))
            .unwrap();
    let rec = mismatch::Recording::new(&log, &model, 40).unwrap();
    let problem = mismatch::Problem::new(rec, model, Default::default(), 0.3).unwrap();
    let e = physics::Effects::default();
    let t = std::time::Instant::now();
    for _ in 0..100 {
        std::hint::black_box(problem.residual(&e));
    }
    println!("residual: {:?} per call", t.elapsed() / 100);
    let t = std::time::Instant::now();
    for _ in 0..100 {
        std::hint::black_box(mismatch::forward::predict_substeps(
            &problem.recording,
            &problem.model,
            &e,
        ));
    }
    println!("substeps: {:?} per call", t.elapsed() / 100);
}
