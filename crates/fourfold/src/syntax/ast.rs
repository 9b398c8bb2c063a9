//! The syntax tree of a formula, as written: every node keeps the byte span it came from so
//! that later stages (name resolution, lowering) can point at the source in their errors.

use std::ops::Range;

/// A byte range in the formula text.
pub type Span = Range<usize>;

/// A parsed formula: `lhs` alone, or the equation `lhs = rhs` (meaning F = lhs − rhs).
#[derive(Debug, Clone, PartialEq)]
pub struct Formula {
    pub lhs: Expr,
    pub rhs: Option<Expr>,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Expr {
    pub kind: ExprKind,
    pub span: Span,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BinOp {
    Add,
    Sub,
    Mul,
    Div,
    Pow,
}

#[derive(Debug, Clone, PartialEq)]
pub enum ExprKind {
    Number(f64),
    /// A variable, constant, parameter or run of variables such as `xy`; resolved when lowered.
    Ident(String),
    Neg(Box<Expr>),
    Binary(BinOp, Box<Expr>, Box<Expr>),
    /// `name(args)`: a function call, or (for a parameter name) an implicit product.
    Call {
        name: String,
        name_span: Span,
        args: Vec<Expr>,
    },
    /// `|expr|`
    Abs(Box<Expr>),
}

impl Expr {
    pub fn new(kind: ExprKind, span: Span) -> Self {
        Self { kind, span }
    }
}
