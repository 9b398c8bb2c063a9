//! Interval evaluation of a [`Tape`] over a box: an enclosure of each output's range.
//! Sound because every [`Interval`] operation is.

use crate::expr::{BinaryOp, UnaryOp};

use super::tape::{Op, PrefixKey, Tape, prepare_slots};
use crate::interval::Interval;

/// A box of R⁴: one interval per axis (x, y, z, w).
pub type Box4 = [Interval; 4];

/// Reusable interval evaluator.
#[derive(Debug, Clone, Default)]
pub struct IntervalEvaluator {
    slots: Vec<Interval>,
    prefix: PrefixKey,
}

impl IntervalEvaluator {
    pub fn new() -> Self {
        Self::default()
    }

    /// Evaluates every output of `tape` over `bx`, writing them into `out`.
    pub fn eval_into(&mut self, tape: &Tape, bx: &Box4, params: &[f64], out: &mut [Interval]) {
        let (slots, start) = prepare_slots(
            &mut self.slots,
            &mut self.prefix,
            tape,
            params,
            Interval::EMPTY,
        );
        for (i, &op) in tape.ops().iter().enumerate().skip(start) {
            slots[i] = apply!(op, bx, params, |k| slots[k as usize]);
        }
        for (o, &slot) in out.iter_mut().zip(tape.outputs()) {
            *o = slots[slot as usize];
        }
    }

    /// Whether the function computed by `tape`, just evaluated by [`Self::eval_into`] or
    /// [`Self::eval`] over a box, is defined and continuous on the whole box as far as the
    /// enclosures tell: every value is bounded, and every operation with a restricted domain
    /// or a jump has its operands where it is defined and continuous (sqrt of x ≥ 0, ln of
    /// x > 0, asin and acos of [-1, 1], real powers of x > 0, no division by or negative
    /// power of an interval holding 0, sign and step away from 0, atan2 off its cut). Then the
    /// enclosures of its partial derivatives over the box bound its slope there (the mean
    /// value inequality holds for a continuous, piecewise differentiable function).
    pub fn continuous_on_last_box(&self, tape: &Tape) -> bool {
        continuous(tape, |i| self.slots[i as usize])
    }

    /// The first output of `tape` over `bx`.
    pub fn eval(&mut self, tape: &Tape, bx: &Box4, params: &[f64]) -> Interval {
        let mut out = [Interval::EMPTY];
        self.eval_into(tape, bx, params, &mut out);
        out[0]
    }
}

/// The value of instruction `$op` over the box `$bx`, where `|$k| $read` reads slot `$k`. A
/// macro, not a function taking a closure, which made the one-box loop slower.
macro_rules! apply {
    ($op:expr, $bx:expr, $params:expr, |$k:ident| $read:expr) => {{
        use $crate::eval::{Interval, Op};
        let slot = |$k: u32| $read;
        match $op {
            Op::Const(c) => Interval::point(c),
            Op::Var(a) => $bx[a as usize & 3],
            Op::Param(i) => Interval::point($params.get(i as usize).copied().unwrap_or(1.0)),
            Op::Add(a, b) => slot(a).add(slot(b)),
            Op::Sub(a, b) => slot(a).sub(slot(b)),
            Op::Mul(a, b) => slot(a).mul(slot(b)),
            Op::Neg(a) => slot(a).neg(),
            Op::Square(a) => slot(a).square(),
            Op::Powi(a, n) => slot(a).powi(n),
            Op::Unary(op, a) => $crate::eval::interval_eval::unary(op, slot(a)),
            Op::Binary(op, a, b) => $crate::eval::interval_eval::binary(op, slot(a), slot(b)),
        }
    }};
}
pub(crate) use apply;

/// See [`IntervalEvaluator::continuous_on_last_box`]; `slot` reads the evaluated slots.
/// Each operation's own condition is its row's `continuous` (`crate::ops`).
pub(crate) fn continuous(tape: &Tape, slot: impl Fn(u32) -> Interval) -> bool {
    tape.ops().iter().enumerate().all(|(i, op)| {
        let v = slot(i as u32);
        if v.is_empty() || !v.lo().is_finite() || !v.hi().is_finite() {
            return false;
        }
        match *op {
            Op::Powi(a, n) => n >= 0 || !slot(a).contains_zero(),
            Op::Unary(op, a) => (op.spec().continuous)(slot(a)),
            Op::Binary(op, a, b) => (op.spec().continuous)(slot(a), slot(b)),
            _ => true,
        }
    })
}

/// The interval extension of a unary operation.
#[inline]
pub fn unary(op: UnaryOp, a: Interval) -> Interval {
    (op.spec().interval)(a)
}

/// The interval extension of a binary operation.
#[inline]
pub fn binary(op: BinaryOp, a: Interval, b: Interval) -> Interval {
    (op.spec().interval)(a, b)
}
