//! Stage 1 of the pipeline: formula text → syntax tree, with located, explained errors.

pub mod ast;
pub mod diagnostic;
pub mod parser;

pub use ast::{BinOp, Expr, ExprKind, Formula, Span};
pub use diagnostic::{CaretWindow, SourceError};
pub use parser::parse;
