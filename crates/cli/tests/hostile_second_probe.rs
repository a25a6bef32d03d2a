//! Issue 31 (the second hostile-input probe): one module per part, each test asserting a property
//! the documentation promises, through the built `learn` binary.

mod common;

#[path = "hostile_second_probe/outputs.rs"]
mod outputs;
