//! The outputs of the sim-to-real mismatch tool (the `mismatch` crate): one recording against a
//! nominal model ([`recording`]: `mismatch.md` and `mismatch.svg`), several flights of one vehicle
//! analysed together ([`fleet`]: `<model stem>.md`, its figure and the terminal lines), a recording
//! longer than one analysis in parts ([`parts`]), and the demo
//! matrix on simulated recordings ([`demo`]: `summary.md` and the terminal table).
//!
//! Each module holds the plain result types the outputs record as they are (numbers, strings,
//! windows, targets; serialised as the `mismatch` crate's JSON records them) and a view (
//! [`recording::RecordingView`], [`fleet::FleetView`], [`demo::DemoView`]) that the `mismatch`
//! crate fills from its own results: the effects and candidates by their names, the rest borrowed.
//! Rendering returns the text (Markdown, SVG); the caller writes the files.

pub mod demo;
pub mod fleet;
pub mod parts;
pub mod recording;
mod residual_figure;
mod scale;
mod wind_figure;

/// `[a, b]` (or `a` alone) with each number to two significant digits.
pub(crate) fn two_digit_list(values: &[f64]) -> String {
    let texts: Vec<String> = values
        .iter()
        .map(|&x| {
            let decimals = if x > 0.0 {
                (1 - x.log10().floor() as i32).max(0) as usize
            } else {
                0
            };
            format!("{x:.decimals$}")
        })
        .collect();
    if texts.len() == 1 {
        texts[0].clone()
    } else {
        format!("[{}]", texts.join(", "))
    }
}

/// A drawing error as text.
fn text(error: impl std::fmt::Display) -> String {
    error.to_string()
}
