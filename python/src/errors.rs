//! The package's exceptions: a formula that does not parse (a `ValueError` carrying the
//! command line's caret message and where it points), and a picture the GPU could not draw.

use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;

use fourfold::syntax::SourceError;

create_exception!(
    fourfold,
    FormulaError,
    PyValueError,
    "A formula that does not parse or lower. str() is the caret message `fourfold check` \
     prints; `message`, `hint`, `start` and `end` (character offsets into `formula`, so \
     `formula[start:end]` is the part pointed at), `line` and `column` (1-based) say where."
);

create_exception!(
    fourfold,
    RenderError,
    PyRuntimeError,
    "Drawing failed for a reason that is not the caller's value: no usable GPU, a device \
     lost, a file that cannot be written."
);

/// The `FormulaError` for `error` in `source`.
pub fn formula_error(py: Python<'_>, error: &SourceError, source: &str) -> PyErr {
    let err = FormulaError::new_err(error.render("formula", source));
    let value = err.value(py);
    let chars = |byte: usize| source[..byte.min(source.len())].chars().count();
    let (start, end) = (chars(error.span.start), chars(error.span.end));
    let before = &source[..error.span.start.min(source.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().unwrap_or("").chars().count() + 1;
    let set = || -> PyResult<()> {
        value.setattr("message", error.message.as_str())?;
        value.setattr("hint", error.hint.as_deref())?;
        value.setattr("formula", source)?;
        value.setattr("start", start)?;
        value.setattr("end", end)?;
        value.setattr("line", line)?;
        value.setattr("column", column)
    };
    // Setting attributes on a fresh exception instance does not fail.
    let _ = set();
    err
}

/// A `ValueError` with `message`.
pub fn value_error(message: impl Into<String>) -> PyErr {
    PyValueError::new_err(message.into())
}

/// A `RenderError` with `message`.
pub fn render_error(message: impl ToString) -> PyErr {
    RenderError::new_err(message.to_string())
}
