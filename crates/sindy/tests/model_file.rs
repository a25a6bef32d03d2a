//! Saving and loading models: round trip, refusal to overwrite, and errors naming the field.

use sindy::{
    FeatureLibrary, LibrarySpec, Mat, OptimizerSpec, SindyError, SindyModel, SindyParams,
    Trajectory,
};

fn model() -> SindyModel {
    // ẋ = y − 0.1x, ẏ = −x + 0.5u at scattered points of [−3, 3]³ (exact derivatives)
    let n = 300;
    let time: Vec<f64> = (0..n).map(|k| k as f64 * 0.01).collect();
    let scatter = |i: usize, frequency: f64, phase: f64| 3.0 * (frequency * i as f64 + phase).sin();
    let states = Mat::from_fn(n, 2, |i, j| {
        if j == 0 {
            scatter(i, 12.9898, 0.0)
        } else {
            scatter(i, 78.233, 1.0)
        }
    });
    let controls = Mat::from_fn(n, 1, |i, _| scatter(i, 37.719, 2.0));
    let derivatives = Mat::from_fn(n, 2, |i, j| {
        if j == 0 {
            states[(i, 1)] - 0.1 * states[(i, 0)]
        } else {
            -states[(i, 0)] + 0.5 * controls[(i, 0)]
        }
    });
    let trajectory = Trajectory::new(time, states)
        .unwrap()
        .with_controls(controls)
        .unwrap()
        .with_derivatives(derivatives)
        .unwrap();
    SindyParams::new(&["x", "y"], &["u"])
        .library(
            FeatureLibrary::from_spec(&LibrarySpec::parse("poly:2+fourier:1").unwrap()).unwrap(),
        )
        .optimizer(OptimizerSpec::stlsq(0.05))
        .fit(&[trajectory])
        .unwrap()
}

fn temp_path(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("sindy-tests-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    let _ = std::fs::remove_file(&path);
    path
}

#[test]
fn equations_print_like_pysindy_with_signs_folded() {
    assert_eq!(
        model().equations(3),
        vec!["x' = -0.100 x + 1.000 y", "y' = -1.000 x + 0.500 u"]
    );
}

#[test]
fn a_saved_model_loads_and_predicts_identically() {
    let model = model();
    let path = temp_path("model.json");
    model.save(&path, false).unwrap();
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    assert_eq!(json["state"], serde_json::json!(["x", "y"]));
    assert_eq!(json["control"], serde_json::json!(["u"]));
    assert_eq!(json["features"][0], "1");
    assert!(
        json["features"]
            .as_array()
            .unwrap()
            .iter()
            .any(|f| f == "sin(u)")
    );
    assert_eq!(json["equations"]["x"].as_object().unwrap().len(), 2);
    assert!((json["equations"]["x"]["y"].as_f64().unwrap() - 1.0).abs() < 1e-9);

    let loaded = SindyModel::load(&path).unwrap();
    let inputs = Mat::from_fn(7, 3, |i, j| (i * 3 + j) as f64 * 0.1 - 0.5);
    let (a, b) = (
        model.predict_inputs(inputs.as_ref()).unwrap(),
        loaded.predict_inputs(inputs.as_ref()).unwrap(),
    );
    assert_eq!(a, b);
    assert_eq!(loaded.equations(6), model.equations(6));

    // An existing file is never overwritten unless asked.
    let error = model.save(&path, false).unwrap_err();
    assert!(matches!(error, SindyError::Io { .. }) && error.to_string().contains("model.json"));
    model.save(&path, true).unwrap();
}

#[test]
fn inconsistent_files_are_rejected_naming_the_field() {
    let text = model().to_json().unwrap();
    let path = std::path::Path::new("bad.json");
    let mut unknown_feature: serde_json::Value = serde_json::from_str(&text).unwrap();
    let equation = unknown_feature["equations"]["x"].as_object_mut().unwrap();
    let coefficient = equation.remove("y").unwrap();
    equation.insert("q".to_string(), coefficient);
    let cases = [
        (text.replace("\"sin(u)\"", "\"sin(w)\""), "features"),
        (unknown_feature.to_string(), "equations.x"),
        (text.replace("sindy-model/1", "sindy-model/9"), "format"),
        ("{\"state\": [".to_string(), "(document)"),
    ];
    for (bad, field) in cases {
        let error = SindyModel::from_json(&bad, path).unwrap_err().to_string();
        assert!(
            error.contains(field) && error.contains("bad.json"),
            "{error}"
        );
        assert!(!error.contains('\n'), "{error}");
    }
}

#[test]
fn custom_libraries_fit_but_cannot_be_saved() {
    let n = 100;
    let time: Vec<f64> = (0..n).map(|k| k as f64 * 0.01).collect();
    let states = Mat::from_fn(n, 1, |i, _| 0.2 + time[i]);
    let derivatives = Mat::from_fn(n, 1, |i, _| 2.0 * states[(i, 0)].exp());
    let trajectory = Trajectory::new(time, states)
        .unwrap()
        .with_derivatives(derivatives)
        .unwrap();
    let library = FeatureLibrary::custom(vec![
        sindy::CustomFunction::new("exp({})", f64::exp).unwrap(),
    ])
    .unwrap();
    let model = SindyParams::new(&["x"], &[])
        .library(library)
        .fit(&[trajectory])
        .unwrap();
    assert!((model.coefficient("x", "exp(x)").unwrap() - 2.0).abs() < 1e-10);
    assert!(matches!(
        model.to_json(),
        Err(SindyError::NotSerialisable(_))
    ));
}
