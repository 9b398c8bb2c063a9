//! The formula language's operations, each a row of one table ([`UNARY`], [`BINARY`]): its
//! name, its value at a point, its interval extension and continuity, its derivative rule,
//! and its WGSL. Lowering, folding, differentiation, printing, both evaluators and the
//! shader's code generation all read the rows, so adding a function to the language is
//! adding a row (and its interval rule where it needs one). Beneath the pipeline, beside
//! [`crate::interval`].

mod binary;
mod op;
mod unary;
mod words;

pub use binary::{BINARY, BinarySpec, Operands};
pub use op::{BinaryOp, Builder, NodeId, UnaryOp};
pub use unary::{UNARY, UnarySpec};
pub use words::{CONSTANTS, Function, function, function_names};

/// `v^n` for an integer `n` (the graph's integer powers, which are not a function of the
/// language but what `^` with an integer exponent becomes): undefined at 0 for n < 0.
pub fn powi(v: f64, n: i32) -> f64 {
    if v == 0.0 && n < 0 {
        return f64::NAN;
    }
    v.powi(n)
}
