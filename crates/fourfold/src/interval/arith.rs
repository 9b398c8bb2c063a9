//! Interval arithmetic, rounded outward: sums, differences, products and quotients (with
//! branch-free paths for finite operands, which the batch evaluator's lane loops use), and
//! the algebraic functions (|x|, x², xⁿ, √x, ∛x).

use super::rounding::{down, greater, lesser, lib_down, lib_up, mul0, pow_down, pow_up, up};
use super::value::Interval;

impl Interval {
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
}
