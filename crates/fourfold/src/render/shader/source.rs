//! The ray caster's shader for one formula: the template with the formula's functions spliced
//! in at its markers, validated by naga before any pipeline sees it.

use crate::formula::CompiledFormula;

use super::tapes::{INTERVAL, POINT, tape_function};

/// The ray-casting template (`templates/raycast/`): the bindings and the formula's markers,
/// the rays, the shading, the march, certified pixels, and the entry points.
pub const TEMPLATE: &str = concat!(
    include_str!("../../../templates/raycast/bindings.wgsl"),
    "\n",
    include_str!("../../../templates/raycast/rays.wgsl"),
    "\n",
    include_str!("../../../templates/raycast/shading.wgsl"),
    "\n",
    include_str!("../../../templates/raycast/march.wgsl"),
    "\n",
    include_str!("../../../templates/raycast/certify.wgsl"),
    "\n",
    include_str!("../../../templates/raycast/entry.wgsl"),
);
const F_MARKER: &str = "//@FOURFOLD_F@";
const GRAD_MARKER: &str = "//@FOURFOLD_GRAD@";
const F_GRAD_MARKER: &str = "//@FOURFOLD_F_GRAD@";
const INTERVAL_MARKER: &str = "//@FOURFOLD_INTERVAL@";
/// Rigorous interval arithmetic in WGSL (certified pixels), spliced in before `ff_f_box`.
pub const INTERVAL_LIBRARY: &str = include_str!("../../../templates/interval.wgsl");

/// The most parameters a shader can read (the uniform holds 16 × vec4).
pub const MAX_PARAMS: usize = 64;

/// A generated shader that naga rejected: a bug in fourfold, reported rather than crashed on.
#[derive(Debug, Clone, thiserror::Error)]
pub enum CodegenError {
    #[error("the formula has {0} parameters; the shader holds at most {MAX_PARAMS}")]
    TooManyParams(usize),
    #[error("internal error: the generated WGSL does not parse: {0}")]
    Parse(String),
    #[error("internal error: the generated WGSL does not validate: {0}")]
    Validate(String),
}

/// A complete, validated shader.
#[derive(Debug, Clone)]
pub struct Shader {
    pub source: String,
    pub module: naga::Module,
}

/// Generates and validates the ray-casting shader for `formula`.
pub fn generate(formula: &CompiledFormula) -> Result<Shader, CodegenError> {
    if formula.params.len() > MAX_PARAMS {
        return Err(CodegenError::TooManyParams(formula.params.len()));
    }
    let f = tape_function(&POINT, "ff_f", "f32", &formula.tape_f, |v| v[0].clone());
    let grad = tape_function(&POINT, "ff_grad", "vec4<f32>", &formula.tape_grad, |v| {
        format!("vec4<f32>({}, {}, {}, {})", v[0], v[1], v[2], v[3])
    });
    let f_grad = tape_function(&POINT, "ff_f_grad", "FGrad", &formula.tape_all, |v| {
        format!(
            "FGrad({}, vec4<f32>({}, {}, {}, {}))",
            v[0], v[1], v[2], v[3], v[4]
        )
    });
    let interval = format!(
        "{INTERVAL_LIBRARY}\n{}\n\n{}",
        tape_function(&INTERVAL, "ff_f_box", "vec2<f32>", &formula.tape_f, |v| v
            [0]
        .clone()),
        tape_function(
            &INTERVAL,
            "ff_f_grad_box",
            "IvFGrad",
            &formula.tape_all,
            |v| format!("IvFGrad({}, {}, {}, {}, {})", v[0], v[1], v[2], v[3], v[4])
        )
    );
    let source = TEMPLATE
        .replace(F_MARKER, &f)
        .replace(GRAD_MARKER, &grad)
        .replace(F_GRAD_MARKER, &f_grad)
        .replace(INTERVAL_MARKER, &interval);
    let module = validate(&source)?;
    Ok(Shader { source, module })
}

/// Parses and validates WGSL with naga (all capabilities a WebGPU device has).
pub fn validate(source: &str) -> Result<naga::Module, CodegenError> {
    let module = naga::front::wgsl::parse_str(source)
        .map_err(|e| CodegenError::Parse(e.emit_to_string(source)))?;
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::default(),
    )
    .validate(&module)
    .map_err(|e| CodegenError::Validate(e.emit_to_string(source)))?;
    Ok(module)
}
