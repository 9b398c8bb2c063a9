//! A formula made ready for the GPU: compiled (parsed, lowered, differentiated, its tapes
//! made) and its shader generated and validated, with the time of each. What a front end
//! makes of a formula's text before it builds a tree for it; cheap enough (milliseconds)
//! for every keystroke.

use std::sync::Arc;

use web_time::Instant;

use crate::formula::CompiledFormula;
use crate::syntax::SourceError;

use super::shader::{CodegenError, Shader, generate};

/// A compiled formula and its validated shader, shared (cloning is cheap).
#[derive(Debug, Clone)]
pub struct Program {
    pub formula: Arc<CompiledFormula>,
    pub shader: Arc<Shader>,
    /// Milliseconds of the compile (parse, lowering, derivatives, tapes).
    pub compile_ms: f64,
    /// Milliseconds of the shader's generation and naga's validation.
    pub codegen_ms: f64,
}

/// Why a formula's text is not a program: the text itself (with its span, for a caret), or
/// a shader the formula needs that the GPU cannot take.
#[derive(Debug, Clone, thiserror::Error)]
pub enum ProgramError {
    #[error("{}", .0.message)]
    Formula(SourceError),
    #[error("the shader for this formula is invalid: {0}")]
    Shader(CodegenError),
}

impl Program {
    /// Compiles `text` and generates its shader.
    pub fn new(text: &str) -> Result<Self, ProgramError> {
        let started = Instant::now();
        let formula = CompiledFormula::compile(text).map_err(ProgramError::Formula)?;
        let compile_ms = ms(started);
        let started = Instant::now();
        let shader = generate(&formula).map_err(ProgramError::Shader)?;
        Ok(Self {
            formula: Arc::new(formula),
            shader: Arc::new(shader),
            compile_ms,
            codegen_ms: ms(started),
        })
    }
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}
