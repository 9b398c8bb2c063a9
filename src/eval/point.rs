//! Point evaluation in f64 of a [`Tape`]: F, or F and ∇F. Outside a function's domain the
//! value is NaN (see [`crate::expr::graph::apply_unary`]); callers treat NaN as "undefined".

use crate::expr::graph::{apply_binary, apply_powi, apply_unary};

use super::tape::{Instr, Tape};

/// Reusable evaluator; holds its slot storage so repeated calls do not allocate.
#[derive(Debug, Clone, Default)]
pub struct PointEvaluator {
    slots: Vec<f64>,
}

impl PointEvaluator {
    pub fn new() -> Self {
        Self::default()
    }

    /// Evaluates every output of `tape` at `p`, writing them into `out`.
    pub fn eval_into(&mut self, tape: &Tape, p: [f64; 4], params: &[f64], out: &mut [f64]) {
        self.slots.clear();
        self.slots.reserve(tape.len());
        for instr in tape.instrs() {
            let s = &self.slots;
            let v = match *instr {
                Instr::Const(c) => c,
                Instr::Var(a) => p[a as usize],
                Instr::Param(i) => params.get(i as usize).copied().unwrap_or(1.0),
                Instr::Unary(op, a) => apply_unary(op, s[a as usize]),
                Instr::Binary(op, a, b) => apply_binary(op, s[a as usize], s[b as usize]),
                Instr::Powi(a, n) => apply_powi(s[a as usize], n),
            };
            self.slots.push(v);
        }
        for (o, &slot) in out.iter_mut().zip(tape.outputs()) {
            *o = self.slots[slot as usize];
        }
    }

    /// The first output of `tape` at `p` (F, for the formula's tapes).
    pub fn eval(&mut self, tape: &Tape, p: [f64; 4], params: &[f64]) -> f64 {
        let mut out = [0.0];
        self.eval_into(tape, p, params, &mut out);
        out[0]
    }
}
