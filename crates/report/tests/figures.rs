//! The qualitative figure on synthetic traces: layout, colours, real text.

use report::{MethodTrace, OutputAxis, QualitativeFigure};

/// A full-dynamics figure (six outputs) over a 2511-sample flight at 50 Hz.
fn synthetic_figure(outputs: &[&str]) -> QualitativeFigure {
    let n = 2511;
    let time: Vec<f64> = (0..n).map(|k| k as f64 * 0.02).collect();
    let truth: Vec<Vec<f64>> = (0..outputs.len())
        .map(|j| {
            time.iter()
                .enumerate()
                .map(|(k, t)| {
                    let noise = ((k * 7919 + j * 104729) % 1000) as f64 / 1000.0 - 0.5;
                    (1.0 + j as f64) * (0.8 * t + j as f64).sin() + 0.4 * noise
                })
                .collect()
        })
        .collect();
    let smooth = |scale: f64| -> Vec<Vec<f64>> {
        (0..outputs.len())
            .map(|j| {
                time.iter()
                    .map(|t| scale * (1.0 + j as f64) * (0.8 * t + j as f64).sin())
                    .collect()
            })
            .collect()
    };
    QualitativeFigure {
        table: "full".to_string(),
        condition: "35wind".to_string(),
        split: n / 2,
        outputs: outputs.iter().map(|o| OutputAxis::for_target(o)).collect(),
        truth,
        methods: vec![
            MethodTrace {
                method: "SINDy".to_string(),
                prediction: smooth(0.9),
                band: None,
            },
            MethodTrace {
                method: "LeARN".to_string(),
                prediction: smooth(1.05),
                band: None,
            },
        ],
        time,
    }
}

const FULL: [&str; 6] = ["vdot_x", "vdot_y", "vdot_z", "wdot_x", "wdot_y", "wdot_z"];

#[test]
fn full_figure_has_every_panel_colour_and_label_as_text() {
    let figure = synthetic_figure(&FULL);
    let svg = figure.render_svg().unwrap();
    if let Some(dir) = std::env::var_os("REPORT_FIGURE_DIR") {
        std::fs::write(std::path::Path::new(&dir).join("synthetic-full.svg"), &svg).unwrap();
    }
    assert!(svg.starts_with("<svg"));
    // Colours are lower-case hex in plotters' output.
    for colour in ["#FFAA6B", "#EB3324", "#3282F6"] {
        assert!(
            svg.to_uppercase().contains(colour),
            "colour {colour} missing"
        );
    }
    // Text is real SVG text: titles, legend, axis labels with units.
    assert!(svg.contains("<text"));
    for text in [
        "SINDy (35wind)",
        "LeARN (35wind)",
        "Ground Truth",
        "Adaptation",
        "Generalization",
        "t [s]",
        "v\u{307}x [m/s²]",
        "ω\u{307}z [rad/s²]",
    ] {
        assert!(svg.contains(text), "text {text:?} missing");
    }
    // One axis description per panel: 6 outputs × 2 methods.
    assert_eq!(svg.matches("t [s]").count(), 12);
    // Three series per panel: truth, adaptation and generalisation.
    for colour in ["#FFAA6B", "#EB3324", "#3282F6"] {
        assert_eq!(svg.matches(&format!("stroke=\"{colour}\"")).count(), 12);
    }
    assert_eq!(figure.size(), (2 * 3 * 300 + 18, 78 + 2 * 210));
}

#[test]
fn translational_figure_has_one_row_of_panels() {
    let figure = synthetic_figure(&FULL[..3]);
    let svg = figure.render_svg().unwrap();
    assert_eq!(svg.matches("stroke=\"#3282F6\"").count(), 6);
    assert!(!svg.contains("ω\u{307}"));
    assert_eq!(figure.size().1, 78 + 210);
}

#[test]
fn inconsistent_traces_are_reported_not_drawn() {
    let mut figure = synthetic_figure(&FULL[..3]);
    figure.methods[1].prediction[2][100] = f64::NAN;
    let message = figure.render_svg().unwrap_err().to_string();
    assert!(
        message.contains("LeARN") && message.contains("sample 100"),
        "{message}"
    );
    let mut figure = synthetic_figure(&FULL[..3]);
    figure.truth[0].pop();
    assert!(
        figure
            .render_svg()
            .unwrap_err()
            .to_string()
            .contains("ground truth")
    );
    let mut figure = synthetic_figure(&FULL[..3]);
    figure.split = figure.time.len();
    assert!(figure.render_svg().is_err());
}
