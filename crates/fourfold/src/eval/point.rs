//! Point evaluation in f64 of a [`Tape`]: F, or F and ∇F. Outside a function's domain the
//! value is NaN (each operation's `point` in `crate::ops`); callers treat NaN as "undefined".
//! The CPU twin evaluates as the GPU does instead: each operation's result rounded to f32,
//! overflowing to ±∞ and with subnormals flushed to 0 (as lavapipe does), so that where a
//! formula leaves f32's range (`tan(1e300*k)`, `(w^3.84)^x` near w = 0) its pictures are
//! the GPU's, not f64's.

use crate::ops::powi;

use super::tape::{Op, PrefixKey, Tape, prepare_slots};

/// Reusable evaluator; holds its slot storage so repeated calls do not allocate.
#[derive(Debug, Clone, Default)]
pub struct PointEvaluator {
    slots: Vec<f64>,
    /// The slots of an evaluation in f32 (`single`).
    narrow_slots: Vec<f32>,
    prefix: PrefixKey,
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
        let (slots, start) = prepare_slots(&mut self.slots, &mut self.prefix, tape, params, 0.0);
        for (i, op) in tape.ops().iter().enumerate().skip(start) {
            slots[i] = match *op {
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
            };
        }
        for (o, &slot) in out.iter_mut().zip(tape.outputs()) {
            *o = slots[slot as usize];
        }
    }

    /// As [`Self::run_double`] with each result rounded to f32 (see the module's note). + − ×
    /// run in f32 itself: on f32 operands, f32's rounding of the exact result is f64's
    /// rounded again to f32 (53 ≥ 2 × 24 + 2 bits, so the double rounding is harmless), at
    /// a third of the instructions; the other operations go through f64 as before.
    fn run_single(&mut self, tape: &Tape, p: [f64; 4], params: &[f64], out: &mut [f64]) {
        let (slots, start) =
            prepare_slots(&mut self.narrow_slots, &mut self.prefix, tape, params, 0.0);
        for (i, op) in tape.ops().iter().enumerate().skip(start) {
            let wide = |a: u32| f64::from(slots[a as usize]);
            slots[i] = match *op {
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
            };
        }
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

/// `x` rounded to the nearest f32 (±∞ beyond its range), subnormals flushed to 0.
#[inline(always)]
fn narrow(x: f64) -> f32 {
    flush(x as f32)
}

/// `y`, or 0 of its sign where it is subnormal (as lavapipe flushes them).
#[inline(always)]
fn flush(y: f32) -> f32 {
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

    proptest! {
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
