//! The second hostile-input probe (issue 31): one module per part, each driving the built binary.

mod common;

#[path = "hostile_second_probe/bounds.rs"]
mod bounds;
