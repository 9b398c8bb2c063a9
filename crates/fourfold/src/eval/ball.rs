//! F's sign proved at up to [`LANES`] near-points at once by midpoint–radius ("ball")
//! arithmetic in f64: each value a midpoint and a bound on its distance from the exact
//! value, the rounding of every operation included. Only for tapes of sums, products and
//! positive integer powers ([`BallLanes::takes`]): there a point's ball costs a few
//! multiplications an operation, where an interval's directed roundings, and its powers'
//! loops, cost many. Where a ball holds 0 it proves nothing, and the caller asks intervals.

use multiversion::multiversion;

use super::LANES;
use super::interval_eval::Box4;
use super::tape::{Op, Tape};

/// How much a radius is grown past the rounding of its own sum of products (a handful of
/// operations, each off by at most half an ulp), and the absolute error it carries for a
/// result that underflows.
const GROW: f64 = 1.0 + 16.0 * f64::EPSILON;
const TINY: f64 = f64::MIN_POSITIVE;

/// Reusable ball evaluator at up to [`LANES`] points.
#[derive(Debug, Clone, Default)]
pub struct BallLanes {
    /// Each instruction's balls: midpoints and radii, lane by lane.
    slots: Vec<Balls>,
}

/// Midpoints and radii, lane by lane.
type Balls = [[f64; LANES]; 2];

impl BallLanes {
    pub fn new() -> Self {
        Self::default()
    }

    /// Whether every instruction of `tape` is one balls take: constants, coordinates,
    /// parameters, sums, differences, products, negation and powers k > 0 (no library
    /// call, see [`Op::calls_library`]).
    pub fn takes(tape: &Tape) -> bool {
        !tape.ops().iter().any(Op::calls_library)
    }

    /// The proved sign (1, −1; 0: not proved) of `tape`'s first output over each of
    /// `boxes` (1 to [`LANES`], each a point's enclosure, or any box) into `out`. A sign
    /// is proved where the ball holds only values of it: F has that sign over the whole
    /// box, in exact arithmetic with the tape's f64 constants and `params`.
    pub fn signs(&mut self, tape: &Tape, boxes: &[Box4], params: &[f64], out: &mut [i8]) {
        self.eval(tape, boxes, params);
        for (l, sign) in out[..boxes.len()].iter_mut().enumerate() {
            let (m, r) = self.ball(tape, 0, l);
            *sign = if m.is_finite() && r.is_finite() && m.abs() > r {
                if m > 0.0 { 1 } else { -1 }
            } else {
                0
            };
        }
    }

    /// Output `k` of `tape` over box `lane` of the last [`Self::eval`]: a midpoint and a
    /// radius that hold each of its values in exact arithmetic (none where not finite).
    pub fn ball(&self, tape: &Tape, k: usize, lane: usize) -> (f64, f64) {
        let [mid, rad] = &self.slots[tape.outputs()[k] as usize];
        (mid[lane], rad[lane])
    }

    /// Evaluates every output of `tape` over each of `boxes` (1 to [`LANES`]); read them
    /// with [`Self::ball`].
    pub fn eval(&mut self, tape: &Tape, boxes: &[Box4], params: &[f64]) {
        assert!(
            Self::takes(tape),
            "balls take sums, products and powers only"
        );
        assert!((1..=LANES).contains(&boxes.len()));
        let ops = tape.ops();
        self.slots.resize(ops.len(), [[0.0; LANES]; 2]);
        run(ops, &mut self.slots, boxes, params);
    }
}

/// The tape's instructions `ops` over `boxes` into `slots`, every lane in step. (Also compiled
/// for AVX2: see `eval`.)
#[multiversion(targets("x86_64+avx2"))]
fn run(ops: &[Op], slots: &mut [Balls], boxes: &[Box4], params: &[f64]) {
    let n = boxes.len();
    for (i, &op) in ops.iter().enumerate() {
        let (done, rest) = slots.split_at_mut(i);
        let out = &mut rest[0];
        let at = |k: u32| &done[k as usize];
        match op {
            Op::Const(c) => *out = [[c; LANES], [0.0; LANES]],
            Op::Var(a) => {
                // The coordinate's ball around its interval (lanes past the boxes'
                // repeat the last).
                for l in 0..LANES {
                    let x = boxes[l.min(n - 1)][a as usize & 3];
                    let m = 0.5 * x.lo() + 0.5 * x.hi();
                    let r = (x.hi() - m).max(m - x.lo());
                    (out[0][l], out[1][l]) = (m, r * GROW + TINY);
                }
            }
            Op::Param(p) => {
                let v = params.get(p as usize).copied().unwrap_or(1.0);
                *out = [[v; LANES], [0.0; LANES]];
            }
            Op::Add(a, b) => add(out, at(a), at(b), 1.0),
            Op::Sub(a, b) => add(out, at(a), at(b), -1.0),
            Op::Mul(a, b) => mul(out, at(a), at(b)),
            Op::Neg(a) => {
                // (A loop, not `array::map`: a call the AVX2 build could not inline.)
                let [m, r] = at(a);
                let mut negated = [0.0; LANES];
                for l in 0..LANES {
                    negated[l] = -m[l];
                }
                *out = [negated, *r];
            }
            Op::Square(a) => mul(out, at(a), at(a)),
            Op::Powi(a, k) if k > 0 => *out = power(at(a), k.unsigned_abs()),
            Op::Powi(..) | Op::Unary(..) | Op::Binary(..) => {
                unreachable!("checked by `takes`")
            }
        }
    }
}

/// a + s·b (s = ±1): |x ± y − (a ± b)| ≤ ra + rb, and the sum's rounding.
#[inline(always)]
fn add(out: &mut Balls, [am, ar]: &Balls, [bm, br]: &Balls, s: f64) {
    for l in 0..LANES {
        let m = am[l] + s * bm[l];
        out[0][l] = m;
        out[1][l] = (ar[l] + br[l] + f64::EPSILON * m.abs()) * GROW + TINY;
    }
}

/// a·b: |xy − ab| ≤ |a|·rb + |b|·ra + ra·rb, and the product's rounding.
#[inline(always)]
fn mul(out: &mut Balls, [am, ar]: &Balls, [bm, br]: &Balls) {
    for l in 0..LANES {
        let m = am[l] * bm[l];
        out[0][l] = m;
        let spread = am[l].abs() * br[l] + bm[l].abs() * ar[l] + ar[l] * br[l];
        out[1][l] = (spread + f64::EPSILON * m.abs()) * GROW + TINY;
    }
}

/// a^k for k ≥ 0, by squarings and products.
#[inline(always)]
fn power(a: &Balls, k: u32) -> Balls {
    let mut acc: Balls = [[1.0; LANES], [0.0; LANES]];
    let (mut base, mut rest) = (*a, k);
    while rest > 0 {
        if rest & 1 == 1 {
            let product = acc;
            mul(&mut acc, &product, &base);
        }
        rest >>= 1;
        if rest > 0 {
            let b = base;
            mul(&mut base, &b, &b);
        }
    }
    acc
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::CompiledFormula;
    use crate::eval::{Interval, IntervalEvaluator};
    use proptest::prelude::*;

    /// Only sums, products and non-negative powers are taken.
    #[test]
    fn balls_take_arithmetic_tapes_only() {
        for (src, takes) in [
            ("x^6 + y^6 + z^6 + w^6 + 4x^2 y^2 z^2 - 1", true),
            (
                "(x^2 + y^2 + z^2 + R^2 - r^2)^2 - 4R^2(x^2 + y^2) - w",
                true,
            ),
            ("x^-2 + y", false),
            ("x / y", false),
            ("cos(x) + y", false),
            ("abs(x) - w", false),
        ] {
            let f = CompiledFormula::compile(src).unwrap();
            assert_eq!(BallLanes::takes(&f.tape_f), takes, "{src}");
        }
    }

    proptest! {
        /// Two forms of one polynomial, which f64 rounds apart (most at large coordinates,
        /// where their terms cancel), have balls that overlap: each holds the exact value.
        #[test]
        fn balls_of_one_value_written_two_ways_overlap(
            points in prop::collection::vec(prop::array::uniform4(
                prop_oneof![-1e6f64..1e6, -1.0f64..1.0, -1e-100f64..1e-100]
            ), 1..=LANES),
        ) {
            let pairs = [
                ("(x + y)^2 - y^2 + z", "x^2 + 2 x y + z"),
                ("(x*y + z)^3 - z^3 + w", "(x*y)^3 + 3 (x*y)^2 z + 3 x*y z^2 + w"),
                ("x^7 - w^7", "(x - w)(x^6 + x^5 w + x^4 w^2 + x^3 w^3 + x^2 w^4 + x w^5 + w^6)"),
                ("(x - z)(x + z) + y", "x^2 - z^2 + y"),
            ];
            let mut a = BallLanes::new();
            let mut b = BallLanes::new();
            // (Exact points: only the rounding of the operations sets the balls apart.)
            let boxes: Vec<Box4> = points.iter().map(|p| p.map(Interval::point)).collect();
            for (one, other) in pairs {
                let (f, g) = (CompiledFormula::compile(one).unwrap(), CompiledFormula::compile(other).unwrap());
                a.eval(&f.tape_f, &boxes, &[]);
                b.eval(&g.tape_f, &boxes, &[]);
                for lane in 0..boxes.len() {
                    let ((m1, r1), (m2, r2)) = (a.ball(&f.tape_f, 0, lane), b.ball(&g.tape_f, 0, lane));
                    prop_assume!([m1, r1, m2, r2].iter().all(|v| v.is_finite()));
                    prop_assert!((m1 - m2).abs() <= r1 + r2, "{} against {} at {:?}: {:?} {:?}", one, other, points[lane], (m1, r1), (m2, r2));
                }
            }
        }

        /// A proved sign is F's over the whole box, as intervals enclose it: never the
        /// sign they prove the other way; and where F is far from 0, the ball proves it.
        #[test]
        fn a_proved_sign_is_the_intervals(
            points in prop::collection::vec(prop::array::uniform4(-2.0f64..2.0), 1..=LANES),
            width in prop_oneof![Just(0.0f64), 1e-12f64..1e-3],
            k in 0.5f64..3.0,
        ) {
            let sources = [
                "x^6 + y^6 + z^6 + w^6 + 4x^2 y^2 z^2 - 1",
                "(x^2 + y^2 + z^2 + R^2 - r^2)^2 - 4R^2(x^2 + y^2) - w",
                "x y z - w^3 + R * 0.1",
            ];
            let params = [k, 1.0];
            let mut balls = BallLanes::new();
            let mut intervals = IntervalEvaluator::new();
            let boxes: Vec<Box4> = points
                .iter()
                .map(|p| p.map(|v| Interval::new(v - width, v + width)))
                .collect();
            for src in sources {
                let f = CompiledFormula::compile(src).unwrap();
                let mut signs = [0i8; LANES];
                balls.signs(&f.tape_f, &boxes, &params, &mut signs);
                for (b, &sign) in boxes.iter().zip(&signs) {
                    let v = intervals.eval(&f.tape_f, b, &params);
                    if v.lo() > 0.0 {
                        prop_assert!(sign >= 0, "{}", src);
                    }
                    if v.hi() < 0.0 {
                        prop_assert!(sign <= 0, "{}", src);
                    }
                    if sign > 0 {
                        prop_assert!(v.hi() > 0.0, "{}: ball says +, intervals {:?}", src, v);
                    }
                    if sign < 0 {
                        prop_assert!(v.lo() < 0.0, "{}: ball says −, intervals {:?}", src, v);
                    }
                    let far = v.lo() > 1e-6 * (1.0 + v.hi().abs()) || v.hi() < -1e-6 * (1.0 + v.lo().abs());
                    if width == 0.0 && far {
                        prop_assert!(sign != 0, "{}: F far from 0, {:?}, not proved", src, v);
                    }
                }
            }
        }
    }
}
