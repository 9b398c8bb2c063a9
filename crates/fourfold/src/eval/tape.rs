//! A straight-line program over the nodes that some outputs need: the graph's topological
//! order, renumbered densely. Point and interval evaluation both walk it once, front to back.
//!
//! Instructions that depend only on constants and parameters (`R^2 - r^2`, `4R^2`) come
//! first, as a *uniform prefix*: an evaluator computes it once per parameter set and then only
//! the rest per point or box. (Moving them ahead keeps the order topological: a uniform
//! instruction's operands are uniform too.)

use std::sync::atomic::{AtomicU64, Ordering};

use crate::expr::graph::operands;
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

/// The evaluators' form of an instruction: one flat enum, so that their loops dispatch once
/// per instruction (the common arithmetic has its own variants).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Op {
    Const(f64),
    Var(u8),
    Param(u32),
    Add(u32, u32),
    Sub(u32, u32),
    Mul(u32, u32),
    Neg(u32),
    Square(u32),
    Powi(u32, i32),
    Unary(UnaryOp, u32),
    Binary(BinaryOp, u32, u32),
}

impl Op {
    /// Whether the instruction calls a library function (a power k ≤ 0 among them), which
    /// an evaluator of many points at once runs point by point: the rest is arithmetic
    /// that runs for all of them together.
    pub fn calls_library(&self) -> bool {
        matches!(self, Op::Powi(_, ..=0) | Op::Unary(..) | Op::Binary(..))
    }
}

impl From<Instr> for Op {
    fn from(instr: Instr) -> Self {
        match instr {
            Instr::Const(v) => Op::Const(v),
            Instr::Var(a) => Op::Var(a & 3),
            Instr::Param(i) => Op::Param(i),
            Instr::Unary(UnaryOp::Neg, a) => Op::Neg(a),
            Instr::Unary(op, a) => Op::Unary(op, a),
            Instr::Binary(BinaryOp::Add, a, b) => Op::Add(a, b),
            Instr::Binary(BinaryOp::Sub, a, b) => Op::Sub(a, b),
            Instr::Binary(BinaryOp::Mul, a, b) => Op::Mul(a, b),
            Instr::Binary(op, a, b) => Op::Binary(op, a, b),
            Instr::Powi(a, 2) => Op::Square(a),
            Instr::Powi(a, n) => Op::Powi(a, n),
        }
    }
}

/// A straight-line program: slot i holds the value of instruction i.
#[derive(Debug, Clone)]
pub struct Tape {
    instrs: Vec<Instr>,
    ops: Vec<Op>,
    outputs: Vec<u32>,
    uniform_len: usize,
    /// The coordinates each instruction reads, itself or through its operands: bit k for
    /// x_k (0 for the uniform prefix).
    reads: Vec<u8>,
    /// Distinct per `Tape::new` (clones share it: same content), so an evaluator can tell
    /// whether its cached uniform prefix belongs to this tape.
    id: u64,
}

static NEXT_TAPE_ID: AtomicU64 = AtomicU64::new(1);

impl Tape {
    /// The program that computes `outputs` of `graph`, in that order.
    pub fn new(graph: &ExprGraph, outputs: &[NodeId]) -> Self {
        let needed = graph.reachable(outputs);
        // A node is uniform when it reads no coordinate.
        let mut uniform = vec![false; graph.len()];
        for (i, node) in graph.nodes().iter().enumerate() {
            uniform[i] = match *node {
                Node::Const(_) | Node::Param(_) => true,
                Node::Var(_) => false,
                Node::Unary(_, a) | Node::Powi(a, _) => uniform[a.index()],
                Node::Binary(_, a, b) => uniform[a.index()] && uniform[b.index()],
            };
        }
        // The order of the instructions: the uniform ones, then the others, each in the
        // graph's order; but the constants first of all, in the order those instructions
        // (then the outputs) first read them, not in the order the graph made them. So two
        // formulas that differ only in their numbers have the same tape but for them, and
        // the same shader (`render::shader::constants`), whichever number the graph met
        // first (x^3's exponent makes a 3 before sin(3 z)'s, 2.5 comes after y^2's 2).
        let mut order: Vec<usize> = Vec::new();
        for pass_uniform in [true, false] {
            order.extend((0..graph.len()).filter(|&i| {
                needed[i]
                    && uniform[i] == pass_uniform
                    && !matches!(graph.nodes()[i], Node::Const(_))
            }));
        }
        let mut constants: Vec<usize> = Vec::new();
        let mut placed = vec![false; graph.len()];
        let reads = order
            .iter()
            .flat_map(|&i| operands(graph.nodes()[i]))
            .chain(outputs.iter().copied());
        for id in reads {
            if matches!(graph.nodes()[id.index()], Node::Const(_)) && !placed[id.index()] {
                placed[id.index()] = true;
                constants.push(id.index());
            }
        }
        let mut slot = vec![u32::MAX; graph.len()];
        let mut instrs = Vec::new();
        for i in constants.into_iter().chain(order) {
            let s = |id: NodeId| slot[id.index()];
            let instr = match graph.nodes()[i] {
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
        let uniform_len = (0..graph.len())
            .filter(|&i| needed[i] && uniform[i])
            .count();
        let outputs = outputs.iter().map(|o| slot[o.index()]).collect();
        let ops = instrs.iter().map(|&i| Op::from(i)).collect();
        let mut reads: Vec<u8> = Vec::with_capacity(instrs.len());
        for instr in &instrs {
            let of = |a: u32| reads[a as usize];
            let r = match *instr {
                Instr::Const(_) | Instr::Param(_) => 0,
                Instr::Var(a) => 1 << (a & 3),
                Instr::Unary(_, a) | Instr::Powi(a, _) => of(a),
                Instr::Binary(_, a, b) => of(a) | of(b),
            };
            reads.push(r);
        }
        Self {
            instrs,
            ops,
            outputs,
            uniform_len,
            reads,
            id: NEXT_TAPE_ID.fetch_add(1, Ordering::Relaxed),
        }
    }

    /// How many leading instructions depend on constants and parameters only.
    pub fn uniform_len(&self) -> usize {
        self.uniform_len
    }

    /// Identity of this program (shared by clones).
    pub fn id(&self) -> u64 {
        self.id
    }

    pub fn instrs(&self) -> &[Instr] {
        &self.instrs
    }

    /// The instructions in the evaluators' flat form.
    pub fn ops(&self) -> &[Op] {
        &self.ops
    }

    /// Whether an instruction past the uniform prefix calls a library function (see
    /// [`Op::calls_library`]): where none does, a tape at many points at once is
    /// arithmetic alone.
    pub fn calls_library(&self) -> bool {
        self.ops[self.uniform_len..].iter().any(Op::calls_library)
    }

    /// The coordinates each instruction reads (bit k: x_k), itself or through its operands.
    pub fn reads(&self) -> &[u8] {
        &self.reads
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

/// The coordinates (bit k: x_k) that differ between a point's `last` (bits; None: no point,
/// all differ) and `now`: the instructions reading them are the ones to run again.
pub(crate) fn moved<T: PartialEq>(last: Option<[T; 4]>, now: &[T; 4]) -> u8 {
    match last {
        Some(last) => (0..4).fold(0, |m, k| m | (u8::from(last[k] != now[k]) << k)),
        None => 0xf,
    }
}

/// Remembers for which tape and parameter values an evaluator's uniform prefix was computed.
#[derive(Debug, Clone, Default)]
pub(crate) struct PrefixKey {
    tape: u64,
    params: Vec<u64>,
}

/// Sizes `slots` for `tape` and returns them with the index of the first instruction to run:
/// 0 when the uniform prefix must be (re)computed, else the prefix's length.
pub(crate) fn prepare_slots<'a, T: Copy>(
    slots: &'a mut Vec<T>,
    key: &mut PrefixKey,
    tape: &Tape,
    params: &[f64],
    fill: T,
) -> (&'a mut [T], usize) {
    let start = if key.stale(tape, params) {
        0
    } else {
        tape.uniform_len()
    };
    (sized(slots, tape, fill), start)
}

/// `slots` grown to hold `tape`'s, and as many of them.
pub(crate) fn sized<'a, T: Copy>(slots: &'a mut Vec<T>, tape: &Tape, fill: T) -> &'a mut [T] {
    let n = tape.len();
    if slots.len() < n {
        slots.resize(n, fill);
    }
    &mut slots[..n]
}

impl PrefixKey {
    /// True when the prefix must be (re)computed for `tape` and `params`; records them.
    pub(crate) fn stale(&mut self, tape: &Tape, params: &[f64]) -> bool {
        let same = self.tape == tape.id
            && self.params.len() == params.len()
            && self
                .params
                .iter()
                .zip(params)
                .all(|(a, b)| *a == b.to_bits());
        if !same {
            self.tape = tape.id;
            self.params.clear();
            self.params.extend(params.iter().map(|p| p.to_bits()));
        }
        !same
    }
}
