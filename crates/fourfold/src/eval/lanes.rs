//! Point evaluation of a [`Tape`] in f32, as the GPU computes (see `point`), at up to
//! [`LANES`] points at once: each instruction dispatched once for all of them, its
//! arithmetic a loop over all lanes (which the compiler vectorizes), a library function's
//! a loop over the points' whose coordinates it reads moved since the lane's last point
//! (a slice's march moves one: a lattice's cosines of the others are kept). The results
//! are bit for bit those of
//! [`PointEvaluator::single_precision`](super::PointEvaluator::single_precision): each lane
//! takes the same operations, rounded and flushed the same way.

use multiversion::multiversion;

use crate::ops::powi;

use super::LANES;
use super::point::{flush, narrow};
use super::tape::{Op, PrefixKey, Tape, moved, sized};

/// Reusable evaluator at up to [`LANES`] points.
#[derive(Debug, Clone, Default)]
pub struct PointLanes {
    slots: Vec<[f32; LANES]>,
    prefix: PrefixKey,
    len: usize,
    /// Each lane's last point's coordinates (bits), where its slots hold that point's
    /// values (None: they do not); kept only where the tape calls a library function past
    /// its uniform prefix (`calls`).
    last: [Option<[u32; 4]>; LANES],
    calls: bool,
}

impl PointLanes {
    pub fn new() -> Self {
        Self::default()
    }

    /// Evaluates every output of `tape` at each of `points` (1 to [`LANES`] of them, in
    /// f32 as the GPU's); read the results with [`Self::output`].
    pub fn eval(&mut self, tape: &Tape, points: &[[f32; 4]], params: &[f64]) {
        assert!(
            (1..=LANES).contains(&points.len()),
            "a batch holds 1 to {LANES} points, not {}",
            points.len()
        );
        let n = points.len();
        self.len = n;
        // (A tape or parameters new since the last call: the uniform prefix is computed
        // again, and no lane's slots hold the tape's values.)
        let stale = self.prefix.stale(tape, params);
        if stale {
            self.last = [None; LANES];
            self.calls = tape.calls_library();
        }
        let start = if stale { 0 } else { tape.uniform_len() };
        let slots = sized(&mut self.slots, tape, [0.0; LANES]);
        // The coordinates lane by lane, flushed as the point evaluator's (lanes past the
        // points' repeat the last), and which moved since each lane's last point.
        let coordinate: [[f32; LANES]; 4] =
            std::array::from_fn(|k| std::array::from_fn(|l| flush(points[l.min(n - 1)][k])));
        let calls = self.calls;
        let moved: [u8; LANES] = std::array::from_fn(|l| {
            if !calls {
                return 0xf;
            }
            let bits: [u32; 4] = std::array::from_fn(|k| coordinate[k][l].to_bits());
            let moved = moved(self.last[l], &bits);
            // (Lanes past the points' take no library function: their slots hold nothing.)
            self.last[l] = (l < n).then_some(bits);
            moved
        });
        let ops = (&tape.ops()[start..], &tape.reads()[start..]);
        run(ops, &mut slots[..], start, (&coordinate, &moved, n), params);
    }

    /// Output `k` of `tape` at point `lane` of the last batch.
    pub fn output(&self, tape: &Tape, k: usize, lane: usize) -> f32 {
        debug_assert!(lane < self.len);
        self.slots[tape.outputs()[k] as usize][lane]
    }
}

/// The tape's instructions `ops` (with the coordinates each reads), from instruction
/// `first` on, into `slots`: each instruction's lanes in step, a library call's in the
/// first `n` lanes whose read coordinates `moved`. (Also compiled for AVX2: see `eval`.)
#[multiversion(targets("x86_64+avx2"))]
fn run(
    (ops, reads): (&[Op], &[u8]),
    slots: &mut [[f32; LANES]],
    first: usize,
    (coordinate, moved, n): (&[[f32; LANES]; 4], &[u8; LANES], usize),
    params: &[f64],
) {
    for (k, (&op, &read)) in ops.iter().zip(reads).enumerate() {
        let (done, rest) = slots.split_at_mut(first + k);
        let out = &mut rest[0];
        let at = |a: u32| &done[a as usize];
        match op {
            Op::Const(c) => *out = [narrow(c); LANES],
            Op::Var(a) => *out = coordinate[a as usize & 3],
            Op::Param(i) => *out = [narrow(params.get(i as usize).copied().unwrap_or(1.0)); LANES],
            Op::Add(a, b) => lanes2(out, at(a), at(b), |x, y| flush(x + y)),
            Op::Sub(a, b) => lanes2(out, at(a), at(b), |x, y| flush(x - y)),
            Op::Mul(a, b) => lanes2(out, at(a), at(b), |x, y| flush(x * y)),
            Op::Neg(a) => lanes1(out, at(a), |x| -x),
            Op::Square(a) => lanes1(out, at(a), |x| flush(x * x)),
            // (A positive power: `powi`'s products, lane by lane in step, which
            // vectorize.)
            Op::Powi(a, k) if k > 0 => *out = powers(at(a), k.unsigned_abs()),
            // (Library calls, lane by lane: only the points' lanes whose operands'
            // coordinates moved.)
            Op::Powi(a, k) => {
                let a = at(a);
                for l in (0..n).filter(|&l| moved[l] & read != 0) {
                    out[l] = narrow(powi(f64::from(a[l]), k));
                }
            }
            Op::Unary(op, a) => {
                let (point, a) = (op.spec().point, at(a));
                for l in (0..n).filter(|&l| moved[l] & read != 0) {
                    out[l] = narrow(point(f64::from(a[l])));
                }
            }
            Op::Binary(op, a, b) => {
                let (point, a, b) = (op.spec().point, at(a), at(b));
                for l in (0..n).filter(|&l| moved[l] & read != 0) {
                    out[l] = narrow(point(f64::from(a[l]), f64::from(b[l])));
                }
            }
        }
    }
}

/// x^k in every lane for k ≥ 1, narrowed: the products `ops::powi` takes, in its order,
/// in f64. (Loops, not `array::map`: a call the AVX2 build could not inline.)
#[inline(always)]
fn powers(a: &[f32; LANES], k: u32) -> [f32; LANES] {
    let mut base = [0.0f64; LANES];
    for l in 0..LANES {
        base[l] = f64::from(a[l]);
    }
    let mut product = [1.0f64; LANES];
    let mut rest = k;
    loop {
        if rest & 1 != 0 {
            for l in 0..LANES {
                product[l] *= base[l];
            }
        }
        rest >>= 1;
        if rest == 0 {
            break;
        }
        for l in 0..LANES {
            base[l] *= base[l];
        }
    }
    let mut out = [0.0f32; LANES];
    for l in 0..LANES {
        out[l] = narrow(product[l]);
    }
    out
}

#[inline(always)]
fn lanes1(out: &mut [f32; LANES], a: &[f32; LANES], f: impl Fn(f32) -> f32) {
    for l in 0..LANES {
        out[l] = f(a[l]);
    }
}

#[inline(always)]
fn lanes2(out: &mut [f32; LANES], a: &[f32; LANES], b: &[f32; LANES], f: impl Fn(f32, f32) -> f32) {
    for l in 0..LANES {
        out[l] = f(a[l], b[l]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::CompiledFormula;
    use crate::eval::PointEvaluator;
    use proptest::prelude::*;

    proptest! {
        /// Batch after batch, each lane moving along one axis or taking a new point, or
        /// the batch shrinking, its outputs stay the single-precision evaluator's: values
        /// kept for a lane whose operands did not move are its point's.
        #[test]
        fn lanes_that_keep_coordinates_keep_the_evaluator_s_values(
            start in prop::collection::vec(prop::array::uniform4(-2.0f32..2.0), LANES),
            moves in prop::collection::vec(
                (0usize..4, prop::collection::vec(prop_oneof![Just(0.0f32), -0.5f32..0.5], LANES), 1..=LANES),
                1..6,
            ),
        ) {
            let sources = [
                "cos(3x) + cos(3y) + cos(3z) + cos(3w)",
                "sqrt(x^2 + y^2) * exp(z) - w/(1 + y^2) + x^-3",
            ];
            for src in sources {
                let f = CompiledFormula::compile(src).unwrap();
                let tape = &f.tape_all;
                let mut lanes = PointLanes::new();
                let mut points = start.clone();
                lanes.eval(tape, &points, &[]);
                for (axis, steps, n) in &moves {
                    for (p, step) in points.iter_mut().zip(steps) {
                        p[*axis] += step;
                    }
                    lanes.eval(tape, &points[..*n], &[]);
                    for (lane, p) in points[..*n].iter().enumerate() {
                        let mut one = [0.0; 5];
                        let p64 = p.map(f64::from);
                        PointEvaluator::single_precision().eval_into(tape, p64, &[], &mut one);
                        for (j, &v) in one.iter().enumerate() {
                            let (w, v) = (lanes.output(tape, j, lane), v as f32);
                            prop_assert!(w.to_bits() == v.to_bits() || (w.is_nan() && v.is_nan()),
                                "{} at {:?}, output {}: {} against {}", src, p, j, w, v);
                        }
                    }
                }
            }
        }

        /// Each lane's outputs are the single-precision evaluator's at its point, bit for
        /// bit (NaN as NaN), for batches of any size, formulas of every kind of operation.
        #[test]
        fn each_lane_is_the_single_precision_evaluator_s(
            points in prop::collection::vec(prop::array::uniform4(
                prop_oneof![Just(0.0f64), Just(-0.0), Just(1e-39), -3.0f64..3.0, -1e30f64..1e30]
            ), 1..=LANES),
            k in 0.0f64..3.0,
        ) {
            let sources = [
                "1/x + sqrt(y) * sin(z*k) - atan2(w, x) + y^3",
                "(x^2 + y^2 + z^2 + R^2 - r^2)^2 - 4R^2(x^2 + y^2) - w",
                "x^6 + y^6 + z^6 + w^6 + 4x^2 y^2 z^2 - 1e-30",
                "ln(z - x) + abs(w) * cos(3y) - max(x, k) + exp(y)^(-2)",
            ];
            let params = [k, 2.0, 1.0];
            for src in sources {
                let f = CompiledFormula::compile(src).unwrap();
                let tape = &f.tape_all;
                let mut lanes = PointLanes::new();
                let in_f32: Vec<[f32; 4]> = points.iter().map(|p| p.map(|v| v as f32)).collect();
                lanes.eval(tape, &in_f32, &params);
                for (lane, &p) in points.iter().enumerate() {
                    let mut one = [0.0; 5];
                    PointEvaluator::single_precision().eval_into(tape, p, &params, &mut one);
                    for (j, &v) in one.iter().enumerate() {
                        let w = lanes.output(tape, j, lane);
                        let v = v as f32;
                        prop_assert!(w.to_bits() == v.to_bits() || (w.is_nan() && v.is_nan()),
                            "{} at {:?}, output {}: {} against {}", src, p, j, w, v);
                    }
                }
            }
        }
    }
}
