//! The second hostile-input probe (issue 31): one module per part of the fix, each driving the
//! built `learn` binary on the probe's reproductions.

mod common;

#[path = "hostile_second_probe/degenerate.rs"]
mod degenerate;
