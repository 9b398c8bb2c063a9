//! The part of the domain a one-off picture looks at, when that is less than all of it: a
//! slice's hyperplane or a slab's band across the direction n2. A tree built within it keeps
//! only the boxes that meet it: M ∩ hyperplane is a surface, so at level L it meets about
//! 4^L boxes where M meets 8^L.

use crate::eval::Box4;

/// The points p of R⁴ with `lo` ≤ (p − origin)·normal ≤ `hi`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Region {
    pub normal: [f64; 4],
    pub origin: [f64; 4],
    pub lo: f64,
    pub hi: f64,
}

/// How far past the region a box may lie and still be kept, as a share of the reach given
/// to [`Region::band`] (the domain's half-diagonal plus its centre's largest coordinate): a
/// ray's points are worked out in f32 on the GPU (and rounded in the twin), so they stray
/// from the exact hyperplane by a few ulps of their coordinates; a box they may reach must
/// be in the tree, or a pixel would prove nothing there.
pub const REGION_MARGIN: f64 = 1e-4;

impl Region {
    /// The band within `half` of `offset` along `normal` from `origin`, widened by
    /// [`REGION_MARGIN`] of `reach`.
    pub fn band(normal: [f64; 4], origin: [f64; 4], offset: f64, half: f64, reach: f64) -> Self {
        let margin = REGION_MARGIN * reach;
        Self {
            normal,
            origin,
            lo: offset - half - margin,
            hi: offset + half + margin,
        }
    }

    /// Whether `bx` may meet the region: the range of (p − origin)·normal over the box, in
    /// f64 rounded to nearest and then widened by far more than its roundings (a few units
    /// of 2^-53 of its terms), so a box that meets it is never left out. (Outward rounding
    /// at each step cost a sixth of a one-off slice's tree.)
    pub fn meets(&self, bx: &Box4) -> bool {
        if bx.iter().any(|x| x.is_empty()) {
            return false;
        }
        let (mut lo, mut hi, mut size) = (0.0f64, 0.0f64, 0.0f64);
        for k in 0..4 {
            let n = self.normal[k];
            let a = (bx[k].lo() - self.origin[k]) * n;
            let b = (bx[k].hi() - self.origin[k]) * n;
            lo += a.min(b);
            hi += a.max(b);
            size += a.abs().max(b.abs());
        }
        if !(lo.is_finite() && hi.is_finite()) {
            // (An unbounded box, or a normal's 0 times its infinite side: kept.)
            return true;
        }
        let slack = 1e-12 * size + 1e-300;
        hi + slack >= self.lo && lo - slack <= self.hi
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interval::Interval;

    fn cube(lo: f64, hi: f64) -> Box4 {
        [Interval::new(lo, hi); 4]
    }

    #[test]
    fn a_box_meets_a_hyperplane_it_straddles_or_touches_and_no_other() {
        let w = Region::band([0.0, 0.0, 0.0, 1.0], [0.0; 4], 0.5, 0.0, 0.0);
        assert!(w.meets(&cube(0.0, 1.0)));
        assert!(w.meets(&cube(0.5, 1.0)));
        assert!(w.meets(&cube(0.0, 0.5)));
        assert!(!w.meets(&cube(0.0, 0.49)));
        assert!(!w.meets(&cube(0.51, 1.0)));
        // A turned normal: x + w = 1 (over √2) passes the box [0, 0.5]⁴ by its far corner.
        let s = 0.5f64.sqrt();
        let turned = Region::band([s, 0.0, 0.0, s], [0.0; 4], s, 0.0, 0.0);
        assert!(turned.meets(&cube(0.0, 0.5)));
        assert!(!turned.meets(&cube(0.0, 0.49)));
        // The margin keeps a box just past the hyperplane.
        let widened = Region::band([0.0, 0.0, 0.0, 1.0], [0.0; 4], 0.5, 0.0, 100.0);
        assert!(widened.meets(&cube(0.0, 0.495)));
    }

    proptest::proptest! {
        /// No box that an outward-rounded interval enclosure says may meet the region is
        /// left out, whatever the box, the normal and the band.
        #[test]
        fn a_box_the_interval_enclosure_keeps_is_kept(
            lo in proptest::array::uniform4(-10.0f64..10.0),
            size in proptest::array::uniform4(0.0f64..5.0),
            normal in proptest::array::uniform4(-1.0f64..1.0),
            origin in proptest::array::uniform4(-3.0f64..3.0),
            (offset, half) in (-5.0f64..5.0, 0.0f64..0.01),
        ) {
            let bx: Box4 = std::array::from_fn(|k| Interval::new(lo[k], lo[k] + size[k]));
            let region = Region::band(normal, origin, offset, half, 0.0);
            let along = (0..4).fold(Interval::point(0.0), |sum, k| {
                let from_origin = bx[k].sub(Interval::point(origin[k]));
                sum.add(from_origin.mul(Interval::point(normal[k])))
            });
            let enclosed = along.hi() >= region.lo && along.lo() <= region.hi;
            proptest::prop_assert!(!enclosed || region.meets(&bx));
        }
    }

    #[test]
    fn a_band_keeps_what_lies_within_it() {
        let slab = Region::band([1.0, 0.0, 0.0, 0.0], [1.0; 4], 0.0, 0.25, 0.0);
        assert!(slab.meets(&cube(1.1, 1.2)));
        assert!(slab.meets(&cube(0.5, 0.75)));
        assert!(!slab.meets(&cube(0.5, 0.7)));
        assert!(!slab.meets(&cube(1.3, 2.0)));
    }
}
