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

/// A fresh temporary directory, removed with everything in it when dropped.
fn temp_dir() -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix("sindy-tests-")
        .tempdir()
        .unwrap()
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
    let dir = temp_dir();
    let path = dir.path().join("model.json");
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
        (
            "{\"state\": [".to_string(),
            "field 'state (line 1 column 11)'",
        ),
        (
            text.replace(
                "\"kind\": \"central\"",
                "\"kind\": \"savitzky_golay\", \"window\": 4, \"order\": 2",
            ),
            "field 'derivative'",
        ),
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

/// A trajectory of `n` samples of x, y (scattered, exact derivatives ẋ = y, ẏ = −x).
fn xy(n: usize, scale: f64) -> Trajectory {
    let time: Vec<f64> = (0..n).map(|k| k as f64 * 0.01).collect();
    let states = Mat::from_fn(n, 2, |i, j| scale * ((i * 7 + 3 * j) as f64).sin());
    let derivatives = Mat::from_fn(n, 2, |i, j| {
        if j == 0 {
            states[(i, 1)]
        } else {
            -states[(i, 0)]
        }
    });
    Trajectory::new(time, states)
        .unwrap()
        .with_derivatives(derivatives)
        .unwrap()
}

#[test]
fn a_library_whose_feature_names_repeat_is_refused() {
    // poly:2+poly:2 printed `x' = 0.500 y + 0.500 y` and saved {"x": {"y": 0.5}}: half the model.
    let library = FeatureLibrary::from_spec(&LibrarySpec::parse("poly:2+poly:2").unwrap()).unwrap();
    let error = SindyParams::new(&["x", "y"], &[])
        .library(library)
        .fit(&[xy(50, 1.0)])
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("library 'poly:2+poly:2'") && error.contains("feature '1' twice"),
        "{error}"
    );
    // Names can collide through the inputs too: an input called `x^2` next to `x`.
    let library = FeatureLibrary::from_spec(&LibrarySpec::parse("poly:2").unwrap()).unwrap();
    let error = library
        .unique_feature_names(&["x", "x^2"])
        .unwrap_err()
        .to_string();
    assert!(error.contains("'x^2' twice"), "{error}");
    // Disjoint parts are fine.
    let library =
        FeatureLibrary::from_spec(&LibrarySpec::parse("poly:0+poly:1:noconstant").unwrap())
            .unwrap();
    assert_eq!(
        library.unique_feature_names(&["x", "y"]).unwrap(),
        ["1", "x", "y"]
    );
}

#[test]
fn a_model_file_with_repeated_names_is_refused() {
    let text = model().to_json().unwrap();
    let path = std::path::Path::new("dup.json");
    let mut doubled: serde_json::Value = serde_json::from_str(&text).unwrap();
    doubled["library"] = serde_json::json!({"kind": "concatenation", "parts": [
        {"kind": "polynomial", "degree": 1, "constant": false},
        {"kind": "polynomial", "degree": 1, "constant": false}]});
    doubled["features"] = serde_json::json!(["x", "y", "u", "x", "y", "u"]);
    doubled["equations"] = serde_json::json!({"x": {"y": 1.0}, "y": {"x": -1.0}});
    let error = SindyModel::from_json(&doubled.to_string(), path)
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("dup.json: field 'library'") && error.contains("'x' twice"),
        "{error}"
    );
    let mut same_state: serde_json::Value = serde_json::from_str(&text).unwrap();
    same_state["control"] = serde_json::json!(["x"]);
    let error = SindyModel::from_json(&same_state.to_string(), path)
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("dup.json: field 'control'") && error.contains("'x'"),
        "{error}"
    );
}

#[test]
fn a_non_finite_feature_is_named_with_its_sample() {
    let mut trajectory = xy(30, 1.0);
    trajectory.states[(4, 0)] = 1e200;
    let library = FeatureLibrary::from_spec(&LibrarySpec::parse("poly:2").unwrap()).unwrap();
    let error = SindyParams::new(&["x", "y"], &[])
        .library(library)
        .fit(&[trajectory])
        .unwrap_err();
    match &error {
        SindyError::NonFinite {
            what, row, column, ..
        } => {
            assert_eq!(
                (what.as_str(), *row, column.as_str()),
                ("library", 4, "feature 'x^2'")
            );
        }
        other => panic!("{other}"),
    }
    assert_eq!(
        error.to_string(),
        "library: feature 'x^2' is not finite (inf) at sample index 4"
    );
}
