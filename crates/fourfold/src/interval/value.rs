//! The interval type: a closed interval [lo, hi] of reals, possibly unbounded, or empty; its
//! constructors and what it tells without arithmetic.

/// A closed interval [lo, hi] of reals, possibly unbounded, or empty.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Interval {
    pub(super) lo: f64,
    pub(super) hi: f64,
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

    /// The largest |v| of v in the interval (+∞ for an empty one, whose ends are not
    /// finite).
    pub fn magnitude(self) -> f64 {
        self.lo.abs().max(self.hi.abs())
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
