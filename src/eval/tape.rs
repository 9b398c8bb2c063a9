//! A straight-line program over the nodes that some outputs need: the graph's topological
//! order, renumbered densely. Point and interval evaluation both walk it once, front to back.

use crate::expr::{BinaryOp, ExprGraph, Node, NodeId, UnaryOp};

/// One instruction; operands are slots of earlier instructions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Instr {
    Const(f64),
    Var(u8),
    Param(u32),
    Unary(UnaryOp, u32),
    Binary(BinaryOp, u32, u32),
    Powi(u32, i32),
}

/// A straight-line program: slot i holds the value of instruction i.
#[derive(Debug, Clone, PartialEq)]
pub struct Tape {
    instrs: Vec<Instr>,
    outputs: Vec<u32>,
}

impl Tape {
    /// The program that computes `outputs` of `graph`, in that order.
    pub fn new(graph: &ExprGraph, outputs: &[NodeId]) -> Self {
        let needed = graph.reachable(outputs);
        let mut slot = vec![u32::MAX; graph.len()];
        let mut instrs = Vec::new();
        for (i, node) in graph.nodes().iter().enumerate() {
            if !needed[i] {
                continue;
            }
            let s = |id: NodeId| slot[id.index()];
            let instr = match *node {
                Node::Const(v) => Instr::Const(v),
                Node::Var(a) => Instr::Var(a),
                Node::Param(p) => Instr::Param(p),
                Node::Unary(op, a) => Instr::Unary(op, s(a)),
                Node::Binary(op, a, b) => Instr::Binary(op, s(a), s(b)),
                Node::Powi(a, n) => Instr::Powi(s(a), n),
            };
            slot[i] = instrs.len() as u32;
            instrs.push(instr);
        }
        let outputs = outputs.iter().map(|o| slot[o.index()]).collect();
        Self { instrs, outputs }
    }

    pub fn instrs(&self) -> &[Instr] {
        &self.instrs
    }

    pub fn outputs(&self) -> &[u32] {
        &self.outputs
    }

    pub fn len(&self) -> usize {
        self.instrs.len()
    }

    pub fn is_empty(&self) -> bool {
        self.instrs.is_empty()
    }
}
