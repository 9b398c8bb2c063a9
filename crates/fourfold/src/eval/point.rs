//! Point evaluation in f64 of a [`Tape`]: F, or F and ∇F. Outside a function's domain the
//! value is NaN (each operation's `point` in `crate::ops`); callers treat NaN as "undefined".
//! The CPU twin evaluates as the GPU does instead: each operation's result rounded to f32,
//! overflowing to ±∞ and with subnormals flushed to 0 (as lavapipe does), so that where a
//! formula leaves f32's range (`tan(1e300*k)`, `(w^3.84)^x` near w = 0) its pictures are
//! the GPU's, not f64's.

use crate::ops::powi;

use super::plan::{Moves, run_tape};
use super::tape::{Op, Tape, sized};

/// Reusable evaluator; holds its slot storage so repeated calls do not allocate. Its slots
/// keep their values from one call to the next: an instruction that reads none of the
/// coordinates that changed since (the uniform prefix: none at all) is not run again. Along
/// a ray parallel to an axis (a slice's seen square on), that is most of a tape.
#[derive(Debug, Clone, Default)]
pub struct PointEvaluator {
    slots: Vec<f64>,
    /// The slots of an evaluation in f32 (`single`).
    narrow_slots: Vec<f32>,
    /// The tape, parameters and point the slots hold the values of, and what each set of
    /// moved coordinates runs.
    moves: Moves<u64>,
    /// Round every operation's result to f32, as the GPU computes.
    single: bool,
}

impl PointEvaluator {
    pub fn new() -> Self {
        Self::default()
    }

    /// An evaluator that rounds every operation's result to f32 (see the module's note).
    pub fn single_precision() -> Self {
        Self {
            single: true,
            ..Self::default()
        }
    }

    /// Evaluates every output of `tape` at `p`, writing them into `out`.
    pub fn eval_into(&mut self, tape: &Tape, p: [f64; 4], params: &[f64], out: &mut [f64]) {
        if self.single {
            self.run_single(tape, p, params, out);
        } else {
            self.run_double(tape, p, params, out);
        }
    }

    fn run_double(&mut self, tape: &Tape, p: [f64; 4], params: &[f64], out: &mut [f64]) {
        let (moved, all) = self.moves.since(tape, params, p.map(f64::to_bits));
        let slots = sized(&mut self.slots, tape, 0.0);
        run_tape!(
            slots,
            &mut self.moves.plans,
            tape,
            (moved, all),
            double_op(p, params)
        );
        for (o, &slot) in out.iter_mut().zip(tape.outputs()) {
            *o = slots[slot as usize];
        }
    }

    /// As [`Self::run_double`] with each result rounded to f32 (see the module's note).
    fn run_single(&mut self, tape: &Tape, p: [f64; 4], params: &[f64], out: &mut [f64]) {
        let (moved, all) = self.moves.since(tape, params, p.map(f64::to_bits));
        let slots = sized(&mut self.narrow_slots, tape, 0.0);
        run_tape!(
            slots,
            &mut self.moves.plans,
            tape,
            (moved, all),
            single_op(p, params)
        );
        for (o, &slot) in out.iter_mut().zip(tape.outputs()) {
            *o = f64::from(slots[slot as usize]);
        }
    }

    /// The first output of `tape` at `p` (F, for the formula's tapes).
    pub fn eval(&mut self, tape: &Tape, p: [f64; 4], params: &[f64]) -> f64 {
        let mut out = [0.0];
        self.eval_into(tape, p, params, &mut out);
        out[0]
    }
}

/// Instruction `op`'s value at `p` in f64, its operands in `slots`.
#[inline(always)]
fn double_op(op: Op, slots: &[f64], p: [f64; 4], params: &[f64]) -> f64 {
    match op {
        Op::Const(c) => c,
        Op::Var(a) => p[a as usize & 3],
        Op::Param(i) => params.get(i as usize).copied().unwrap_or(1.0),
        Op::Add(a, b) => slots[a as usize] + slots[b as usize],
        Op::Sub(a, b) => slots[a as usize] - slots[b as usize],
        Op::Mul(a, b) => slots[a as usize] * slots[b as usize],
        Op::Neg(a) => -slots[a as usize],
        Op::Square(a) => slots[a as usize] * slots[a as usize],
        Op::Powi(a, n) => powi(slots[a as usize], n),
        Op::Unary(op, a) => (op.spec().point)(slots[a as usize]),
        Op::Binary(op, a, b) => (op.spec().point)(slots[a as usize], slots[b as usize]),
    }
}

/// As [`double_op`], rounded to f32. + − × run in f32 itself: on f32 operands, f32's
/// rounding of the exact result is f64's rounded again to f32 (53 ≥ 2 × 24 + 2 bits, so the
/// double rounding is harmless), at a third of the instructions; the other operations go
/// through f64.
#[inline(always)]
fn single_op(op: Op, slots: &[f32], p: [f64; 4], params: &[f64]) -> f32 {
    let wide = |a: u32| f64::from(slots[a as usize]);
    match op {
        Op::Const(c) => narrow(c),
        Op::Var(a) => narrow(p[a as usize & 3]),
        Op::Param(i) => narrow(params.get(i as usize).copied().unwrap_or(1.0)),
        Op::Add(a, b) => flush(slots[a as usize] + slots[b as usize]),
        Op::Sub(a, b) => flush(slots[a as usize] - slots[b as usize]),
        Op::Mul(a, b) => flush(slots[a as usize] * slots[b as usize]),
        Op::Neg(a) => -slots[a as usize],
        Op::Square(a) => flush(slots[a as usize] * slots[a as usize]),
        Op::Powi(a, n) => narrow(powi(wide(a), n)),
        Op::Unary(op, a) => narrow((op.spec().point)(wide(a))),
        Op::Binary(op, a, b) => narrow((op.spec().point)(wide(a), wide(b))),
    }
}

/// `x` rounded to the nearest f32 (±∞ beyond its range), subnormals flushed to 0.
#[inline(always)]
pub(super) fn narrow(x: f64) -> f32 {
    flush(x as f32)
}

/// `y`, or 0 of its sign where it is subnormal (as lavapipe flushes them).
#[inline(always)]
pub(super) fn flush(y: f32) -> f32 {
    if y.is_subnormal() {
        0.0f32.copysign(y)
    } else {
        y
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::CompiledFormula;
    use proptest::prelude::*;

    /// An f32 as the evaluator's slots hold them: any bit pattern, subnormals flushed.
    fn slot() -> impl Strategy<Value = f32> {
        any::<u32>().prop_map(|bits| flush(f32::from_bits(bits)))
    }

    /// The same bits, or both NaN (the payload is not part of the result).
    fn same(a: f32, b: f32) -> bool {
        a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
    }

    /// A coordinate's next value: kept, or one of a few that include both zeros.
    fn coordinate() -> impl Strategy<Value = Option<f64>> {
        prop::option::of(prop::sample::select(vec![0.0, -0.0, 0.5, -1.25, 2.0, 1e-3]))
    }

    proptest! {
        /// An evaluator that keeps the values of instructions reading no coordinate that
        /// moved gives, at each point of a walk that moves some coordinates at a time (to
        /// −0 from +0 too) and changes the parameters now and then, what a new one gives.
        #[test]
        fn kept_values_are_those_a_new_evaluator_computes(
            steps in prop::collection::vec((prop::array::uniform4(coordinate()), 0..4u8), 1..40),
            single in prop::bool::ANY,
        ) {
            let formulas = [
                "1/x + sqrt(y) * sin(z*k) - atan2(w, x) + y^3",
                "(x^2 + y^2 + z^2 + R^2 - r^2)^2 - 4R^2(x^2 + y^2) - w",
                "cos(3x) + cos(3y) + cos(3z) + cos(3w)",
            ];
            for src in formulas {
                let f = CompiledFormula::compile(src).unwrap();
                let make = || if single { PointEvaluator::single_precision() } else { PointEvaluator::new() };
                let (mut kept, mut p) = ([make(), make()], [0.25; 4]);
                for &(moves, k) in &steps {
                    for (c, m) in p.iter_mut().zip(moves) {
                        *c = m.unwrap_or(*c);
                    }
                    let params = [f64::from(k), 2.0, 1.0];
                    for (kept, tape) in kept.iter_mut().zip([&f.tape_f, &f.tape_all]) {
                        let (mut a, mut b) = ([0.0; 5], [0.0; 5]);
                        let n = tape.outputs().len();
                        kept.eval_into(tape, p, &params, &mut a[..n]);
                        make().eval_into(tape, p, &params, &mut b[..n]);
                        for (x, y) in a.iter().zip(b) {
                            prop_assert!(x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan()), "{src} at {p:?}: {a:?} against {b:?}");
                        }
                    }
                }
            }
        }

        /// `run_single`'s + − × in f32 give what f64's, rounded to f32 and flushed, give.
        #[test]
        fn f32_arithmetic_is_f64_s_rounded(a in slot(), b in slot()) {
            let (x, y) = (f64::from(a), f64::from(b));
            prop_assert!(same(flush(a + b), narrow(x + y)));
            prop_assert!(same(flush(a - b), narrow(x - y)));
            prop_assert!(same(flush(a * b), narrow(x * y)));
            prop_assert!(same(flush(a * a), narrow(x * x)));
        }

        /// The same near f32's smallest normals and largest values, where rounding decides
        /// between a normal, a flushed subnormal and ∞.
        #[test]
        fn f32_arithmetic_is_f64_s_rounded_at_the_edges(
            m in 1.0f32..2.0, n in 1.0f32..2.0, e in -70i32..70, s in prop::bool::ANY,
        ) {
            let a = m * 2f32.powi(e);
            let b = if s { -n } else { n } * 2f32.powi(e.signum() * 63);
            let (x, y) = (f64::from(a), f64::from(b));
            prop_assert!(same(flush(a * b), narrow(x * y)));
            let c = flush(b * 2f32.powi(-100));
            prop_assert!(same(flush(a - c), narrow(x - f64::from(c))));
        }
    }

    #[test]
    fn single_precision_leaves_f32_s_range_as_the_gpu_does() {
        let f = CompiledFormula::compile("tan(1e300*k) - x").unwrap();
        let p = [0.5, 0.0, 0.0, 0.0];
        assert!(PointEvaluator::new().eval(&f.tape_f, p, &[1.0]).is_finite());
        assert!(
            PointEvaluator::single_precision()
                .eval(&f.tape_f, p, &[1.0])
                .is_nan()
        );
        let f = CompiledFormula::compile("(w^3.84)^x").unwrap();
        let p = [1.0, 0.0, 0.0, 1e-11];
        assert!(PointEvaluator::new().eval(&f.tape_f, p, &[]) > 0.0);
        assert_eq!(
            PointEvaluator::single_precision().eval(&f.tape_f, p, &[]),
            0.0
        );
        assert_eq!(narrow(1e-40), 0.0);
        assert_eq!(narrow(0.1), 0.1f32);
    }
}
