//! Point evaluation in f64 of a [`Tape`]: F, or F and ∇F. Outside a function's domain the
//! value is NaN (each operation's `point` in `crate::ops`); callers treat NaN as "undefined".

use crate::ops::powi;

use super::tape::{Op, PrefixKey, Tape, prepare_slots};

/// Reusable evaluator; holds its slot storage so repeated calls do not allocate.
#[derive(Debug, Clone, Default)]
pub struct PointEvaluator {
    slots: Vec<f64>,
    prefix: PrefixKey,
}

impl PointEvaluator {
    pub fn new() -> Self {
        Self::default()
    }

    /// Evaluates every output of `tape` at `p`, writing them into `out`.
    pub fn eval_into(&mut self, tape: &Tape, p: [f64; 4], params: &[f64], out: &mut [f64]) {
        let (slots, start) = prepare_slots(&mut self.slots, &mut self.prefix, tape, params, 0.0);
        for (i, op) in tape.ops().iter().enumerate().skip(start) {
            let v = match *op {
                Op::Const(c) => c,
                Op::Var(a) => p[a as usize & 3],
                Op::Param(i) => params.get(i as usize).copied().unwrap_or(1.0),
                Op::Add(a, b) => slots[a as usize] + slots[b as usize],
                Op::Sub(a, b) => slots[a as usize] - slots[b as usize],
                Op::Mul(a, b) => slots[a as usize] * slots[b as usize],
                Op::Neg(a) => -slots[a as usize],
                Op::Square(a) => powi(slots[a as usize], 2),
                Op::Powi(a, n) => powi(slots[a as usize], n),
                Op::Unary(op, a) => (op.spec().point)(slots[a as usize]),
                Op::Binary(op, a, b) => (op.spec().point)(slots[a as usize], slots[b as usize]),
            };
            slots[i] = v;
        }
        for (o, &slot) in out.iter_mut().zip(tape.outputs()) {
            *o = slots[slot as usize];
        }
    }

    /// The first output of `tape` at `p` (F, for the formula's tapes).
    pub fn eval(&mut self, tape: &Tape, p: [f64; 4], params: &[f64]) -> f64 {
        let mut out = [0.0];
        self.eval_into(tape, p, params, &mut out);
        out[0]
    }
}
