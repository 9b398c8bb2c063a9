//! Where a pixel's observer plane (or a slice's line in it) meets a box: the range of
//! (s, t) a box's search starts from, that range cut down to the box, a point of the plane
//! inside a cell, and the box around a piece of the plane (the shader's `plane_cell`,
//! `shrink_cell`, `cell_point`), in f64 intervals.

use crate::eval::{Box4, Interval};
use crate::render::view::{FLAG_SLAB, FLAG_SLICE, Uniforms};

use super::super::bundle::span_within;
use super::{Cell, Certifier, SearchBox};

impl Certifier<'_> {
    /// The box [lo, hi] within the domain, the same box from o, and the range of (s, t) in
    /// which the pixel's plane (its slab or slice) may meet it; None where it cannot.
    pub(super) fn plane_cell(
        &self,
        o: [f32; 4],
        lo: [f32; 4],
        hi: [f32; 4],
    ) -> Option<(Box4, Box4, Cell)> {
        let u = self.u;
        // The box within the domain (boxes are padded beyond it).
        let bx = within(
            std::array::from_fn(|i| Interval::new(f64::from(lo[i]), f64::from(hi[i]))),
            &self.domain(),
        )?;
        let rel: Box4 = std::array::from_fn(|i| bx[i].sub(Interval::point(f64::from(o[i]))));
        let (s, t) = (dot(&rel, u.n1), dot(&rel, u.n2));
        // n1 and n2 are orthonormal only to f32's rounding (as the shader, generously).
        let m = 1e-5 * (s.magnitude() + t.magnitude()) + 1e-30;
        let widen = |a: Interval| a.add(Interval::new(-m, m));
        let (s, mut t) = (widen(s), widen(t));
        let (offset, half) = (
            f64::from(u.root.section_offset),
            f64::from(u.root.section_half),
        );
        if u.control.flags & FLAG_SLICE != 0 {
            if !t.contains(offset) {
                return None;
            }
            t = Interval::point(offset);
        } else if u.control.flags & FLAG_SLAB != 0 {
            t = t.intersect(offset - half, offset + half);
            if t.is_empty() {
                return None;
            }
        }
        Some((bx, rel, (s, t)))
    }

    /// Whether a slice's line through the pixel, o + s·n1 + offset·n2, misses the box `b`
    /// by far more than the search's widening of its cells (a thousandth of the distances
    /// from o, where the search's is 1e-5): then `certify_box` would find no cell there.
    pub(super) fn line_misses(&self, o: [f32; 4], b: &SearchBox) -> bool {
        let u = self.u;
        let offset = f64::from(u.root.section_offset);
        let base: [f64; 4] = std::array::from_fn(|i| f64::from(o[i]) + offset * f64::from(u.n2[i]));
        let (lo, hi) = (b.lo.map(f64::from), b.hi.map(f64::from));
        let far: f64 = (0..4)
            .map(|i| (lo[i] - base[i]).abs() + (hi[i] - base[i]).abs())
            .sum();
        let margin = 1e-3 * (far + offset.abs()) + 1e-30;
        let sides = std::array::from_fn(|i| (lo[i] - margin, hi[i] + margin));
        span_within(base.map(|b| (b, b)), u.n1.map(f64::from), sides).is_none()
    }

    /// A point of the plane within the cell, in the box `bx` where three rounds find one
    /// (the shader's `cell_point`): the cell's centre `mid`, or else its point clamped into
    /// the box (shrunk by a thousandth) and projected back on the plane, kept in the cell.
    pub(super) fn cell_point(
        &self,
        o: [f32; 4],
        (cs, ct): Cell,
        mid: [f64; 2],
        bx: &Box4,
    ) -> [f64; 2] {
        let mut p = mid;
        let (n1, n2) = (self.u.n1.map(f64::from), self.u.n2.map(f64::from));
        let o = o.map(f64::from);
        for _ in 0..3 {
            let x: [f64; 4] = std::array::from_fn(|i| o[i] + p[0] * n1[i] + p[1] * n2[i]);
            if (0..4).all(|i| x[i] > bx[i].lo() && x[i] < bx[i].hi()) {
                break;
            }
            let q: [f64; 4] = std::array::from_fn(|i| {
                let m = 1e-3 * (bx[i].hi() - bx[i].lo());
                x[i].clamp(bx[i].lo() + m, bx[i].hi() - m) - o[i]
            });
            let d = |n: [f64; 4]| q[0] * n[0] + q[1] * n[1] + q[2] * n[2] + q[3] * n[3];
            p = [d(n1).clamp(cs.lo(), cs.hi()), d(n2).clamp(ct.lo(), ct.hi())];
        }
        p
    }

    /// The part of the cell where o + s·n1 + t·n2 may lie in the box o + `rel`, bounded
    /// (None: nowhere): the shader's `shrink_cell`, in f64.
    pub(super) fn shrink_cell(&self, (s, t): Cell, rel: &Box4, reach: f64) -> Option<Cell> {
        let (n1, n2) = (self.u.n1.map(f64::from), self.u.n2.map(f64::from));
        let ranges: [(f64, f64); 4] = std::array::from_fn(|i| {
            let (lo, hi) = (rel[i].lo(), rel[i].hi());
            let slack = 1e-5 * (reach * (n1[i].abs() + n2[i].abs()) + lo.abs() + hi.abs()) + 1e-30;
            (lo - slack, hi + slack)
        });
        let (mut a, mut b) = ((s.lo(), s.hi()), (t.lo(), t.hi()));
        for _ in 0..2 {
            a = narrow(a, &n1, &n2, b, &ranges);
            b = narrow(b, &n2, &n1, a, &ranges);
        }
        let e = 1e-5 * reach + 1e-30;
        let s = (s.lo().max(a.0 - e), s.hi().min(a.1 + e));
        let t = (t.lo().max(b.0 - e), t.hi().min(b.1 + e));
        (s.0 <= s.1 && t.0 <= t.1).then(|| (Interval::new(s.0, s.1), Interval::new(t.0, t.1)))
    }

    /// The domain, as the frame has it (f32 bounds).
    pub(super) fn domain(&self) -> Box4 {
        domain_of(self.u)
    }

    /// [`Self::plane_box`] of the one point (s, t) = `p`, bit for bit, with no ends to
    /// order (most of the boxes F's sign is proved over).
    pub(super) fn point_box(&self, o: [f32; 4], p: [f64; 2]) -> Box4 {
        let (n1, n2) = (self.u.n1, self.u.n2);
        std::array::from_fn(|i| {
            let (c, a, b) = (f64::from(o[i]), f64::from(n1[i]), f64::from(n2[i]));
            let (sa, tb) = (p[0] * a, p[1] * b);
            let v = c + sa + tb;
            let e = (c.abs() + sa.abs() + tb.abs()) * (8.0 * f64::EPSILON / 2.0) + 1e-300;
            if v.is_finite() && e.is_finite() {
                Interval::new(v - e, v + e)
            } else {
                Interval::point(c)
                    .add(Interval::point(p[0]).mul(Interval::point(a)))
                    .add(Interval::point(p[1]).mul(Interval::point(b)))
            }
        })
    }

    /// The box around the plane's points o + s·n1 + t·n2, s in `s`, t in `t`: each
    /// coordinate's ends summed in f64 and widened by 8 units of rounding of the sum of the
    /// terms' magnitudes (its three roundings and the widening's own take at most 4), at
    /// a fraction of interval arithmetic's cost.
    pub(super) fn plane_box(&self, o: [f32; 4], s: Interval, t: Interval) -> Box4 {
        let (n1, n2) = (self.u.n1, self.u.n2);
        std::array::from_fn(|i| {
            let (c, a, b) = (f64::from(o[i]), f64::from(n1[i]), f64::from(n2[i]));
            let ends = |x: Interval, n: f64| {
                let (p, q) = (x.lo() * n, x.hi() * n);
                (p.min(q), p.max(q))
            };
            let ((sl, sh), (tl, th)) = (ends(s, a), ends(t, b));
            let (lo, hi) = (c + sl + tl, c + sh + th);
            let most = c.abs() + sl.abs().max(sh.abs()) + tl.abs().max(th.abs());
            let e = most * (8.0 * f64::EPSILON / 2.0) + 1e-300;
            if lo.is_finite() && hi.is_finite() && e.is_finite() {
                Interval::new(lo - e, hi + e)
            } else {
                Interval::point(c)
                    .add(s.mul(Interval::point(a)))
                    .add(t.mul(Interval::point(b)))
            }
        })
    }
}

/// The range a takes where a·n_i + b·m_i (b in `other`) lies in `ranges[i]` for each i,
/// intersected with `range` (the shader's `narrow`).
fn narrow(
    range: (f64, f64),
    n: &[f64; 4],
    m: &[f64; 4],
    other: (f64, f64),
    ranges: &[(f64, f64); 4],
) -> (f64, f64) {
    let mut r = range;
    for i in 0..4 {
        if n[i].abs() <= 1e-3 {
            continue;
        }
        let (lo, hi) = ranges[i];
        let q_lo = lo - (m[i] * other.0).max(m[i] * other.1);
        let q_hi = hi - (m[i] * other.0).min(m[i] * other.1);
        let (a, b) = (q_lo / n[i], q_hi / n[i]);
        r = (r.0.max(a.min(b)), r.1.min(a.max(b)));
    }
    r
}

/// The frame's domain (its f32 bounds) in f64.
pub(super) fn domain_of(u: &Uniforms) -> Box4 {
    std::array::from_fn(|i| Interval::new(f64::from(u.domain_lo[i]), f64::from(u.domain_hi[i])))
}

/// Whether box `x` lies within box `b`.
pub(super) fn inside(x: &Box4, b: &Box4) -> bool {
    (0..4).all(|i| x[i].lo() >= b[i].lo() && x[i].hi() <= b[i].hi())
}

/// An enclosure of x · n over the intervals x.
pub(super) fn dot(x: &[Interval], n: [f32; 4]) -> Interval {
    (0..4).fold(Interval::ZERO, |acc, i| {
        acc.add(x[i].mul(Interval::point(f64::from(n[i]))))
    })
}

/// The part of box `x` within box `b`, if any.
pub(super) fn within(x: Box4, b: &Box4) -> Option<Box4> {
    let mut out = x;
    for i in 0..4 {
        out[i] = x[i].intersect(b[i].lo(), b[i].hi());
        if out[i].is_empty() {
            return None;
        }
    }
    Some(out)
}
