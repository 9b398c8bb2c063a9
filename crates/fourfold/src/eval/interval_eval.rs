//! Interval evaluation of a [`Tape`] over a box: an enclosure of each output's range.
//! Sound because every [`Interval`] operation is.

use crate::expr::{BinaryOp, UnaryOp};

use super::tape::{Op, PrefixKey, Run, Tape, plan, prepare_slots};
use crate::interval::Interval;

/// A box of R⁴: one interval per axis (x, y, z, w).
pub type Box4 = [Interval; 4];

/// Reusable interval evaluator.
#[derive(Debug, Clone, Default)]
pub struct IntervalEvaluator {
    slots: Vec<Interval>,
    prefix: PrefixKey,
    /// Where the evaluator keeps values from one box to the next (see [`Self::keeping`]).
    kept: Option<Box<Kept>>,
}

/// The box whose values the slots hold (as bits; None: they hold none) and, for the tape
/// and parameters they hold, the instructions to run by the sides that moved since.
#[derive(Debug, Clone, Default)]
struct Kept {
    last: Option<[[u64; 2]; 4]>,
    runs: [Option<Run>; 16],
}

impl IntervalEvaluator {
    pub fn new() -> Self {
        Self::default()
    }

    /// An evaluator whose slots keep their values from one call to the next: an
    /// instruction that reads none of the box's sides that changed since is not run again
    /// (as `PointEvaluator` does). For boxes that share most of their sides, one after the
    /// other, such as points of one pixel's slice line; where every side moves (boxes of a
    /// turned plane) it costs a little more than [`Self::new`]'s.
    pub fn keeping() -> Self {
        Self {
            kept: Some(Box::default()),
            ..Self::default()
        }
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
        let only = self.kept.as_deref_mut().and_then(|kept| {
            let sides = bx.map(|x| [x.lo().to_bits(), x.hi().to_bits()]);
            if start == 0 {
                kept.runs.iter_mut().for_each(|r| *r = None);
            }
            let moved = match kept.last.filter(|_| start > 0) {
                Some(last) => (0..4).fold(0u8, |m, k| m | (u8::from(last[k] != sides[k]) << k)),
                None => 0xf,
            };
            kept.last = Some(sides);
            (moved != 0xf)
                .then(|| plan(&mut kept.runs, tape, moved))
                .flatten()
        });
        if let Some(list) = only {
            for &(i, op) in list {
                slots[i as usize] = apply!(op, bx, params, |k| slots[k as usize]);
            }
        } else {
            for (i, &op) in tape.ops().iter().enumerate().skip(start) {
                slots[i] = apply!(op, bx, params, |k| slots[k as usize]);
            }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::CompiledFormula;
    use proptest::prelude::*;

    /// A side's next value: kept, or one of a few (points, both zeros, spans across 0,
    /// unbounded, empty).
    fn side() -> impl Strategy<Value = Option<Interval>> {
        prop::option::of(prop::sample::select(vec![
            Interval::point(0.0),
            Interval::point(-0.0),
            Interval::point(0.5),
            Interval::new(-1.25, 0.75),
            Interval::new(1e-3, 2.0),
            Interval::new(-3.0, -0.5),
            Interval::new(0.0, f64::INFINITY),
            Interval::EMPTY,
        ]))
    }

    proptest! {
        /// An evaluator that keeps the values of instructions reading no side that moved
        /// gives, over each box of a walk that moves some sides at a time and changes the
        /// parameters now and then, what a new one gives, and the same continuity.
        #[test]
        fn kept_values_are_those_a_new_evaluator_computes(
            steps in prop::collection::vec((prop::array::uniform4(side()), 0..4u8), 1..40),
        ) {
            let formulas = [
                "1/x + sqrt(y) * sin(z*k) - atan2(w, x) + y^3",
                "(x^2 + y^2 + z^2 + R^2 - r^2)^2 - 4R^2(x^2 + y^2) - w",
                "ln(z - x) + abs(w) * cos(3y) - max(x, k)",
            ];
            for src in formulas {
                let f = CompiledFormula::compile(src).unwrap();
                let mut kept = [IntervalEvaluator::keeping(), IntervalEvaluator::keeping()];
                let mut bx = [Interval::point(0.25); 4];
                for &(moves, k) in &steps {
                    for (c, m) in bx.iter_mut().zip(moves) {
                        *c = m.unwrap_or(*c);
                    }
                    let params = [f64::from(k), 2.0, 1.0];
                    for (kept, tape) in kept.iter_mut().zip([&f.tape_f, &f.tape_all]) {
                        let (mut a, mut b) = ([Interval::EMPTY; 5], [Interval::EMPTY; 5]);
                        let n = tape.outputs().len();
                        let mut fresh = IntervalEvaluator::new();
                        kept.eval_into(tape, &bx, &params, &mut a[..n]);
                        fresh.eval_into(tape, &bx, &params, &mut b[..n]);
                        let bits = |v: &[Interval]| -> Vec<[u64; 2]> {
                            v.iter().map(|x| [x.lo().to_bits(), x.hi().to_bits()]).collect()
                        };
                        prop_assert_eq!(bits(&a), bits(&b), "{} over {:?}", src, bx);
                        prop_assert_eq!(
                            kept.continuous_on_last_box(tape),
                            fresh.continuous_on_last_box(tape)
                        );
                    }
                }
            }
        }
    }
}
