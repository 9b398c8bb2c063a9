//! The words of the formula language that are not parameters: the names its functions are
//! called by (read from the tables) and its named constants.

use super::binary::BINARY;
use super::op::{BinaryOp, UnaryOp};
use super::unary::UNARY;

/// Named constants of the language.
pub const CONSTANTS: &[(&str, f64)] = &[
    ("pi", std::f64::consts::PI),
    ("tau", std::f64::consts::TAU),
    ("e", std::f64::consts::E),
];

/// A function a formula calls by name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Function {
    Unary(UnaryOp),
    /// `pow(a, b)` is `a^b`, with the integer-exponent rules of `^`.
    Binary(BinaryOp),
}

impl Function {
    /// How many arguments it takes.
    pub fn arity(self) -> usize {
        match self {
            Function::Unary(_) => 1,
            Function::Binary(_) => 2,
        }
    }
}

/// The function a formula calls `name`, if any.
pub fn function(name: &str) -> Option<Function> {
    let unary = UNARY
        .iter()
        .filter(|s| s.callable)
        .find(|s| s.name == name || s.aliases.contains(&name))
        .map(|s| Function::Unary(s.op));
    unary.or_else(|| {
        BINARY
            .iter()
            .find(|s| s.callable && s.name == name)
            .map(|s| Function::Binary(s.op))
    })
}

/// Every name a formula may call a function by, in the language's order (each function's
/// aliases after its name).
pub fn function_names() -> impl Iterator<Item = &'static str> {
    let unary = UNARY
        .iter()
        .filter(|s| s.callable)
        .flat_map(|s| std::iter::once(s.name).chain(s.aliases.iter().copied()));
    unary.chain(BINARY.iter().filter(|s| s.callable).map(|s| s.name))
}
