//! fourfold from Python: the Rust half of the `fourfold` package (`fourfold._native`),
//! built by maturin from python/pyproject.toml. Thin glue over the core library: each
//! function takes a scene, runs the same code as the command line, and hands back numpy
//! arrays and plain values; python/fourfold/ wraps them in the Pythonic API
//! (docs/python.md).

mod drawing;
mod errors;
mod formula;
mod keywords;
mod outputs;
mod scene;
mod work;

use pyo3::prelude::*;

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("FormulaError", py.get_type::<errors::FormulaError>())?;
    m.add("RenderError", py.get_type::<errors::RenderError>())?;
    m.add_class::<formula::Formula>()?;
    m.add_class::<scene::Scene>()?;
    m.add_class::<outputs::mesh::Mesh>()?;
    m.add_function(wrap_pyfunction!(outputs::picture::render, m)?)?;
    m.add_function(wrap_pyfunction!(outputs::picture::wgsl, m)?)?;
    m.add_function(wrap_pyfunction!(outputs::picture::png, m)?)?;
    m.add_function(wrap_pyfunction!(outputs::tree::tree, m)?)?;
    m.add_function(wrap_pyfunction!(outputs::animate::animate, m)?)?;
    m.add_function(wrap_pyfunction!(outputs::mesh::mesh, m)?)?;
    m.add_function(wrap_pyfunction!(outputs::critical::critical, m)?)?;
    m.add_function(wrap_pyfunction!(scene::examples, m)?)?;
    m.add_function(wrap_pyfunction!(scene::is_link, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
