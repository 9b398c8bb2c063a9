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
            self.run::<true>(tape, p, params, out);
        } else {
            self.run::<false>(tape, p, params, out);
        }
    }

    /// [`Self::eval_into`] with the rounding chosen once, outside the loop (`SINGLE`: to f32).
    #[inline(always)]
    fn run<const SINGLE: bool>(
        &mut self,
        tape: &Tape,
        p: [f64; 4],
        params: &[f64],
        out: &mut [f64],
    ) {
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
                Op::Square(a) => slots[a as usize] * slots[a as usize],
                Op::Powi(a, n) => powi(slots[a as usize], n),
                Op::Unary(op, a) => (op.spec().point)(slots[a as usize]),
                Op::Binary(op, a, b) => (op.spec().point)(slots[a as usize], slots[b as usize]),
            };
            slots[i] = if SINGLE { to_f32(v) } else { v };
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

/// `x` rounded to the nearest f32 (±∞ beyond its range), subnormals flushed to 0.
#[inline(always)]
fn to_f32(x: f64) -> f64 {
    let y = x as f32;
    if y.is_subnormal() {
        0.0f32.copysign(y).into()
    } else {
        y.into()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::CompiledFormula;

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
        assert_eq!(to_f32(1e-40), 0.0);
        assert_eq!(to_f32(0.1), f64::from(0.1f32));
    }
}
