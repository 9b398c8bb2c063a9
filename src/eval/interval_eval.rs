//! Interval evaluation of a [`Tape`] over a box: an enclosure of each output's range.
//! Sound because every [`Interval`] operation is.

use crate::expr::{BinaryOp, UnaryOp};

use super::interval::Interval;
use super::tape::{Instr, Tape};

/// A box of R⁴: one interval per axis (x, y, z, w).
pub type Box4 = [Interval; 4];

/// Reusable interval evaluator.
#[derive(Debug, Clone, Default)]
pub struct IntervalEvaluator {
    slots: Vec<Interval>,
}

impl IntervalEvaluator {
    pub fn new() -> Self {
        Self::default()
    }

    /// Evaluates every output of `tape` over `bx`, writing them into `out`.
    pub fn eval_into(&mut self, tape: &Tape, bx: &Box4, params: &[f64], out: &mut [Interval]) {
        self.slots.clear();
        self.slots.reserve(tape.len());
        for instr in tape.instrs() {
            let s = &self.slots;
            let v = match *instr {
                Instr::Const(c) => Interval::point(c),
                Instr::Var(a) => bx[a as usize],
                Instr::Param(i) => Interval::point(params.get(i as usize).copied().unwrap_or(1.0)),
                Instr::Unary(op, a) => unary(op, s[a as usize]),
                Instr::Binary(op, a, b) => binary(op, s[a as usize], s[b as usize]),
                Instr::Powi(a, n) => s[a as usize].powi(n),
            };
            self.slots.push(v);
        }
        for (o, &slot) in out.iter_mut().zip(tape.outputs()) {
            *o = self.slots[slot as usize];
        }
    }

    /// The first output of `tape` over `bx`.
    pub fn eval(&mut self, tape: &Tape, bx: &Box4, params: &[f64]) -> Interval {
        let mut out = [Interval::EMPTY];
        self.eval_into(tape, bx, params, &mut out);
        out[0]
    }
}

/// The interval extension of a unary operation.
pub fn unary(op: UnaryOp, a: Interval) -> Interval {
    match op {
        UnaryOp::Neg => a.neg(),
        UnaryOp::Abs => a.abs(),
        UnaryOp::Sqrt => a.sqrt(),
        UnaryOp::Cbrt => a.cbrt(),
        UnaryOp::Exp => a.exp(),
        UnaryOp::Ln => a.ln(),
        UnaryOp::Sin => a.sin(),
        UnaryOp::Cos => a.cos(),
        UnaryOp::Tan => a.tan(),
        UnaryOp::Asin => a.asin(),
        UnaryOp::Acos => a.acos(),
        UnaryOp::Atan => a.atan(),
        UnaryOp::Sinh => a.sinh(),
        UnaryOp::Cosh => a.cosh(),
        UnaryOp::Tanh => a.tanh(),
        UnaryOp::Sign => a.sign(),
        UnaryOp::Step => a.step(),
    }
}

/// The interval extension of a binary operation.
pub fn binary(op: BinaryOp, a: Interval, b: Interval) -> Interval {
    match op {
        BinaryOp::Add => a.add(b),
        BinaryOp::Sub => a.sub(b),
        BinaryOp::Mul => a.mul(b),
        BinaryOp::Div => a.div(b),
        BinaryOp::Pow => a.pow(b),
        BinaryOp::Min => a.min(b),
        BinaryOp::Max => a.max(b),
        BinaryOp::Atan2 => a.atan2(b),
    }
}
