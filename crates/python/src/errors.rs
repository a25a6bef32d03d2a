//! One exception type for every error of the libraries, with their one-line message.

use pyo3::PyErr;

pyo3::create_exception!(
    learn_sysid,
    LearnSysidError,
    pyo3::exceptions::PyValueError,
    "An error of learn-sysid's libraries: bad input (naming the file, row or field), a fit that \
     failed, a file that could not be written."
);

/// `error`'s message as a [`LearnSysidError`].
pub fn raise(error: impl std::fmt::Display) -> PyErr {
    LearnSysidError::new_err(error.to_string())
}
