//! rrt's errors as Python exceptions, with the command line's messages.

use pyo3::exceptions::{PyException, PyValueError};
use pyo3::prelude::*;
use rrt_host::cli::CliError;

pyo3::create_exception!(
    rrt,
    RrtError,
    PyException,
    "An error of a scene, a saved raster, an asset or an output file, with rrt's message (file:line:column: key: what is wrong)."
);

/// `e` and its causes, as `rrt` prints them (`a: b: c`).
pub fn chain(e: &dyn std::error::Error) -> String {
    let mut msg = e.to_string();
    let mut src = e.source();
    while let Some(s) = src {
        msg.push_str(": ");
        msg.push_str(&s.to_string());
        src = s.source();
    }
    msg
}

/// A `ValueError` for argument `arg`: `arg: message`.
pub fn value_error(arg: &str, message: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(format!("{arg}: {message}"))
}

/// A failure of a call: a bad argument (`ValueError`) or rrt's error
/// (`RrtError`).
#[derive(Debug)]
pub enum Error {
    /// The argument and what is wrong with it.
    Arg(String, String),
    /// rrt's error.
    Rrt(CliError),
}

impl Error {
    /// A bad argument.
    pub fn arg(arg: &str, message: impl std::fmt::Display) -> Self {
        Self::Arg(arg.to_string(), message.to_string())
    }
}

/// rrt's errors, through the command line's error type (its messages).
macro_rules! from_rrt {
    ($($t:ty),*) => {$(
        impl From<$t> for Error {
            fn from(e: $t) -> Self {
                Self::Rrt(e.into())
            }
        }
    )*};
}

from_rrt!(
    CliError,
    rrt_host::scene::SceneError,
    rrt_host::voxelize::BuildError,
    rrt_host::render::camera::CameraError,
    rrt_host::trace::TraceError,
    rrt_host::render::RenderError,
    rrt_host::output::rasterfile::RasterFileError
);

impl From<Error> for PyErr {
    fn from(e: Error) -> Self {
        match e {
            Error::Arg(arg, message) => value_error(&arg, message),
            // Sizes, views and options the caller gave.
            Error::Rrt(
                e @ (CliError::Arg { .. }
                | CliError::Camera(_)
                | CliError::Render(rrt_host::render::RenderError::Size { .. })),
            ) => PyValueError::new_err(chain(&e)),
            Error::Rrt(e) => RrtError::new_err(chain(&e)),
        }
    }
}
