//! The extension module `learn_sysid._native` of the Python package `learn-sysid`.
//!
//! What it is for: handing NumPy arrays and Python values to the workspace's libraries and their
//! results back — SINDy fits, predictions, simulations and saved models (`sindy`), the sparse
//! regressions on a library matrix that `pysindy.SINDy` calls as its optimizer (bagged, with
//! coefficient intervals, where the crate bags), the mismatch
//! analysis of a recording (`mismatch`, its files written as the CLI writes them) and LeARN's
//! meta-training, adaptation and explanation on tasks in memory (`learn`). Arrays of `float64`
//! are read in place whatever their strides (no copy), and the interpreter lock is released
//! while the Rust code runs. Every error is a `learn_sysid.LearnSysidError` carrying the
//! library's one-line message.
//!
//! What it is not for: the Python API itself (PySINDy's shape: `SINDy`, `STLSQ`,
//! `PolynomialLibrary`, …), which is the pure-Python package beside this crate
//! (`crates/python/learn_sysid/`), nor any method of its own: every number comes from the crates
//! the `learn` binary uses.

mod arrays;
mod errors;
mod learn_api;
mod mismatch_api;
mod regression_api;
mod sindy_api;

use pyo3::prelude::*;

#[pymodule]
fn _native(module: &Bound<'_, PyModule>) -> PyResult<()> {
    module.add("__version__", env!("CARGO_PKG_VERSION"))?;
    module.add(
        "LearnSysidError",
        module.py().get_type::<errors::LearnSysidError>(),
    )?;
    sindy_api::register(module)?;
    regression_api::register(module)?;
    mismatch_api::register(module)?;
    learn_api::register(module)?;
    Ok(())
}
