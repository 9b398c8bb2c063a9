//! WGSL for F, ∇F and both at once (`ff_f_grad`, for the march's step bound), and their
//! rigorous interval enclosures (certified pixels), spliced into `templates/raycast.wgsl`
//! and validated by naga. Parameters are read from the frame's settings (binding 0) and
//! constants from the formula's table (binding 7), so changing either needs no new shader.

mod constants;
mod interpreter;
mod source;
mod tapes;

pub use interpreter::{InterpretError, REGISTERS, encode_tape, interpreter, program};
pub use source::{
    CodegenError, INTERVAL_LIBRARY, MAX_PARAMS, Shader, TEMPLATE, generate, listing, validate,
};
