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

/// A Python callable told of progress from Rust code that runs without the interpreter lock: each
/// call takes the lock for its length; the first exception it raises is kept for
/// [`Progress::finish`] (the work is not interrupted).
pub struct Progress {
    callback: Option<pyo3::Py<pyo3::PyAny>>,
    failure: std::sync::Mutex<Option<PyErr>>,
}

impl Progress {
    pub fn new(callback: Option<pyo3::Py<pyo3::PyAny>>) -> Self {
        Self {
            callback,
            failure: std::sync::Mutex::new(None),
        }
    }

    /// Calls the callback with `arguments`, unless it has failed before.
    pub fn report<A>(&self, arguments: A)
    where
        A: for<'py> pyo3::call::PyCallArgs<'py>,
    {
        let Some(callback) = &self.callback else {
            return;
        };
        let mut failure = self.failure.lock().unwrap_or_else(|e| e.into_inner());
        if failure.is_some() {
            return;
        }
        pyo3::Python::attach(|py| {
            if let Err(error) = callback.call1(py, arguments) {
                *failure = Some(error);
            }
        });
    }

    /// `result`, or the callback's first exception.
    pub fn finish<T>(self, result: pyo3::PyResult<T>) -> pyo3::PyResult<T> {
        let failure = self.failure.into_inner().unwrap_or_else(|e| e.into_inner());
        match failure {
            Some(error) => Err(error),
            None => result,
        }
    }
}
