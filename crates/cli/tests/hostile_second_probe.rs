//! The second hostile-input probe (issue 31): one module per part, each test through the built
//! `learn` binary, asserting a property the documentation promises, named after the defect it
//! guards.

mod common;

#[path = "hostile_second_probe/bounds.rs"]
mod bounds;
#[path = "hostile_second_probe/degenerate.rs"]
mod degenerate;
#[path = "hostile_second_probe/outputs.rs"]
mod outputs;
#[path = "hostile_second_probe/readers.rs"]
mod readers;
