//! The library functions over intervals: exp and ln, the trigonometric and hyperbolic
//! functions and their inverses, sign and step, min and max, real powers and atan2. Bounds
//! from libm are widened by its error (`LIB_ULPS`); sin and cos use the reduction of
//! `trig.rs` where the argument allows.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use super::rounding::{lib_down, lib_up, up};
use super::trig;
use super::value::Interval;

impl Interval {
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
        let slack = 4.0 * f64::EPSILON * self.magnitude() + 1e-300;
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
        let slack = 4.0 * f64::EPSILON * self.magnitude() + 1e-300;
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
        let slack = 4.0 * f64::EPSILON * self.magnitude() + 1e-300;
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
