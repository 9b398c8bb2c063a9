//! Interval arithmetic: sin and cos against libm, tightness on known cases, domain rules and
//! rounding. (Every evaluator's soundness over random formulas is tests/conformance.rs's.)

mod common;

use fourfold::CompiledFormula;
use fourfold::eval::{Box4, Interval, IntervalEvaluator};
use proptest::prelude::*;

/// An interval around a multiple of π/2 (where sin and cos turn and the quadrant flips),
/// anywhere up to 2^21 (past the reduced range, into the libm path), or wide.
fn trig_interval() -> impl Strategy<Value = Interval> {
    let near_turn = (
        -700_000i64..700_000,
        -4i64..=4,
        prop::sample::select(vec![0.0, 1e-15, 1e-9, 0.01, 1.0]),
    )
        .prop_map(|(n, ulps, w)| {
            let p = n as f64 * std::f64::consts::FRAC_PI_2;
            let lo = f64::from_bits((p.to_bits() as i64 + ulps) as u64);
            Interval::new(lo, lo + w * (1.0 + lo.abs()))
        });
    let anywhere = (
        -2.2e6f64..2.2e6,
        prop::sample::select(vec![0.0, 1e-6, 0.3, 2.0, 7.0]),
    )
        .prop_map(|(lo, w)| Interval::new(lo, lo + w));
    prop_oneof![
        near_turn,
        anywhere,
        (-8.0f64..8.0).prop_map(Interval::point)
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 600, ..ProptestConfig::default() })]

    /// sin and cos hold the platform's values (within an ulp of the true ones, far inside the
    /// widening) at the ends, the middle and random points of the interval.
    #[test]
    fn sin_and_cos_hold_their_values(
        x in trig_interval(),
        samples in prop::collection::vec(0.0f64..=1.0, 6),
    ) {
        let (s, c) = (x.sin(), x.cos());
        for t in samples.into_iter().chain([0.0, 0.5, 1.0]) {
            let p = (x.lo() + t * x.width()).min(x.hi());
            prop_assert!(s.contains(p.sin()), "sin {p} = {} not in {s} (argument {x})", p.sin());
            prop_assert!(c.contains(p.cos()), "cos {p} = {} not in {c} (argument {x})", p.cos());
        }
        // Tight: a point's enclosure is a few units of 1e-15 wide.
        if x.width() == 0.0 && x.lo().abs() < 1e6 {
            prop_assert!(s.width() < 1e-14 && c.width() < 1e-14, "{s} {c}");
        }
    }
}

fn range_of(text: &str, bx: [(f64, f64); 4]) -> Interval {
    let f = CompiledFormula::compile(text).unwrap();
    let bx: Box4 = bx.map(|(lo, hi)| Interval::new(lo, hi));
    IntervalEvaluator::new().eval(&f.tape_f, &bx, &[])
}

fn close(i: Interval, lo: f64, hi: f64) {
    let slack = |v: f64| 1e-12 * (1.0 + v.abs());
    assert!(
        i.contains(lo) && i.contains(hi),
        "{i} does not hold [{lo}, {hi}]"
    );
    assert!(
        i.lo() >= lo - slack(lo) && i.hi() <= hi + slack(hi),
        "{i} is looser than [{lo}, {hi}]"
    );
}

#[test]
fn tight_on_known_cases() {
    let unit = (0.0, 0.0);
    close(range_of("x^2", [(-1.0, 2.0), unit, unit, unit]), 0.0, 4.0);
    assert_eq!(range_of("x^2", [(-1.0, 2.0), unit, unit, unit]).lo(), 0.0);
    assert!(range_of("x^4 + y^2", [(-1.0, 1.0), (-3.0, 2.0), unit, unit]).lo() >= 0.0);
    close(range_of("x*x", [(-1.0, 2.0), unit, unit, unit]), 0.0, 4.0);
    close(range_of("x^3", [(-1.0, 2.0), unit, unit, unit]), -1.0, 8.0);
    close(range_of("sin(x)", [(0.0, 3.0), unit, unit, unit]), 0.0, 1.0);
    close(
        range_of("cos(x)", [(-1.0, 4.0), unit, unit, unit]),
        -1.0,
        1.0,
    );
    close(
        range_of("cos(x)", [(0.5, 1.0), unit, unit, unit]),
        1f64.cos(),
        0.5f64.cos(),
    );
    close(
        range_of("sin(x)", [(4.0, 5.0), unit, unit, unit]),
        -1.0,
        4f64.sin(),
    );
    close(range_of("|x|", [(-3.0, 2.0), unit, unit, unit]), 0.0, 3.0);
    close(
        range_of("exp(x)", [(0.0, 1.0), unit, unit, unit]),
        1.0,
        std::f64::consts::E,
    );
}

#[test]
fn domain_rules() {
    let unit = (0.0, 0.0);
    // sqrt and ln use only the part of the box inside their domain.
    close(
        range_of("sqrt(x)", [(-4.0, 4.0), unit, unit, unit]),
        0.0,
        2.0,
    );
    assert!(range_of("sqrt(x)", [(-4.0, -1.0), unit, unit, unit]).is_empty());
    let ln = range_of("ln(x)", [(-1.0, 1.0), unit, unit, unit]);
    assert_eq!(ln.lo(), f64::NEG_INFINITY);
    assert!(ln.hi() >= 0.0 && ln.hi() < 1e-12);
    assert!(range_of("ln(x)", [(-2.0, -1.0), unit, unit, unit]).is_empty());
    // Division by an interval holding 0: unbounded, never narrow, never a panic.
    let q = range_of("1/x", [(-1.0, 1.0), unit, unit, unit]);
    assert_eq!((q.lo(), q.hi()), (f64::NEG_INFINITY, f64::INFINITY));
    let half = range_of("1/x", [(0.0, 2.0), unit, unit, unit]);
    assert!(half.lo() <= 0.5 && half.hi() == f64::INFINITY);
    assert!(range_of("x/y", [(1.0, 2.0), (0.0, 0.0), unit, unit]).is_empty());
    // Empty propagates: no point of M where F is undefined.
    assert!(range_of("sqrt(x) + y", [(-4.0, -1.0), (-1.0, 1.0), unit, unit]).is_empty());
    // Real powers of negative bases are undefined.
    assert!(range_of("pow(x, 0.5)", [(-2.0, -1.0), unit, unit, unit]).is_empty());
    // tan across a pole is unbounded.
    let t = range_of("tan(x)", [(1.0, 2.0), unit, unit, unit]);
    assert_eq!((t.lo(), t.hi()), (f64::NEG_INFINITY, f64::INFINITY));
}

#[test]
fn outward_rounding_holds_inexact_results() {
    // 0.1 + 0.2 is not representable; the enclosure must hold the true sum of the two doubles.
    let a = Interval::point(0.1);
    let b = Interval::point(0.2);
    let s = a.add(b);
    assert!(s.lo() < 0.1 + 0.2 && s.hi() >= 0.1 + 0.2);
    assert!(s.lo() < s.hi());
}

#[test]
fn empty_and_overflow_cases_of_the_branch_free_rounding() {
    let e = Interval::EMPTY;
    let entire = Interval::new(f64::NEG_INFINITY, f64::INFINITY);
    let one = Interval::new(-1.0, 1.0);
    // An empty operand makes every sum, difference and product empty, also with ±∞ bounds.
    for (a, b) in [(e, one), (one, e), (e, entire), (entire, e), (e, e)] {
        assert!(a.add(b).is_empty(), "{a:?} + {b:?}");
        assert!(a.sub(b).is_empty(), "{a:?} - {b:?}");
        assert!(a.mul(b).is_empty(), "{a:?} * {b:?}");
    }
    // A sum that overflows is bounded below by something finite and above by +∞.
    let big = Interval::point(f64::MAX);
    let s = big.add(big);
    assert!(s.lo() <= f64::MAX && s.lo() > 1e307 && s.hi() == f64::INFINITY);
    let d = big.neg().sub(big);
    assert!(d.hi() >= -f64::MAX && d.lo() == f64::NEG_INFINITY);
    // Zero and subnormal results still move outward.
    let tiny = Interval::point(f64::from_bits(1));
    let z = tiny.sub(tiny);
    assert!(z.lo() < 0.0 && z.hi() > 0.0);
    // Unbounded operands stay unbounded and never turn into NaN.
    let half = Interval::new(0.0, f64::INFINITY);
    let p = half.mul(Interval::new(-2.0, 3.0));
    assert_eq!((p.lo(), p.hi()), (f64::NEG_INFINITY, f64::INFINITY));
    let q = half.add(Interval::point(-1.0));
    assert!(q.lo() <= -1.0 && q.hi() == f64::INFINITY);
}
