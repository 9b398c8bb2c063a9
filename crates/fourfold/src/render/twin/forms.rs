//! The second-order forms' arithmetic over a certified pixel's cell (docs/method.md §5.9,
//! step 3), as the shader's: Taylor's second-order term and the least value of a bowl.

use crate::eval::Interval;

/// Half the second-order term of Taylor's form over a cell, dᵀHd / 2 for d = s·n1 + t·n2
/// (s in `ds`, t in `dt`), H as the box's `form` bounds it (as the shader's `half_quad`).
pub(super) fn half_second_order(
    [al, ah, bl, bh, cl, ch]: [f64; 6],
    ds: Interval,
    dt: Interval,
) -> Interval {
    Interval::new(al, ah)
        .mul(ds.square())
        .add(Interval::new(bl, bh).mul(ds.mul(dt)))
        .add(Interval::new(cl, ch).mul(dt.square()))
        .mul(Interval::point(0.5))
}

/// Whether a + g1·s + g2·t + (A·s² + B·st + C·t²)/2 > 0 for every (s, t) and every
/// A ≥ `al`, C ≥ `cl`, B in `b` (the shader's `bowl_above_zero`): with q = B's middle / 2
/// and w half B's width, the quadratic is at least (al − w)s² + 2q·st + (cl − w)t²; where
/// that is positive definite (P), the least value of the whole is a − gᵀP⁻¹g / 2 =
/// a − num / (2 det), num = r·g1² − 2q·g1·g2 + p·g2², det = pr − q².
pub(super) fn bowl_above_zero(
    a: Interval,
    g1: Interval,
    g2: Interval,
    al: f64,
    b: Interval,
    cl: f64,
) -> bool {
    let q = 0.25 * (b.lo() + b.hi());
    let w = b
        .mul(Interval::point(0.5))
        .sub(Interval::point(q))
        .magnitude();
    let p = Interval::point(al).sub(Interval::point(w)).lo();
    let r = Interval::point(cl).sub(Interval::point(w)).lo();
    let (p, qi, r) = (Interval::point(p), Interval::point(q), Interval::point(r));
    let det = p.mul(r).sub(qi.square());
    if a.is_empty() || !(a.lo() > 0.0 && p.lo() > 0.0 && r.lo() > 0.0 && det.lo() > 0.0) {
        return false;
    }
    let num = r
        .mul(g1.square())
        .sub(Interval::point(2.0 * q).mul(g1.mul(g2)))
        .add(p.mul(g2.square()));
    // (As the shader: a − num / (2 det) > 0 as 2·a·det > num.)
    2.0 * a.mul(det).lo() > num.hi()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// F = 0.01 + 0.1·s + s² + t² (H = 2I) has its least value 0.0075 at s = −0.05: the
    /// bowl proves F > 0 everywhere; with F(c) = 0.002 the least value is −0.0005 and it
    /// must not. A cross term B as wide as A and C leaves no definite bound: no proof.
    #[test]
    fn a_bowl_proves_what_its_least_value_clears() {
        let point = Interval::point;
        let (g1, g2) = (Interval::new(0.0999, 0.1001), point(0.0));
        assert!(bowl_above_zero(point(0.01), g1, g2, 2.0, point(0.0), 2.0));
        assert!(!bowl_above_zero(point(0.002), g1, g2, 2.0, point(0.0), 2.0));
        assert!(!bowl_above_zero(
            point(0.01),
            g1,
            g2,
            2.0,
            Interval::new(-4.0, 4.0),
            2.0
        ));
        // A saddle's (A < 0) or a value of the wrong sign: no proof.
        assert!(!bowl_above_zero(point(0.01), g1, g2, -2.0, point(0.0), 2.0));
        assert!(!bowl_above_zero(point(-0.01), g1, g2, 2.0, point(0.0), 2.0));
        // The least value of 0.01 + 0.1 s + s² + s t + t² is 0.01 − 0.01/3 > 0.
        assert!(bowl_above_zero(point(0.01), g1, g2, 2.0, point(2.0), 2.0));
        assert!(!bowl_above_zero(point(0.003), g1, g2, 2.0, point(2.0), 2.0));
    }
}
