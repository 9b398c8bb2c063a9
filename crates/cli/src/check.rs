//! `fourfold check` and `fourfold grad`: parse a formula and report, or print it with its
//! four partial derivatives.

use crate::failure::Failure;
use crate::input::{Input, Warn, compile_warning, load_scene};

/// `fourfold check`.
pub fn check(input: &Input, warn: Warn) -> Result<String, Failure> {
    let scene = load_scene(input)?;
    let formula = compile_warning(&scene, warn)?;
    let params = formula.param_names();
    Ok(format!(
        "ok: F = {}\n{} graph nodes ({} evaluated for F, {} for F and its gradient, {} with the second derivatives); parameters: {}",
        formula.f_text(),
        formula.graph.len(),
        formula.tape_f.len(),
        formula.tape_all.len(),
        formula.tape_second.len(),
        if params.is_empty() {
            "none".to_string()
        } else {
            params.join(", ")
        }
    ))
}

/// `fourfold grad`.
pub fn grad(input: &Input, warn: Warn) -> Result<String, Failure> {
    let scene = load_scene(input)?;
    let formula = compile_warning(&scene, warn)?;
    let [dx, dy, dz, dw] = formula.gradient_text();
    Ok(format!(
        "F     = {}\ndF/dx = {dx}\ndF/dy = {dy}\ndF/dz = {dz}\ndF/dw = {dw}",
        formula.f_text()
    ))
}
