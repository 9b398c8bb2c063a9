//! What a slab or a slice asks of the tile lists. Only the boxes that meet the section are
//! binned: a slice's line lies in the hyperplane at its offset along n2, a slab's rays in
//! the band about its centre, so no other box can give a pixel a hit (the shader would clip
//! them away one by one). And a slice's boxes are ordered along its ray: its pixels march
//! one line along n1 from `Camera::slice_start` behind the plane's origin, so a box's least
//! distance along it is the same for every pixel (the origins differ along v1 and v2 only),
//! and a pixel stops at the first box beyond the K hits it keeps, as a projection's pixels
//! do by |q| − r.

use crate::render::view::{Camera, Section};
use crate::tree::Hierarchy;

/// Slack for the shader's f32 rounding of centres, directions and the ray's origin:
/// relative to the sizes compared, far beyond f32's 6e-8.
const SLACK: f64 = 1e-5;

pub(super) struct SectionTest {
    section: Section,
    start: f64,
    /// Per level, a box's half extent along n1 and along n2 (its support), padded.
    support: Vec<[f64; 2]>,
}

impl SectionTest {
    pub(super) fn new(hierarchy: &Hierarchy, camera: &Camera) -> Self {
        let along = |half: &[f32; 4], v: &[f64; 4]| -> f64 {
            let s: f64 = (0..4).map(|i| f64::from(half[i]) * v[i].abs()).sum();
            s * (1.0 + SLACK)
        };
        Self {
            section: camera.section,
            start: camera.slice_start,
            support: hierarchy
                .levels
                .iter()
                .map(|l| [along(&l.half, &camera.n1), along(&l.half, &camera.n2)])
                .collect(),
        }
    }

    /// The key a box at `level` sorts by, its centre at (q1, q2) along n1 and n2 from the
    /// camera's centre and `plane_key` its |q| − r: None where it cannot meet the section;
    /// `plane_key` for a whole plane or a slab; for a slice, a lower bound on where the
    /// slice's ray enters it (the shader skips the box, and the rest of the list, once it
    /// keeps K hits nearer than that).
    pub(super) fn key(&self, level: usize, [q1, q2]: [f64; 2], plane_key: f32) -> Option<f32> {
        let [s1, s2] = self.support[level];
        let meets = |lo: f64, hi: f64| {
            let slack = SLACK * (q2.abs() + s2 + lo.abs().max(hi.abs()));
            q2 - s2 <= hi + slack && q2 + s2 >= lo - slack
        };
        match self.section {
            Section::Plane => Some(plane_key),
            Section::Slab { center, half } => {
                meets(center - half, center + half).then_some(plane_key)
            }
            Section::Slice { offset } => meets(offset, offset).then(|| {
                let entry = self.start + q1 - s1;
                let slack = SLACK * (self.start + q1.abs() + s1);
                // Rounded down to f32: a bound from below, as the plane's |q| − r.
                let key = (entry - slack) as f32;
                if f64::from(key) > entry - slack {
                    key.next_down()
                } else {
                    key
                }
            }),
        }
    }
}
