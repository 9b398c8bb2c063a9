//! The operations of the formula language, as the graph, the evaluators and the shader name
//! them, and what a derivative rule builds with.

/// Index of a node in an expression graph (`crate::expr::ExprGraph`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct NodeId(pub u32);

impl NodeId {
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// One-argument operations, in the order the language lists its functions (the table in
/// `unary.rs` follows it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum UnaryOp {
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Sinh,
    Cosh,
    Tanh,
    Exp,
    Ln,
    Sqrt,
    Cbrt,
    Abs,
    /// −1, 0 or 1: the derivative of |u| is sign(u)·u'.
    Sign,
    /// Heaviside step, 0 below 0, 1 above, ½ at 0: selects a branch in d min / d max.
    Step,
    Neg,
}

/// Two-argument operations, functions first (the table in `binary.rs` follows this order).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum BinaryOp {
    Min,
    Max,
    /// Real power a^b for a non-integer exponent: defined for a ≥ 0 only.
    Pow,
    /// atan2(y, x), as in every maths library.
    Atan2,
    Add,
    Sub,
    Mul,
    Div,
}

/// What a derivative rule builds with: the expression graph's simplifying constructors (the
/// graph implements it), so that rules share nodes with F and fold constants as they go.
pub trait Builder {
    fn constant(&mut self, value: f64) -> NodeId;
    fn unary(&mut self, op: UnaryOp, a: NodeId) -> NodeId;
    fn binary(&mut self, op: BinaryOp, a: NodeId, b: NodeId) -> NodeId;
    /// An integer power.
    fn powi(&mut self, a: NodeId, n: i32) -> NodeId;
    /// Whether `a` is the constant `value`.
    fn is_const(&self, a: NodeId, value: f64) -> bool;
}

/// Shorthands for the rules: `b.mul(x, y)` for `b.binary(BinaryOp::Mul, x, y)`, …
pub(super) trait Build: Builder {
    fn add(&mut self, a: NodeId, b: NodeId) -> NodeId {
        self.binary(BinaryOp::Add, a, b)
    }
    fn sub(&mut self, a: NodeId, b: NodeId) -> NodeId {
        self.binary(BinaryOp::Sub, a, b)
    }
    fn mul(&mut self, a: NodeId, b: NodeId) -> NodeId {
        self.binary(BinaryOp::Mul, a, b)
    }
    fn div(&mut self, a: NodeId, b: NodeId) -> NodeId {
        self.binary(BinaryOp::Div, a, b)
    }
    fn neg(&mut self, a: NodeId) -> NodeId {
        self.unary(UnaryOp::Neg, a)
    }
}

impl<B: Builder + ?Sized> Build for B {}
