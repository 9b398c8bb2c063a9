//! How far F's value in f32 at a point, as the single-precision evaluators compute it
//! ([`PointEvaluator::single_precision`](super::PointEvaluator::single_precision) and
//! [`PointLanes`](super::PointLanes), the GPU's arithmetic), can lie from F's exact value
//! there, for every point of a box: a bound worked out once, by a forward pass over the
//! tape that encloses each instruction's exact values (intervals) and bounds its computed
//! value's distance from them (its operands' distances carried through, its rounding to
//! f32, a subnormal flushed to 0). A sample farther from 0 than the bound has F's sign,
//! proved without another evaluation: the static filter of exact geometric predicates.

use super::point::narrow;
use super::{Box4, Interval, Op, Tape};

/// f32's unit roundoff (rounding to nearest moves a normal value by at most this, relative).
const UNIT: f64 = 1.0 / (1u64 << 24) as f64;

/// What rounding a result in f32's subnormal range and flushing it to 0 move it by, at
/// most: f32's least normal value.
const FLUSHED: f64 = f32::MIN_POSITIVE as f64;

/// The bound's own arithmetic is in f64, rounded to nearest: a few units of 2^-53 for
/// each instruction, which this relative margin covers for any tape a formula makes.
const MARGIN: f64 = 1e-6;

/// A bound on |F̃(p) − F(p)| for output `output` of `tape`, for every point p of `domain`
/// whose coordinates are f32 values: F̃ is the single-precision evaluators' value, F the
/// exact one (the tape's f64 constants and `params` taken as exact). None where the tape
/// calls a library function (whose f32 result no bound here covers; a power k ≤ 0 among
/// them), or where a value may leave f32's range.
pub fn single_precision_error(
    tape: &Tape,
    output: usize,
    domain: &Box4,
    params: &[f64],
) -> Option<f64> {
    let ops = tape.ops();
    // Each slot's exact values over the domain, and how far its f32 value may lie from them.
    let mut slots: Vec<(Interval, f64)> = Vec::with_capacity(ops.len());
    for &op in ops {
        let at = |k: u32| slots[k as usize];
        let (value, error) = match op {
            Op::Const(c) => (Interval::point(c), narrowed(c)?),
            Op::Param(i) => {
                let v = params.get(i as usize).copied().unwrap_or(1.0);
                (Interval::point(v), narrowed(v)?)
            }
            // (The point's own coordinates, flushed where subnormal.)
            Op::Var(a) => (domain[a as usize & 3], FLUSHED),
            Op::Neg(a) => {
                let (v, e) = at(a);
                (v.neg(), e)
            }
            Op::Add(a, b) | Op::Sub(a, b) => {
                let ((va, ea), (vb, eb)) = (at(a), at(b));
                let v = match op {
                    Op::Add(..) => va.add(vb),
                    _ => va.sub(vb),
                };
                (v, rounded(v, ea + eb))
            }
            Op::Mul(a, b) => {
                // ãb̃ − ab = (ã − a)·b̃ + a·(b̃ − b).
                let ((va, ea), (vb, eb)) = (at(a), at(b));
                let v = va.mul(vb);
                (
                    v,
                    rounded(v, ea * (vb.magnitude() + eb) + va.magnitude() * eb),
                )
            }
            Op::Square(a) => {
                // ã² − a² = (ã − a)·(ã + a).
                let (va, ea) = at(a);
                let v = va.square();
                (v, rounded(v, ea * (2.0 * va.magnitude() + ea)))
            }
            Op::Powi(a, k) if k > 0 => {
                // The mean value theorem: |ã^k − a^k| ≤ k·max(|ã|, |a|)^(k−1)·|ã − a|; then
                // the power's products in f64 (`ops::powi`), k − 1 roundings of 2^-53 at
                // most, counted twice over; then its narrowing to f32.
                let (va, ea) = at(a);
                let v = va.powi(k);
                let carried = f64::from(k) * (va.magnitude() + ea).powi(k - 1) * ea;
                let products = (v.magnitude() + carried) * f64::from(k) * f64::EPSILON;
                (v, rounded(v, carried + products))
            }
            Op::Powi(..) | Op::Unary(..) | Op::Binary(..) => return None,
        };
        // (Also false for NaN, and for an empty enclosure, whose size is not finite.)
        let in_range = value.magnitude() + error < f64::from(f32::MAX) / 2.0;
        if !in_range {
            return None;
        }
        slots.push((value, error));
    }
    let (_, error) = slots[*tape.outputs().get(output)? as usize];
    Some(error * (1.0 + MARGIN))
}

/// The distance from the exact values in `v` of a result computed `carried` away from
/// them, once rounded to f32 (relative, on at most |v| + carried) and flushed.
fn rounded(v: Interval, carried: f64) -> f64 {
    carried + UNIT * (v.magnitude() + carried) + FLUSHED
}

/// How far `c` moves when narrowed to f32 (None: out of f32's range).
fn narrowed(c: f64) -> Option<f64> {
    let n = narrow(c);
    n.is_finite().then(|| (f64::from(n) - c).abs())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::PointEvaluator;
    use crate::formula::CompiledFormula;
    use proptest::prelude::*;

    /// F's value at `p` in f64, whose own error is far below the f32 bound's.
    fn exact(f: &CompiledFormula, p: [f64; 4], params: &[f64]) -> f64 {
        PointEvaluator::new().eval(&f.tape_f, p, params)
    }

    fn single(f: &CompiledFormula, p: [f64; 4], params: &[f64]) -> f64 {
        PointEvaluator::single_precision().eval(&f.tape_f, p, params)
    }

    fn cube(r: f64) -> Box4 {
        [Interval::new(-r, r); 4]
    }

    const FORMULAS: [&str; 6] = [
        "x^6 + y^6 + z^6 + w^6 + 4x^2 y^2 z^2 - 1",
        "x^2 + y^2 + z^2 + w^2 - 1",
        "(x^2 + y^2 - 0.3)^2 + 1e-3 z^2 - w^3 + 0.1",
        "x*y*z*w - 0.01 x + 3.3 y^5 - z",
        "(x - y)^7 + 1e5 (z - w) - 1e5 (z - w) + 0.7",
        "a x^2 - b y^2 + z w - 1",
    ];

    proptest! {
        /// The f32 value lies within the bound of the exact one, at points anywhere in the
        /// box, tiny and near 0 among them.
        #[test]
        fn the_f32_value_lies_within_the_bound(
            which in 0..FORMULAS.len(),
            r in 0.01f64..3.0,
            at in prop::array::uniform4(-1.0f64..1.0),
            scale in prop::sample::select(vec![1.0, 1e-3, 1e-20, 1e-40]),
            params in prop::array::uniform2(-5.0f64..5.0),
        ) {
            let f = CompiledFormula::compile(FORMULAS[which]).unwrap();
            let bound = single_precision_error(&f.tape_f, 0, &cube(r), &params).unwrap();
            // The point's coordinates as f32 values, inside the box.
            let p = at.map(|v| f64::from((v * r * scale) as f32));
            let (lo, hi) = (single(&f, p, &params), exact(&f, p, &params));
            prop_assert!((lo - hi).abs() <= bound, "{p:?}: {lo} against {hi}, bound {bound}");
        }
    }

    /// Random sums, differences, products and powers of the coordinates, numbers (small
    /// and large) and the parameters a and b.
    fn polynomial() -> impl Strategy<Value = String> {
        let leaf = prop_oneof![
            prop::sample::select(vec!["x", "y", "z", "w", "a", "b", "1e-3", "1e4"])
                .prop_map(String::from),
            (-9.99f64..9.99).prop_map(|c| format!("({c:.3})")),
        ];
        leaf.prop_recursive(5, 48, 2, |inner| {
            prop_oneof![
                (inner.clone(), inner.clone()).prop_map(|(a, b)| format!("({a} + {b})")),
                (inner.clone(), inner.clone()).prop_map(|(a, b)| format!("({a} - {b})")),
                (inner.clone(), inner.clone()).prop_map(|(a, b)| format!("({a} * {b})")),
                (inner.clone(), 2u32..8).prop_map(|(a, k)| format!("({a})^{k}")),
                inner.prop_map(|a| format!("-({a})")),
            ]
        })
    }

    proptest! {
        /// The same on formulas nobody wrote: the f32 value within the bound, wherever the
        /// bound exists (not past f32's range).
        #[test]
        fn random_polynomials_keep_within_their_bound(
            text in polynomial(),
            r in 0.1f64..2.0,
            at in prop::array::uniform4(-1.0f64..1.0),
            params in prop::array::uniform2(-3.0f64..3.0),
        ) {
            let Ok(f) = CompiledFormula::compile(&text) else {
                return Ok(());
            };
            let Some(bound) = single_precision_error(&f.tape_f, 0, &cube(r), &params) else {
                return Ok(());
            };
            let p = at.map(|v| f64::from((v * r) as f32));
            let (lo, hi) = (single(&f, p, &params), exact(&f, p, &params));
            prop_assert!((lo - hi).abs() <= bound, "{text} at {p:?}: {lo} against {hi}, bound {bound}");
        }
    }

    /// The bound is close to the rounding it covers: a few units of f32's rounding of F's
    /// largest terms, not orders of magnitude more.
    #[test]
    fn the_bound_is_a_few_roundings_of_f_s_terms() {
        let f = CompiledFormula::compile("x^2 + y^2 + z^2 + w^2 - 1").unwrap();
        let bound = single_precision_error(&f.tape_f, 0, &cube(1.5), &[]).unwrap();
        // Terms up to 2.25, sums up to 9: about 9 ulps of 9 at most.
        assert!(bound > 4.0 * UNIT && bound < 200.0 * UNIT, "{bound}");
    }

    /// A library function, a negative power or a value past f32's range leave no bound.
    #[test]
    fn library_calls_and_huge_values_have_no_bound() {
        for text in [
            "sin(x) + y",
            "x^-2 + y",
            "sqrt(x^2 + 1) - 2",
            "1e36 x^2 - 1",
        ] {
            let f = CompiledFormula::compile(text).unwrap();
            assert_eq!(
                single_precision_error(&f.tape_f, 0, &cube(100.0), &[]),
                None,
                "{text}"
            );
        }
    }
}
