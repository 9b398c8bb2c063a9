//! Interval evaluation of a [`Tape`] over a box: an enclosure of each output's range.
//! Sound because every [`Interval`] operation is.

use crate::expr::{BinaryOp, UnaryOp};

use super::plan::{Moves, run_tape};
use super::tape::{Op, Tape, sized};
use crate::interval::Interval;

/// A box of R⁴: one interval per axis (x, y, z, w).
pub type Box4 = [Interval; 4];

/// Reusable interval evaluator. As the point evaluator's, its slots keep their values from
/// one call to the next, and an instruction reading none of the coordinates whose interval
/// changed since is not run again (a tile's lines along an axis: x^6 and y^6 of a slice
/// seen along z are the same for all their pieces).
#[derive(Debug, Clone, Default)]
pub struct IntervalEvaluator {
    slots: Vec<Interval>,
    /// The tape, parameters and box the slots hold the values of, and what each set of
    /// moved coordinates runs.
    moves: Moves<[u64; 2]>,
}

impl IntervalEvaluator {
    pub fn new() -> Self {
        Self::default()
    }

    /// Evaluates every output of `tape` over `bx`, writing them into `out`.
    pub fn eval_into(&mut self, tape: &Tape, bx: &Box4, params: &[f64], out: &mut [Interval]) {
        let bits = bx.map(|x| [x.lo().to_bits(), x.hi().to_bits()]);
        let (moved, stale) = self.moves.since(tape, params, bits);
        let slots = sized(&mut self.slots, tape, Interval::EMPTY);
        run_tape!(
            slots,
            &mut self.moves.plans,
            tape,
            (moved, stale),
            interval_op(bx, params)
        );
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

/// Instruction `op`'s enclosure over `bx`, its operands in `slots`.
#[inline(always)]
fn interval_op(op: Op, slots: &[Interval], bx: &Box4, params: &[f64]) -> Interval {
    apply!(op, bx, params, |k| slots[k as usize])
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::formula::CompiledFormula;
    use proptest::prelude::*;

    proptest! {
        /// An evaluator that ran other boxes before, some of their coordinates the same
        /// (the instructions reading only those not run again), encloses each box bit for
        /// bit as a new one does.
        #[test]
        fn boxes_after_others_are_enclosed_as_by_a_new_evaluator(
            which in 0..3usize,
            boxes in prop::collection::vec(
                (prop::array::uniform4(-2.0f64..2.0), prop::array::uniform4(0.0f64..1.0), 0u8..16),
                1..12,
            ),
        ) {
            let text = [
                "x^6 + y^6 + z^6 + w^6 + 4x^2 y^2 z^2 - 1",
                "sqrt(x^2 + y^2) - sin(3z) * w + a",
                "max(abs(x), y z) - exp(w) / (1 + x^2)",
            ][which];
            let f = CompiledFormula::compile(text).unwrap();
            let mut kept = IntervalEvaluator::new();
            let mut bx: Box4 = [Interval::new(0.0, 0.5); 4];
            for (lo, width, keep) in boxes {
                // (Bit k of `keep`: coordinate k stays as it was.)
                for k in (0..4).filter(|&k| keep & (1 << k) == 0) {
                    bx[k] = Interval::new(lo[k], lo[k] + width[k]);
                }
                let (mut fresh, mut again) = ([Interval::EMPTY; 5], [Interval::EMPTY; 5]);
                let mut new = IntervalEvaluator::new();
                new.eval_into(&f.tape_all, &bx, &[0.5], &mut fresh);
                kept.eval_into(&f.tape_all, &bx, &[0.5], &mut again);
                let bits = |v: [Interval; 5]| v.map(|x| [x.lo().to_bits(), x.hi().to_bits()]);
                prop_assert_eq!(bits(fresh), bits(again));
                prop_assert_eq!(
                    kept.continuous_on_last_box(&f.tape_all),
                    new.continuous_on_last_box(&f.tape_all)
                );
            }
        }
    }
}
