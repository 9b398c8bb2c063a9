//! A slice's or slab's band of n2 coordinates, for the twin's walk of the hierarchy: the
//! boxes that cannot meet it are left out, as the shader's tile lists leave them out
//! (`render/view/tiles/section.rs`, whose slack is f32's alone).

use crate::render::view::{FLAG_SLAB, FLAG_SLICE, LEVEL_SLOTS, Uniforms};

use super::shading::V4;

/// The n2 coordinates a slice or slab keeps, from a pixel's origin, and each level's half
/// extent along n1 and n2 (a box's support), worked out once per frame.
#[derive(Debug, Clone, Copy)]
pub(super) struct Band {
    lo: f64,
    hi: f64,
    n1: V4,
    n2: V4,
    support: [[f64; 2]; LEVEL_SLOTS],
}

impl Band {
    /// The section's band from the pixel's plane origin or, for a slice, from its line's
    /// start (`line`, which lies in the slice's hyperplane); None for a whole plane.
    pub(super) fn of(u: &Uniforms, line: bool) -> Option<Self> {
        let (offset, half) = (
            f64::from(u.root.section_offset),
            f64::from(u.root.section_half),
        );
        let (lo, hi) = if u.control.flags & FLAG_SLICE != 0 {
            let at = if line { 0.0 } else { offset };
            (at, at)
        } else if u.control.flags & FLAG_SLAB != 0 {
            (offset - half, offset + half)
        } else {
            return None;
        };
        let along = |half: V4, n: V4| -> f64 {
            (0..4)
                .map(|i| f64::from(half[i]) * f64::from(n[i]).abs())
                .sum()
        };
        let support = u.levels.map(|l| [along(l.half, u.n1), along(l.half, u.n2)]);
        Some(Self {
            lo,
            hi,
            n1: u.n1,
            n2: u.n2,
            support,
        })
    }

    /// Whether a box at `level`, its centre at `rel` from the origin, may meet the band:
    /// its range along n2, widened far beyond the f32 rounding of the origin and of n1, n2
    /// and beyond the certified search's own widening of it (1e-5 of the ranges along n1
    /// and n2), so that no box is left out that a ray or the search could use.
    pub(super) fn meets(&self, rel: V4, level: usize) -> bool {
        self.meets_within(rel.map(f64::from), level, 0.0)
    }

    /// As [`Self::meets`], for any of the boxes whose centres lie within `margin` of `rel`
    /// along n1 and n2 (a tile's pixels' boxes, from the tile's centre).
    pub(super) fn meets_within(&self, rel: [f64; 4], level: usize, margin: f64) -> bool {
        let along = |n: V4| -> f64 { (0..4).map(|i| rel[i] * f64::from(n[i])).sum() };
        let [r1, r2] = self.support[level];
        let (q1, q2) = (along(self.n1), along(self.n2));
        let widest = q1.abs() + r1 + q2.abs() + r2 + self.lo.abs() + self.hi.abs() + 2.0 * margin;
        let slack = 1e-4 * widest + 1e-6 + margin;
        q2 - r2 <= self.hi + slack && q2 + r2 >= self.lo - slack
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use bytemuck::Zeroable;

    /// A slice's band keeps every box whose range along n2 reaches the slice, and leaves
    /// out those beyond it; from the slice's line (in its hyperplane) the band is 0.
    #[test]
    fn a_section_s_band_leaves_out_only_boxes_that_cannot_meet_it() {
        let mut u = Uniforms::zeroed();
        u.n1 = [0.6, 0.8, 0.0, 0.0];
        u.n2 = [0.0, 0.0, 0.6, 0.8];
        u.control.flags = FLAG_SLICE;
        u.root.section_offset = 0.5;
        // A level-2 box's range along n2 is its centre's ± 0.14 (0.1 · (0.6 + 0.8)).
        u.levels[2].half = [0.1; 4];
        let band = Band::of(&u, false).expect("a slice has a band");
        let at = |q2: f32| [0.0, 0.0, 0.6 * q2, 0.8 * q2];
        for q2 in [0.36, 0.5, 0.64] {
            assert!(band.meets(at(q2), 2), "{q2}");
        }
        for q2 in [0.3, 0.7, -0.5] {
            assert!(!band.meets(at(q2), 2), "{q2}");
        }
        let line = Band::of(&u, true).expect("a slice has a band");
        assert!(line.meets(at(0.1), 2) && !line.meets(at(0.2), 2));
        u.control.flags = 0;
        assert!(Band::of(&u, false).is_none());
    }
}
