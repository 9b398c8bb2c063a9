//! Stage 2: the expression graph (hash-consed DAG), lowering from syntax, symbolic
//! derivatives and infix printing.

pub mod deriv;
pub mod display;
pub mod graph;
pub mod lower;

pub use deriv::derivative;
pub use display::to_infix;
pub use graph::{BinaryOp, ExprGraph, Node, NodeId, UnaryOp, VARIABLES};
