//! A rigorous interval type: every operation returns an interval that contains the exact
//! result of the operation on every pair of real numbers in its operands (and, for library
//! functions, every value the platform's `f64` function returns there).
//!
//! * Arithmetic rounds outward: each bound of `+ - * /` and `sqrt` (correctly rounded by IEEE
//!   754) is moved one ulp out.
//! * Library functions (`exp`, `sin`, ...) are not correctly rounded; their bounds are moved
//!   out by [`LIB_ULPS`] ulps, above the documented error of glibc, musl and the Rust `libm`.
//! * Domain rules follow IEEE 1788's set-based flavour: `sqrt`, `ln`, `asin`, `acos` and real
//!   `pow` use only the part of the argument inside their domain; an argument wholly outside
//!   gives the empty interval. Division by an interval containing 0 gives a half-line or the
//!   whole line; division by exactly [0, 0] is empty.
//! * Even powers and `x²` are never negative; `sin`/`cos` find their extrema by quadrant.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use super::trig;

/// How many ulps a library function's bounds are widened.
pub const LIB_ULPS: u32 = 2;

/// A closed interval [lo, hi] of reals, possibly unbounded, or empty.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Interval {
    lo: f64,
    hi: f64,
}

/// The next float below `x` (one ulp; enough, as `+ - * /` and `sqrt` are correctly rounded,
/// so their exact result is within half an ulp of the rounded one). Done on the bits, with
/// selects rather than branches: the rounding is on the critical path of every interval
/// operation, and a float-arithmetic version cost four dependent operations. +∞ (an overflow:
/// the exact value is above `f64::MAX`) comes down to `MAX`; −∞ stays; ±0 gives the smallest
/// negative subnormal; NaN (only from an empty operand) stays NaN, so the result stays empty.
#[inline]
fn down(x: f64) -> f64 {
    let b = x.to_bits() as i64;
    // Positive floats: one step down is bits − 1; negative ones: bits + 1.
    let r = f64::from_bits((b - ((b >> 63) | 1)) as u64);
    let r = if x == f64::NEG_INFINITY { x } else { r };
    if x == 0.0 { -TINY } else { r }
}

/// The next float above `x`; see [`down`]. −∞ comes up to `−MAX`, +∞ stays.
#[inline]
fn up(x: f64) -> f64 {
    let b = x.to_bits() as i64;
    let r = f64::from_bits((b + ((b >> 63) | 1)) as u64);
    let r = if x == f64::INFINITY { x } else { r };
    if x == 0.0 { TINY } else { r }
}

/// `a < b ? a : b`: one `minsd`, unlike `f64::min`, which handles NaN. A NaN `a` gives `b`.
#[inline]
pub(crate) fn lesser(a: f64, b: f64) -> f64 {
    if a < b { a } else { b }
}

/// `a > b ? a : b`; a NaN `a` gives `b`.
#[inline]
pub(crate) fn greater(a: f64, b: f64) -> f64 {
    if a > b { a } else { b }
}

/// The smallest positive subnormal.
const TINY: f64 = f64::from_bits(1);

#[inline]
fn lib_down(x: f64) -> f64 {
    let mut x = x;
    for _ in 0..LIB_ULPS {
        x = down(x);
    }
    x
}

#[inline]
fn lib_up(x: f64) -> f64 {
    let mut x = x;
    for _ in 0..LIB_ULPS {
        x = up(x);
    }
    x
}

/// A lower bound of x^k for x ≥ 0 (square-and-multiply, every product rounded down; the
/// operands stay non-negative, so each rounded product bounds the exact one from below).
#[inline]
fn pow_down(x: f64, k: u32) -> f64 {
    directed_pow(x, k, |a, b| greater(down(a * b), 0.0))
}

/// An upper bound of x^k for x ≥ 0.
#[inline]
fn pow_up(x: f64, k: u32) -> f64 {
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
fn mul0(a: f64, b: f64) -> f64 {
    if a == 0.0 || b == 0.0 { 0.0 } else { a * b }
}

impl Interval {
    pub const EMPTY: Interval = Interval {
        lo: f64::INFINITY,
        hi: f64::NEG_INFINITY,
    };
    pub const ENTIRE: Interval = Interval {
        lo: f64::NEG_INFINITY,
        hi: f64::INFINITY,
    };
    pub const ZERO: Interval = Interval { lo: 0.0, hi: 0.0 };
    pub const ONE: Interval = Interval { lo: 1.0, hi: 1.0 };

    /// [lo, hi]; empty if lo > hi or either bound is NaN.
    #[inline]
    pub fn new(lo: f64, hi: f64) -> Self {
        if lo <= hi {
            Self { lo, hi }
        } else {
            Self::EMPTY
        }
    }

    /// The interval holding exactly `v` (empty for NaN, which is no real number).
    #[inline]
    pub fn point(v: f64) -> Self {
        Self::new(v, v)
    }

    /// The interval with these bounds, unchecked: for bounds taken from an interval.
    #[inline]
    pub(crate) const fn from_bounds(lo: f64, hi: f64) -> Self {
        Self { lo, hi }
    }

    #[inline]
    pub const fn lo(self) -> f64 {
        self.lo
    }
    #[inline]
    pub const fn hi(self) -> f64 {
        self.hi
    }
    #[inline]
    pub fn is_empty(self) -> bool {
        !(self.lo <= self.hi)
    }
    #[inline]
    pub fn contains(self, v: f64) -> bool {
        self.lo <= v && v <= self.hi
    }
    #[inline]
    pub fn contains_zero(self) -> bool {
        self.lo <= 0.0 && 0.0 <= self.hi
    }
    pub fn width(self) -> f64 {
        if self.is_empty() {
            0.0
        } else {
            self.hi - self.lo
        }
    }
    pub fn midpoint(self) -> f64 {
        0.5 * self.lo + 0.5 * self.hi
    }
    /// The smallest interval holding both.
    pub fn hull(self, other: Self) -> Self {
        if self.is_empty() {
            return other;
        }
        if other.is_empty() {
            return self;
        }
        Self::new(self.lo.min(other.lo), self.hi.max(other.hi))
    }
    /// The part of `self` inside [lo, hi].
    pub fn intersect(self, lo: f64, hi: f64) -> Self {
        if self.is_empty() {
            return self;
        }
        Self::new(self.lo.max(lo), self.hi.min(hi))
    }

    #[inline]
    pub fn add(self, b: Self) -> Self {
        // No empty check needed: EMPTY is [+∞, −∞], so an empty operand makes lo = +∞ or NaN
        // and hi = −∞ or NaN, which `down`/`up` keep out of order, and `new` gives EMPTY.
        let lo = down(self.lo + b.lo);
        // A sum of non-negative numbers is non-negative: keep x^2 + y^2 ≥ 0 exact.
        let floor = if (self.lo >= 0.0) & (b.lo >= 0.0) {
            0.0
        } else {
            f64::NEG_INFINITY
        };
        let lo = greater(lo, floor);
        Self::new(lo, up(self.hi + b.hi))
    }

    #[inline]
    pub fn sub(self, b: Self) -> Self {
        // Empty operands give EMPTY as in `add`.
        Self::new(down(self.lo - b.hi), up(self.hi - b.lo))
    }

    #[inline]
    pub fn neg(self) -> Self {
        // EMPTY, [+∞, −∞], negates to itself.
        Self {
            lo: -self.hi,
            hi: -self.lo,
        }
    }

    #[inline]
    pub fn mul(self, b: Self) -> Self {
        if Self::multiplies_finite(self, b) {
            return self.mul_finite(b);
        }
        self.mul_unbounded(b)
    }

    /// Whether `mul_finite` applies: every bound finite (so neither operand empty).
    #[inline]
    pub(crate) fn multiplies_finite(a: Self, b: Self) -> bool {
        a.is_finite() & b.is_finite()
    }

    /// Both bounds finite (so not empty either).
    #[inline]
    fn is_finite(self) -> bool {
        (self.lo.abs() < f64::INFINITY) & (self.hi.abs() < f64::INFINITY)
    }

    /// The product of two intervals with finite bounds (the usual case): four plain products
    /// and min/max with no branch, so that a loop of them vectorizes; no 0·∞ can occur.
    #[inline]
    pub(crate) fn mul_finite(self, b: Self) -> Self {
        let a = self;
        let (p1, p2, p3, p4) = (a.lo * b.lo, a.lo * b.hi, a.hi * b.lo, a.hi * b.hi);
        let lo = lesser(lesser(p1, p2), lesser(p3, p4));
        let hi = greater(greater(p1, p2), greater(p3, p4));
        // Products of two non-negative (or two non-positive) intervals stay ≥ 0.
        let floor = if ((a.lo >= 0.0) & (b.lo >= 0.0)) | ((a.hi <= 0.0) & (b.hi <= 0.0)) {
            0.0
        } else {
            f64::NEG_INFINITY
        };
        Self::new(greater(down(lo), floor), up(hi))
    }

    /// The product where a bound is infinite or an operand empty: by sign cases, with 0·∞ = 0.
    fn mul_unbounded(self, b: Self) -> Self {
        if self.is_empty() || b.is_empty() {
            return Self::EMPTY;
        }
        let a = self;
        // Sign cases: two products unless both straddle zero.
        let (lo, hi) = if a.lo >= 0.0 {
            if b.lo >= 0.0 {
                return Self::new(greater(down(mul0(a.lo, b.lo)), 0.0), up(mul0(a.hi, b.hi)));
            } else if b.hi <= 0.0 {
                (mul0(a.hi, b.lo), mul0(a.lo, b.hi))
            } else {
                (mul0(a.hi, b.lo), mul0(a.hi, b.hi))
            }
        } else if a.hi <= 0.0 {
            if b.lo >= 0.0 {
                (mul0(a.lo, b.hi), mul0(a.hi, b.lo))
            } else if b.hi <= 0.0 {
                return Self::new(greater(down(mul0(a.hi, b.hi)), 0.0), up(mul0(a.lo, b.lo)));
            } else {
                (mul0(a.lo, b.hi), mul0(a.lo, b.lo))
            }
        } else if b.lo >= 0.0 {
            (mul0(a.lo, b.hi), mul0(a.hi, b.hi))
        } else if b.hi <= 0.0 {
            (mul0(a.hi, b.lo), mul0(a.lo, b.lo))
        } else {
            (
                lesser(mul0(a.lo, b.hi), mul0(a.hi, b.lo)),
                greater(mul0(a.lo, b.lo), mul0(a.hi, b.hi)),
            )
        };
        Self::new(down(lo), up(hi))
    }

    #[inline]
    pub fn div(self, b: Self) -> Self {
        if Self::divides_finite(self, b) {
            return self.div_finite(b);
        }
        self.div_general(b)
    }

    /// Whether `div_finite` applies: finite bounds and a divisor away from 0.
    #[inline]
    pub(crate) fn divides_finite(a: Self, b: Self) -> bool {
        a.is_finite() & b.is_finite() & !b.contains_zero()
    }

    /// The quotient by a divisor away from 0, all bounds finite (the usual case): four plain
    /// quotients and min/max with no branch, as in `mul_finite`.
    #[inline]
    pub(crate) fn div_finite(self, b: Self) -> Self {
        let a = self;
        let (q1, q2, q3, q4) = (a.lo / b.lo, a.lo / b.hi, a.hi / b.lo, a.hi / b.hi);
        let lo = lesser(lesser(q1, q2), lesser(q3, q4));
        let hi = greater(greater(q1, q2), greater(q3, q4));
        Self::new(down(lo), up(hi))
    }

    fn div_general(self, b: Self) -> Self {
        if self.is_empty() || b.is_empty() || (b.lo == 0.0 && b.hi == 0.0) {
            return Self::EMPTY;
        }
        let a = self;
        if b.contains_zero() {
            if a.lo == 0.0 && a.hi == 0.0 {
                return Self::ZERO;
            }
            // Only one side of 0 in the divisor: a half-line, when a keeps its sign.
            if b.lo == 0.0 {
                if a.lo >= 0.0 {
                    return Self::new(down(a.lo / b.hi), f64::INFINITY);
                }
                if a.hi <= 0.0 {
                    return Self::new(f64::NEG_INFINITY, up(a.hi / b.hi));
                }
            } else if b.hi == 0.0 {
                if a.lo >= 0.0 {
                    return Self::new(f64::NEG_INFINITY, up(a.lo / b.lo));
                }
                if a.hi <= 0.0 {
                    return Self::new(down(a.hi / b.lo), f64::INFINITY);
                }
            }
            return Self::ENTIRE;
        }
        let q = |x: f64, y: f64| {
            if x == 0.0 {
                0.0
            } else if y.is_infinite() && x.is_infinite() {
                // ∞/∞ over a set: unbounded, the sign of the quotient.
                if (x > 0.0) == (y > 0.0) {
                    f64::INFINITY
                } else {
                    f64::NEG_INFINITY
                }
            } else {
                x / y
            }
        };
        let p = [q(a.lo, b.lo), q(a.lo, b.hi), q(a.hi, b.lo), q(a.hi, b.hi)];
        let lo = p[0].min(p[1]).min(p[2]).min(p[3]);
        let hi = p[0].max(p[1]).max(p[2]).max(p[3]);
        if b.lo.is_infinite() || b.hi.is_infinite() {
            // x/±∞ → 0 bounds the quotient from one side; include 0 to stay sound.
            return Self::new(down(lo.min(0.0)), up(hi.max(0.0)));
        }
        Self::new(down(lo), up(hi))
    }

    #[inline]
    pub fn abs(self) -> Self {
        if self.is_empty() || self.lo >= 0.0 {
            self
        } else if self.hi <= 0.0 {
            self.neg()
        } else {
            Self::new(0.0, greater(-self.lo, self.hi))
        }
    }

    /// x², never negative; the same as `powi(2)`.
    #[inline]
    pub fn square(self) -> Self {
        // Branch-free: the squares of the ends, and 0 when the interval straddles 0.
        let (a, b) = (self.lo * self.lo, self.hi * self.hi);
        let lo = if (self.lo < 0.0) & (self.hi > 0.0) {
            0.0
        } else {
            lesser(a, b)
        };
        let square = Self::new(greater(down(lo), 0.0), up(greater(a, b)));
        if self.is_empty() { Self::EMPTY } else { square }
    }

    /// x^n for an integer n; tight (never negative) for even n.
    #[inline]
    pub fn powi(self, n: i32) -> Self {
        if self.is_empty() {
            return self;
        }
        match n {
            0 => return Self::ONE,
            1 => return self,
            n if n < 0 => return Self::ONE.div(self.powi(-n)),
            _ => {}
        }
        let k = n.unsigned_abs();
        if n % 2 == 0 {
            // |x|^n is increasing in |x|: bound each end by a directed power.
            let m = self.abs();
            Self::new(pow_down(m.lo, k), pow_up(m.hi, k))
        } else {
            // x^n is increasing and odd: (-a)^n = -(a^n).
            let lo = if self.lo >= 0.0 {
                pow_down(self.lo, k)
            } else {
                -pow_up(-self.lo, k)
            };
            let hi = if self.hi >= 0.0 {
                pow_up(self.hi, k)
            } else {
                -pow_down(-self.hi, k)
            };
            Self::new(lo, hi)
        }
    }

    /// Branch-free: a negative `hi` (the argument wholly outside the domain) or an empty
    /// argument make `hi` NaN, and the result empty.
    #[inline]
    pub fn sqrt(self) -> Self {
        let lo = greater(self.lo, 0.0).sqrt();
        Self::new(greater(down(lo), 0.0), up(self.hi.sqrt()))
    }

    pub fn cbrt(self) -> Self {
        if self.is_empty() {
            return self;
        }
        Self::new(lib_down(self.lo.cbrt()), lib_up(self.hi.cbrt()))
    }

    pub fn exp(self) -> Self {
        if self.is_empty() {
            return self;
        }
        Self::new(lib_down(self.lo.exp()).max(0.0), lib_up(self.hi.exp()))
    }

    pub fn ln(self) -> Self {
        if self.is_empty() || self.hi <= 0.0 {
            return Self::EMPTY;
        }
        let lo = if self.lo <= 0.0 {
            f64::NEG_INFINITY
        } else {
            lib_down(self.lo.ln())
        };
        Self::new(lo, lib_up(self.hi.ln()))
    }

    /// cos, with its maxima at 2kπ and minima at π + 2kπ found by quadrant.
    #[inline]
    pub fn cos(self) -> Self {
        if trig::reducible(self) {
            return trig::cos(self);
        }
        self.cos_libm()
    }

    /// cos through the platform's libm, for arguments [`trig`] does not reduce.
    fn cos_libm(self) -> Self {
        if self.is_empty() {
            return self;
        }
        if !(self.hi - self.lo < TAU) {
            return Self::new(-1.0, 1.0);
        }
        let (clo, chi) = (self.lo.cos(), self.hi.cos());
        let mut lo = lib_down(clo.min(chi));
        let mut hi = lib_up(clo.max(chi));
        // PI and TAU are rounded; testing a slightly wider interval keeps the test sound.
        let slack = 4.0 * f64::EPSILON * self.lo.abs().max(self.hi.abs()) + 1e-300;
        if contains_multiple(self.lo - slack, self.hi + slack, 0.0, TAU) {
            hi = 1.0;
        }
        if contains_multiple(self.lo - slack, self.hi + slack, PI, TAU) {
            lo = -1.0;
        }
        Self::new(lo.max(-1.0), hi.min(1.0))
    }

    #[inline]
    pub fn sin(self) -> Self {
        if trig::reducible(self) {
            return trig::sin(self);
        }
        self.sin_libm()
    }

    /// sin through the platform's libm, for arguments [`trig`] does not reduce.
    fn sin_libm(self) -> Self {
        if self.is_empty() {
            return self;
        }
        if !(self.hi - self.lo < TAU) {
            return Self::new(-1.0, 1.0);
        }
        let (slo, shi) = (self.lo.sin(), self.hi.sin());
        let mut lo = lib_down(slo.min(shi));
        let mut hi = lib_up(slo.max(shi));
        let slack = 4.0 * f64::EPSILON * self.lo.abs().max(self.hi.abs()) + 1e-300;
        if contains_multiple(self.lo - slack, self.hi + slack, FRAC_PI_2, TAU) {
            hi = 1.0;
        }
        if contains_multiple(self.lo - slack, self.hi + slack, -FRAC_PI_2, TAU) {
            lo = -1.0;
        }
        Self::new(lo.max(-1.0), hi.min(1.0))
    }

    pub fn tan(self) -> Self {
        if self.is_empty() {
            return self;
        }
        if !(self.hi - self.lo < PI) {
            return Self::ENTIRE;
        }
        let slack = 4.0 * f64::EPSILON * self.lo.abs().max(self.hi.abs()) + 1e-300;
        if contains_multiple(self.lo - slack, self.hi + slack, FRAC_PI_2, PI) {
            return Self::ENTIRE;
        }
        Self::new(lib_down(self.lo.tan()), lib_up(self.hi.tan()))
    }

    pub fn asin(self) -> Self {
        let d = self.intersect(-1.0, 1.0);
        if d.is_empty() {
            return d;
        }
        let limit = up(FRAC_PI_2);
        Self::new(
            lib_down(d.lo.asin()).max(-limit),
            lib_up(d.hi.asin()).min(limit),
        )
    }

    pub fn acos(self) -> Self {
        let d = self.intersect(-1.0, 1.0);
        if d.is_empty() {
            return d;
        }
        Self::new(
            lib_down(d.hi.acos()).max(0.0),
            lib_up(d.lo.acos()).min(up(PI)),
        )
    }

    pub fn atan(self) -> Self {
        if self.is_empty() {
            return self;
        }
        let limit = up(FRAC_PI_2);
        Self::new(
            lib_down(self.lo.atan()).max(-limit),
            lib_up(self.hi.atan()).min(limit),
        )
    }

    pub fn sinh(self) -> Self {
        if self.is_empty() {
            return self;
        }
        Self::new(lib_down(self.lo.sinh()), lib_up(self.hi.sinh()))
    }

    pub fn cosh(self) -> Self {
        if self.is_empty() {
            return self;
        }
        let m = self.abs();
        let lo = if m.lo == 0.0 {
            1.0
        } else {
            lib_down(m.lo.cosh()).max(1.0)
        };
        Self::new(lo, lib_up(m.hi.cosh()))
    }

    pub fn tanh(self) -> Self {
        if self.is_empty() {
            return self;
        }
        Self::new(
            lib_down(self.lo.tanh()).max(-1.0),
            lib_up(self.hi.tanh()).min(1.0),
        )
    }

    pub fn sign(self) -> Self {
        if self.is_empty() {
            return self;
        }
        let s = |v: f64| v.signum() * f64::from(u8::from(v != 0.0));
        Self::new(s(self.lo), s(self.hi))
    }

    pub fn step(self) -> Self {
        if self.is_empty() {
            return self;
        }
        let s = |v: f64| {
            if v > 0.0 {
                1.0
            } else if v < 0.0 {
                0.0
            } else {
                0.5
            }
        };
        Self::new(s(self.lo), s(self.hi))
    }

    pub fn min(self, b: Self) -> Self {
        if self.is_empty() || b.is_empty() {
            return Self::EMPTY;
        }
        Self::new(self.lo.min(b.lo), self.hi.min(b.hi))
    }

    pub fn max(self, b: Self) -> Self {
        if self.is_empty() || b.is_empty() {
            return Self::EMPTY;
        }
        Self::new(self.lo.max(b.lo), self.hi.max(b.hi))
    }

    /// Real power a^b = exp(b·ln a) over the part of `a` that is ≥ 0.
    pub fn pow(self, b: Self) -> Self {
        let a = self.intersect(0.0, f64::INFINITY);
        if a.is_empty() || b.is_empty() {
            return Self::EMPTY;
        }
        if a.hi == 0.0 {
            // 0^b: 0 for b > 0, 1 for b = 0, ∞ for b < 0 (not a real number).
            let mut r = Self::EMPTY;
            if b.hi > 0.0 {
                r = r.hull(Self::ZERO);
            }
            if b.contains_zero() {
                r = r.hull(Self::ONE);
            }
            return r;
        }
        let ln = if a.lo == 0.0 {
            Self::new(f64::NEG_INFINITY, lib_up(a.hi.ln()))
        } else {
            a.ln()
        };
        let mut r = b.mul(ln).exp();
        if a.lo == 0.0 && b.contains_zero() {
            r = r.hull(Self::ONE);
        }
        r
    }

    /// atan2(y = self, x), through atan on half-planes where it is continuous.
    pub fn atan2(self, x: Self) -> Self {
        let y = self;
        if y.is_empty() || x.is_empty() {
            return Self::EMPTY;
        }
        let full = Self::new(-up(PI), up(PI));
        let r = if x.lo > 0.0 {
            y.div(x).atan()
        } else if y.lo > 0.0 {
            Self::point(FRAC_PI_2).sub(x.div(y).atan())
        } else if y.hi < 0.0 {
            Self::point(-FRAC_PI_2).sub(x.div(y).atan())
        } else {
            full
        };
        Self::new(r.lo.max(full.lo), r.hi.min(full.hi))
    }
}

/// Whether [lo, hi] contains offset + k·period for some integer k.
fn contains_multiple(lo: f64, hi: f64, offset: f64, period: f64) -> bool {
    let k = ((lo - offset) / period).ceil();
    // The quotient is rounded: try the neighbour too. Callers pass [lo, hi] already widened
    // by more than the rounding error of `offset + k·period`.
    [k - 1.0, k].into_iter().any(|k| {
        let p = offset + k * period;
        lo <= p && p <= hi
    })
}

impl std::fmt::Display for Interval {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.is_empty() {
            write!(f, "∅")
        } else {
            write!(f, "[{}, {}]", self.lo, self.hi)
        }
    }
}
