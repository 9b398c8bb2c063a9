//! Directed rounding on the bits of an f64, without branches: the next float below or above,
//! a library function's wider steps, and powers bounded from below and above.

/// How many ulps a library function's bounds are widened.
pub const LIB_ULPS: u32 = 2;

/// The next float below `x` (one ulp; enough, as `+ - * /` and `sqrt` are correctly rounded,
/// so their exact result is within half an ulp of the rounded one). Done on the bits, with
/// selects rather than branches: the rounding is on the critical path of every interval
/// operation, and a float-arithmetic version cost four dependent operations. +∞ (an overflow:
/// the exact value is above `f64::MAX`) comes down to `MAX`; −∞ stays; ±0 gives the smallest
/// negative subnormal; NaN (only from an empty operand) stays NaN, so the result stays empty.
#[inline]
pub(super) fn down(x: f64) -> f64 {
    let b = x.to_bits() as i64;
    // Positive floats: one step down is bits − 1; negative ones: bits + 1.
    let r = f64::from_bits((b - ((b >> 63) | 1)) as u64);
    let r = if x == f64::NEG_INFINITY { x } else { r };
    if x == 0.0 { -TINY } else { r }
}

/// The next float above `x`; see [`down`]. −∞ comes up to `−MAX`, +∞ stays.
#[inline]
pub(super) fn up(x: f64) -> f64 {
    let b = x.to_bits() as i64;
    let r = f64::from_bits((b + ((b >> 63) | 1)) as u64);
    let r = if x == f64::INFINITY { x } else { r };
    if x == 0.0 { TINY } else { r }
}

/// `a < b ? a : b`: one `minsd`, unlike `f64::min`, which handles NaN. A NaN `a` gives `b`.
#[inline]
pub fn lesser(a: f64, b: f64) -> f64 {
    if a < b { a } else { b }
}

/// `a > b ? a : b`; a NaN `a` gives `b`.
#[inline]
pub fn greater(a: f64, b: f64) -> f64 {
    if a > b { a } else { b }
}

/// The smallest positive subnormal.
const TINY: f64 = f64::from_bits(1);

#[inline]
pub(super) fn lib_down(x: f64) -> f64 {
    let mut x = x;
    for _ in 0..LIB_ULPS {
        x = down(x);
    }
    x
}

#[inline]
pub(super) fn lib_up(x: f64) -> f64 {
    let mut x = x;
    for _ in 0..LIB_ULPS {
        x = up(x);
    }
    x
}

/// A lower bound of x^k for x ≥ 0 (square-and-multiply, every product rounded down; the
/// operands stay non-negative, so each rounded product bounds the exact one from below).
#[inline]
pub(super) fn pow_down(x: f64, k: u32) -> f64 {
    directed_pow(x, k, |a, b| greater(down(a * b), 0.0))
}

/// An upper bound of x^k for x ≥ 0.
#[inline]
pub(super) fn pow_up(x: f64, k: u32) -> f64 {
    directed_pow(x, k, |a, b| up(a * b))
}

#[inline]
fn directed_pow(x: f64, mut k: u32, mul: impl Fn(f64, f64) -> f64) -> f64 {
    if x == 0.0 || x.is_infinite() {
        return x;
    }
    let mut base = x;
    let mut acc = 1.0;
    loop {
        if k & 1 == 1 {
            acc = if acc == 1.0 { base } else { mul(acc, base) };
        }
        k >>= 1;
        if k == 0 {
            return acc;
        }
        base = mul(base, base);
    }
}

/// Product in which 0 × ∞ is 0: the bound of a set product, not an IEEE product.
#[inline]
pub(super) fn mul0(a: f64, b: f64) -> f64 {
    if a == 0.0 || b == 0.0 { 0.0 } else { a * b }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// x^k in double-double arithmetic (each product's rounding error recovered exactly by
    /// a fused multiply-add): within k·2^-100 of the exact power, relative.
    fn double_double_pow(x: f64, k: u32) -> (f64, f64) {
        let mul = |(ah, al): (f64, f64), (bh, bl): (f64, f64)| {
            let p = ah * bh;
            let e = ah.mul_add(bh, -p) + (ah * bl + al * bh);
            let hi = p + e;
            (hi, e - (hi - p))
        };
        let mut acc = (1.0, 0.0);
        for _ in 0..k {
            acc = mul(acc, (x, 0.0));
        }
        acc
    }

    proptest! {
        /// The bounds hold the exact power and lie within a few ulps per product of it, for
        /// small, tiny and huge bases.
        #[test]
        fn powers_bounds_hold_the_exact_power(
            mantissa in 1.0f64..2.0,
            exponent in prop_oneof![-8i32..8, -400i32..400],
            k in 1u32..40,
        ) {
            let x = mantissa * 2f64.powi(exponent);
            let (hi, lo) = double_double_pow(x, k);
            prop_assume!(hi.is_normal() && hi < f64::MAX / 4.0);
            let margin = hi * f64::from(k) * 2f64.powi(-100);
            let (down, up) = (pow_down(x, k), pow_up(x, k));
            // (down − hi and up − hi are exact: each lies within a few ulps of hi. A bound
            // may be the exact power itself, which the margin then allows for.)
            prop_assert!(down - hi <= lo + margin, "{x}^{k}: {down} above {hi} + {lo}");
            prop_assert!(up - hi >= lo - margin, "{x}^{k}: {up} below {hi} + {lo}");
            let ulps = 4.0 * f64::from(k) * f64::EPSILON * hi;
            prop_assert!(hi - down <= ulps && up - hi <= ulps, "{x}^{k}: [{down}, {up}] around {hi}");
        }
    }
}
