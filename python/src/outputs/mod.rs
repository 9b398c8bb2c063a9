//! What a scene makes: pictures, the tree, the shader, animations, slice meshes and the
//! sweep's critical values, each as the command of the same name makes it.

pub mod animate;
pub mod critical;
pub mod mesh;
pub mod picture;
pub mod tree;

use std::sync::Arc;

use pyo3::prelude::*;

use fourfold::formula::CompiledFormula;

use crate::formula::Formula;
use crate::scene::Scene;

/// The scene's formula compiled (a `FormulaError` if it does not parse), and the warnings
/// for parameters it uses that the scene leaves at 1.0, or that the scene sets and it does
/// not use.
pub fn compile(py: Python<'_>, scene: &Scene) -> PyResult<(Arc<CompiledFormula>, Vec<String>)> {
    let formula = Formula::compile(py, &scene.scene.formula)?;
    let (missing, unused) = formula.param_mismatch(scene.scene.params.keys());
    let mut warnings: Vec<String> = missing
        .iter()
        .map(|name| {
            format!("parameter {name} has no value; using 1.0 (give params={{'{name}': VALUE}})")
        })
        .collect();
    warnings.extend(
        unused
            .iter()
            .map(|name| format!("parameter {name} is set but the formula does not use it")),
    );
    Ok((formula, warnings))
}

/// Issues each of `warnings` as a Python `UserWarning`.
pub fn warn_all(py: Python<'_>, warnings: &[String]) -> PyResult<()> {
    for w in warnings {
        let message = std::ffi::CString::new(w.replace('\0', " ")).unwrap_or_default();
        PyErr::warn(
            py,
            &py.get_type::<pyo3::exceptions::PyUserWarning>(),
            &message,
            2,
        )?;
    }
    Ok(())
}
