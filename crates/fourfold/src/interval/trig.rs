//! Interval sin and cos for arguments within ±[`REDUCIBLE`], without the platform's libm: a
//! Cody–Waite range reduction to x = k·π/2 + r, Taylor polynomials in r, every endpoint value
//! within [`VALUE_ERROR`] of the true one (the bound is derived in docs/method.md §1), and
//! the extrema found from the exact quadrant index k. No branch, so that the batch
//! evaluator's lane loops vectorize (and cheaper than two libm calls in the one-box
//! evaluator too). Larger or unbounded arguments take the libm path in `functions.rs`.

use std::f64::consts::FRAC_2_PI;

use super::rounding::{greater, lesser};
use super::value::Interval;

/// The largest |x| reduced here: |k| < 2^20, so k·P1 and k·P2 are exact.
pub(crate) const REDUCIBLE: f64 = 1_048_576.0;

/// The amount by which each endpoint's value is widened: the bound of docs/method.md §1,
/// 6e-16, with a margin over three.
pub(crate) const VALUE_ERROR: f64 = 2e-15;

/// The bound on the reduced argument's error, |r̃ − r|: 3 roundings of values below 0.8.
const REDUCTION_ERROR: f64 = 3e-16;

/// π/2 in three parts: P1 has 31 significant bits and P2 32, so that k·P1 and k·P2 are exact
/// for |k| < 2^21; P1 + P2 + P3 is π/2 within 2^-120.
const P1: f64 = f64::from_bits(0x3FF9_21FB_5440_0000);
const P2: f64 = f64::from_bits(0x3DD0_B461_1A60_0000);
const P3: f64 = f64::from_bits(0x3BA3_198A_2E03_7073);

/// 1.5·2^52: adding it rounds a number below 2^51 in magnitude to an integer, which is then
/// the low bits of the sum.
const ROUNDER: f64 = 6_755_399_441_055_744.0;

/// Taylor coefficients of sin r / r in z = r², from z¹ up (1/3!, 1/5!, ... with signs).
const SIN: [f64; 7] = [
    -1.0 / 6.0,
    1.0 / 120.0,
    -1.0 / 5_040.0,
    1.0 / 362_880.0,
    -1.0 / 39_916_800.0,
    1.0 / 6_227_020_800.0,
    -1.0 / 1_307_674_368_000.0,
];

/// Taylor coefficients of cos r in z = r², from z² up.
const COS: [f64; 7] = [
    1.0 / 24.0,
    -1.0 / 720.0,
    1.0 / 40_320.0,
    -1.0 / 3_628_800.0,
    1.0 / 479_001_600.0,
    -1.0 / 87_178_291_200.0,
    1.0 / 20_922_789_888_000.0,
];

/// Whether `a` is non-empty with both ends within ±REDUCIBLE (false for NaN and ±∞).
#[inline(always)]
pub(crate) fn reducible(a: Interval) -> bool {
    (a.lo().abs() <= REDUCIBLE) & (a.hi().abs() <= REDUCIBLE) & (a.lo() <= a.hi())
}

/// x = k·π/2 + r with k the nearest integer to x·2/π (as an integer) and r̃ within
/// REDUCTION_ERROR of r, |r| < 0.786.
#[inline(always)]
fn reduce(x: f64) -> (i64, f64) {
    let t = x * FRAC_2_PI + ROUNDER;
    let k = t - ROUNDER;
    let q = (t.to_bits() as i64).wrapping_sub(ROUNDER.to_bits() as i64);
    (q, ((x - k * P1) - k * P2) - k * P3)
}

/// Horner's scheme over `coefficients`, highest last.
#[inline(always)]
fn horner(z: f64, coefficients: &[f64; 7]) -> f64 {
    coefficients.iter().rev().fold(0.0, |p, &c| p * z + c)
}

/// sin(k·π/2 + r): ±sin r or ±cos r by k mod 4.
#[inline(always)]
fn sin_of(k: i64, r: f64) -> f64 {
    let z = r * r;
    let sin = r + r * z * horner(z, &SIN);
    let cos = (1.0 - 0.5 * z) + z * z * horner(z, &COS);
    let v = if k & 1 == 0 { sin } else { cos };
    if k & 2 == 0 { v } else { -v }
}

/// Encloses sin(x + shift·π/2) over `a`, which must be [`reducible`]: sin for shift 0, cos
/// for shift 1.
#[inline(always)]
pub(crate) fn shifted_sin(a: Interval, shift: i64) -> Interval {
    let (kl, rl) = reduce(a.lo());
    let (kh, rh) = reduce(a.hi());
    let (vl, vh) = (sin_of(kl + shift, rl), sin_of(kh + shift, rh));
    // The integers n with n·π/2 possibly in [lo, hi] (widened by the reduction's error).
    let first = kl + i64::from(rl > REDUCTION_ERROR);
    let last = kh - i64::from(rh < -REDUCTION_ERROR);
    // Whether one of them has n + shift ≡ c (mod 4): sin peaks at c = 1 and dips at c = 3.
    let hits = |c: i64| (last + shift - c) >> 2 >= (first + shift - c + 3) >> 2;
    let lo = if hits(3) {
        -1.0
    } else {
        greater(lesser(vl, vh) - VALUE_ERROR, -1.0)
    };
    let hi = if hits(1) {
        1.0
    } else {
        lesser(greater(vl, vh) + VALUE_ERROR, 1.0)
    };
    Interval::from_bounds(lo, hi)
}

/// Encloses sin over `a`, which must be [`reducible`].
#[inline(always)]
pub(crate) fn sin(a: Interval) -> Interval {
    shifted_sin(a, 0)
}

/// Encloses cos over `a`, which must be [`reducible`].
#[inline(always)]
pub(crate) fn cos(a: Interval) -> Interval {
    shifted_sin(a, 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The endpoint values stay well within VALUE_ERROR of libm's (itself within an ulp).
    #[test]
    fn values_match_libm() {
        let mut worst = 0.0_f64;
        let mut x = -REDUCIBLE;
        let mut check = |x: f64| {
            let (k, r) = reduce(x);
            worst = worst
                .max((sin_of(k, r) - x.sin()).abs())
                .max((sin_of(k + 1, r) - x.cos()).abs());
        };
        while x <= REDUCIBLE {
            check(x);
            x += 0.000_37 * (1.0 + x.abs());
        }
        // Next to the multiples of π/2, where r is smallest and the quadrant flips.
        for n in -1000..1000 {
            let p = f64::from(n) * std::f64::consts::FRAC_PI_2;
            for ulps in -3i64..=3 {
                check(f64::from_bits((p.to_bits() as i64 + ulps) as u64));
            }
        }
        assert!(worst < VALUE_ERROR / 4.0, "worst error {worst:e}");
    }
}
