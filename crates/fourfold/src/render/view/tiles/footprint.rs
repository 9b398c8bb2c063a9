//! Where a marched box reaches the screen: its cover boxes' footprints (centre and level),
//! runs of them under a coarser box, each level's projection on the screen in pixel units,
//! and the box records the shader reads.

use crate::gpu_layout::{BoxRecord, PlaneCurvature};
use crate::render::view::Camera;
use crate::tree::Hierarchy;

/// Where a marched box reaches the screen: the centre of the projection of one of its cover
/// boxes in pixel units (pixel (px, py) has its centre at (px + 0.5, py + 0.5)) and that
/// box's level, and the marched box's place in the view's order (its record's index).
#[derive(Debug, Clone, Copy)]
pub(super) struct Footprint {
    pub(super) slot: u32,
    pub(super) cx: f32,
    pub(super) cy: f32,
    pub(super) level: u32,
}

impl Footprint {
    pub(super) fn level(&self) -> usize {
        self.level as usize
    }
}

/// A run of footprints of one marched box (`slot`): the children of one box of the next
/// coarser cover, or a single footprint where there is none. The coarser box's footprint
/// (`parent`, None where off screen or no coarser cover) holds theirs: where every tile it
/// reaches is already marked for the box, the run adds nothing and is skipped.
#[derive(Debug, Clone, Copy)]
pub(super) struct Run {
    pub(super) slot: u32,
    pub(super) parent: Option<Footprint>,
    /// The run's footprints, `start..end` in the view's footprints.
    pub(super) feet: (u32, u32),
}

impl Run {
    /// The footprint that reaches every band the run's footprints reach (without a parent
    /// a run holds one footprint).
    pub(super) fn bound<'a>(&'a self, feet: &'a [Footprint]) -> &'a Footprint {
        self.parent.as_ref().unwrap_or(&feet[self.feet.0 as usize])
    }
}

/// A level's sizes in pixel units, padded a little for the shader's f32 rounding: the
/// box's half widths along x and y (its support along v1 and v2) and its projection.
#[derive(Debug, Clone, Copy)]
pub(super) struct Reach {
    pub(super) hx: f32,
    pub(super) hy: f32,
    pub(super) shape: Projection,
}

/// The projection of a level's box on the screen, about its centre, in pixel units (y
/// down): the pixels whose observer plane meets the box are those whose centres lie in
/// it. A 4D box with half extents h projects (along n1, n2) to the zonotope Σ [−1, 1]·g_i,
/// g_i = h_i (v1_i, −v2_i) / s: a centrally symmetric polygon of up to 8 vertices, smaller
/// than the disk ∩ rectangle that the sphere and the supports bound, so fewer tiles get a
/// box. Padded by `slack` pixels all round (the shader's f32 rounding).
#[derive(Debug, Clone, Copy)]
pub(super) struct Projection {
    pub(super) vertices: [[f32; 2]; 8],
    pub(super) count: usize,
    pub(super) slack: f32,
}

impl Projection {
    /// The zonotope of the generators `g` (pixel units), scaled by `scale` and padded by
    /// `slack`.
    pub(super) fn new(g: [[f64; 2]; 4], scale: f64, slack: f32) -> Self {
        // Each generator pointing into the upper half plane, by angle.
        let mut g: Vec<[f64; 2]> = g
            .into_iter()
            .filter(|v| v[0].abs() + v[1].abs() > 0.0)
            .map(|v| {
                if v[1] < 0.0 || (v[1] == 0.0 && v[0] < 0.0) {
                    [-v[0], -v[1]]
                } else {
                    v
                }
            })
            .collect();
        g.sort_by(|a, b| a[1].atan2(a[0]).total_cmp(&b[1].atan2(b[0])));
        let mut p = [
            -g.iter().map(|v| v[0]).sum::<f64>(),
            -g.iter().map(|v| v[1]).sum::<f64>(),
        ];
        let mut vertices = [[0.0f32; 2]; 8];
        let mut count = 0;
        for sign in [2.0, -2.0] {
            for v in &g {
                vertices[count] = [(p[0] * scale) as f32, (p[1] * scale) as f32];
                count += 1;
                p = [p[0] + sign * v[0], p[1] + sign * v[1]];
            }
        }
        if count == 0 {
            count = 1; // a point (no extent)
        }
        Self {
            vertices,
            count,
            slack,
        }
    }

    /// The x range (about the centre) of the footprint's points with y in [y0, y1], or None.
    pub(super) fn x_range(&self, y0: f32, y1: f32) -> Option<(f32, f32)> {
        let (y0, y1) = (y0 - self.slack, y1 + self.slack);
        let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
        let v = &self.vertices[..self.count];
        for (k, p) in v.iter().enumerate() {
            let q = v[(k + 1) % v.len()];
            if (y0..=y1).contains(&p[1]) {
                (lo, hi) = (lo.min(p[0]), hi.max(p[0]));
            }
            for y in [y0, y1] {
                if (p[1] < y) != (q[1] < y) {
                    let x = p[0] + (y - p[1]) * (q[0] - p[0]) / (q[1] - p[1]);
                    (lo, hi) = (lo.min(x), hi.max(x));
                }
            }
        }
        (lo <= hi).then_some((lo - self.slack, hi + self.slack))
    }
}

/// Maps an f32 to a u32 with the same order (for sorting by key as plain integers).
pub(super) fn order_key(x: f32) -> u32 {
    let bits = x.to_bits();
    if bits >> 31 == 1 {
        !bits
    } else {
        bits | 1 << 31
    }
}

/// Inclusive range of pixel indices whose centres (i + 0.5) lie within `half` of `c`, in
/// `0..pixels`; None if empty.
pub(super) fn pixel_range(c: f32, half: f32, pixels: u32) -> Option<(u32, u32)> {
    let p0 = (c - half - 0.5).ceil().max(0.0);
    let p1 = (c + half - 0.5).floor().min(pixels as f32 - 1.0);
    (p0 <= p1).then_some((p0 as u32, p1 as u32))
}

/// The tile rows (side `t`) whose pixel rows the footprint may reach; None if off screen.
pub(super) fn tile_rows(f: &Footprint, r: &Reach, t: u32, h: u32) -> Option<(u32, u32)> {
    pixel_range(f.cy, r.hy, h).map(|(y0, y1)| (y0 / t, y1 / t))
}

/// The tiles (side `t`) of tile row `ty` that hold a pixel the footprint reaches (its
/// centre in the box's projection, `Projection`); None if none.
pub(super) fn row_span(f: &Footprint, r: &Reach, t: u32, ty: u32, w: u32) -> Option<(u32, u32)> {
    let lo = (ty * t) as f32 + 0.5 - f.cy;
    let hi = lo + (t - 1) as f32;
    let (a, b) = r.shape.x_range(lo, hi)?;
    let p0 = (f.cx + a - 0.5).ceil().max(0.0);
    let p1 = (f.cx + b - 0.5).floor().min(w as f32 - 1.0);
    (p0 <= p1).then_some((p0 as u32 / t, p1 as u32 / t))
}

/// The record of node `i`, given its centre minus the camera's centre projected on v1, v2,
/// n1 and n2 (see [`BoxRecord`]).
pub(super) fn record(
    hierarchy: &Hierarchy,
    i: u32,
    [a, b, q1, q2]: [f64; 4],
    camera: &Camera,
) -> BoxRecord {
    let node = &hierarchy.nodes[i as usize];
    let level_radius = f64::from(hierarchy.levels[node.level() as usize].radius);
    let dist = q1.hypot(q2);
    // As the shader's radius (a little larger than the level's, for its rounding).
    let radius = level_radius * 1.000_01;
    let delta = if dist > radius {
        (radius / dist).asin() + 1e-3
    } else {
        -1.0
    };
    let [al, ah, bl, bh, cl, ch] = hierarchy
        .curvature(i as usize)
        .in_plane(camera.n1, camera.n2);
    BoxRecord {
        view: [a as f32, b as f32, (dist - level_radius) as f32],
        level: node.meta,
        angles: [q2.atan2(q1) as f32, delta as f32],
        node: i,
        unused: 0,
        center: node.center,
        slope: hierarchy.slope(i as usize),
        form: PlaneCurvature {
            ab: [al, ah, bl, bh],
            c: [cl, ch],
            unused: [0.0; 2],
        },
    }
}
