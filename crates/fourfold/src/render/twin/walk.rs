//! The boxes of the hierarchy a pixel's rays march, or its certified search covers: a walk
//! of the hierarchy as the shader's MODE 2 walks it. A tile of pixels first walks it once
//! with tests widened to hold every pixel of the tile, keeping the nodes it visits; each
//! pixel then walks that short list with its own tests, which gives the boxes, in order,
//! that its walk of the whole hierarchy gives (a node no pixel of the tile can pass is left
//! out with its subtree, and a pixel would have skipped it).

use crate::render::view::{Uniforms, march_steps};
use crate::tree::{Curvature, Hierarchy};

use super::march::Along;
use super::pixel::Marched;
use super::section::Band;
use super::shading::{V4, add, dot, sub};

/// A node the tile's walk kept, the index in the list past its subtree, and for a marched
/// box of a slice the range of the tile's one-signed stretches in it and its bounds along
/// the slice's rays (see `frame`).
#[derive(Debug, Clone, Copy)]
pub(super) struct Kept {
    node: u32,
    skip: u32,
    pub(super) one_signed: (u32, u32),
    pub(super) along: Option<Along>,
}

impl Kept {
    pub(super) fn node(&self) -> usize {
        self.node as usize
    }
}

/// A square of pixels around `centre` (a pixel origin, in f64, as each pixel's is made),
/// whose origins lie within `radius` of it along the picture's plane (v1, v2), give or take
/// `rounding` (a bound far beyond f32's rounding of the terms an origin is the sum of).
#[derive(Debug, Clone, Copy)]
pub(super) struct Tile {
    pub(super) centre: [f64; 4],
    pub(super) radius: f64,
    pub(super) rounding: f64,
}

/// The nodes of `h` that a pixel of `tile` may visit, in the walk's order, into `kept`;
/// a node whose box `free` proves free of M (for every pixel of the tile) is left out with
/// its subtree, as one no pixel of the tile can pass.
pub(super) fn tile_nodes(
    h: &Hierarchy,
    u: &Uniforms,
    (tile, band): (Tile, &Option<Band>),
    mut free: impl FnMut(V4, V4) -> bool,
    kept: &mut Vec<Kept>,
) {
    kept.clear();
    let mut open = Open::default();
    let mut i = 0usize;
    while i < h.nodes.len() {
        open.close_to(i, kept);
        let node = &h.nodes[i];
        let level = node.level() as usize;
        let half = u.levels[level].half;
        if !tile_may_visit(u, tile, node.center, level, band)
            || free(sub(node.center, half), add(node.center, half))
        {
            i = node.skip as usize;
            continue;
        }
        kept.push(Kept {
            node: i as u32,
            skip: 0,
            one_signed: (0, 0),
            along: None,
        });
        open.push(kept, node.skip as usize);
        // (A marched box is walked whole: its subtree is not.)
        i = if node.is_marched() {
            node.skip as usize
        } else {
            i + 1
        };
    }
    open.close_to(usize::MAX, kept);
}

/// The entries of a walk's list whose subtree is still being walked, and the index (in
/// what is walked) where each ends: an entry's `skip` is the list's length once the walk
/// reaches that end.
#[derive(Default)]
struct Open(Vec<(usize, usize)>);

impl Open {
    /// The list's last entry, whose subtree ends at `end`.
    fn push(&mut self, kept: &[Kept], end: usize) {
        self.0.push((kept.len() - 1, end));
    }

    /// Closes the entries whose subtree ends at `at` or before.
    fn close_to(&mut self, at: usize, kept: &mut [Kept]) {
        while let Some(&(entry, end)) = self.0.last()
            && end <= at
        {
            kept[entry].skip = kept.len() as u32;
            self.0.pop();
        }
    }
}

/// The entries of a tile's walk `kept` that a part of the tile may still visit, in order,
/// into `out`: an entry whose box `free` proves free of M for that part is left out with
/// its subtree, as [`tile_nodes`] leaves one out for the whole tile.
pub(super) fn narrow_kept(
    h: &Hierarchy,
    u: &Uniforms,
    kept: &[Kept],
    mut free: impl FnMut(V4, V4) -> bool,
    out: &mut Vec<Kept>,
) {
    out.clear();
    let mut open = Open::default();
    let mut e = 0usize;
    while e < kept.len() {
        open.close_to(e, out);
        let k = kept[e];
        let node = &h.nodes[k.node()];
        let half = u.levels[node.level() as usize].half;
        if free(sub(node.center, half), add(node.center, half)) {
            e = k.skip as usize;
            continue;
        }
        out.push(k);
        open.push(out, k.skip as usize);
        e += 1;
    }
    open.close_to(usize::MAX, out);
}

/// Whether some pixel of `tile` may pass a node's tests (see [`pixel_skips`]): each in f64
/// from the tile's centre, widened by the tile's radius and far beyond the f32 rounding of
/// the pixels' origins and of the picture's directions.
fn tile_may_visit(u: &Uniforms, tile: Tile, center: V4, level: usize, band: &Option<Band>) -> bool {
    let rel: [f64; 4] = std::array::from_fn(|k| f64::from(center[k]) - tile.centre[k]);
    let along = |n: V4| -> f64 { (0..4).map(|k| rel[k] * f64::from(n[k])).sum() };
    let (a, b) = (along(u.v1), along(u.v2));
    let radius = f64::from(u.levels[level].radius);
    let scale: f64 = (0..4)
        .map(|k| f64::from(center[k]).abs() + tile.centre[k].abs())
        .sum();
    let slack =
        1e-4 * (a.abs() + b.abs() + radius + tile.radius) + 1e-5 * scale + tile.rounding + 1e-30;
    if (a * a + b * b).sqrt() > radius + tile.radius + slack {
        return false;
    }
    band.as_ref().is_none_or(|band| {
        // The pixels' origins differ from the centre along v1 and v2 only, which n1 and n2
        // are orthogonal to but for rounding.
        let tilt = |n: V4| f64::from(dot(u.v1, n).abs() + dot(u.v2, n).abs());
        let margin = tile.radius * (tilt(u.n1) + tilt(u.n2) + 1e-3) + 1e-5 * scale + tile.rounding;
        band.meets_within(rel, level, margin)
    })
}

/// Whether pixel origin `o`'s walk skips a node centred at `center` at `level`: its sphere
/// misses the pixel's observer plane, or with a `band` (a slice's or slab's) its range
/// along n2 cannot meet the section (the shader's tile lists' tests).
fn pixel_skips(u: &Uniforms, o: V4, center: V4, level: usize, band: &Option<Band>) -> bool {
    let rel = sub(center, o);
    let (a, b) = (dot(rel, u.v1), dot(rel, u.v2));
    let radius = u.levels[level].radius;
    a * a + b * b > radius * radius || band.as_ref().is_some_and(|b| !b.meets(rel, level))
}

/// The boxes pixel `o`'s rays march (or, for a certifying hierarchy, its certified search
/// covers), into `boxes`, walking the nodes its tile kept: the hierarchy's marched boxes
/// that its walk visits, or the domain for brute force.
pub(super) fn boxes_of(
    h: &Hierarchy,
    u: &Uniforms,
    o: V4,
    (band, kept): (&Option<Band>, &[Kept]),
    boxes: &mut Vec<Marched>,
) {
    boxes.clear();
    if u.brute_force() {
        boxes.push(Marched {
            lo: u.domain_lo,
            hi: u.domain_hi,
            steps: u.counts.brute_steps,
            slope: [f32::INFINITY; 4],
            curvature: Curvature::NONE,
            node: None,
            one_signed: (0, 0),
            along: None,
        });
        return;
    }
    let mut e = 0usize;
    while e < kept.len() {
        let Kept {
            node: i,
            skip,
            one_signed,
            along,
        } = kept[e];
        let i = i as usize;
        let node = &h.nodes[i];
        let level = node.level() as usize;
        if pixel_skips(u, o, node.center, level, band) {
            e = skip as usize;
            continue;
        }
        // As the shader's `visit`: the boxes of the cut are marched whole.
        if node.is_marched() {
            let half = u.levels[level].half;
            boxes.push(Marched {
                lo: sub(node.center, half),
                hi: add(node.center, half),
                steps: steps_of(h, u, i),
                slope: h.slope(i),
                curvature: h.curvature(i),
                node: Some(i),
                one_signed,
                along,
            });
            e = skip as usize;
            continue;
        }
        e += 1;
    }
}

/// The steps a marched box `i` of `h` is marched in: a leaf's m, a coarser box's as many as
/// its leaves would get (the shader's `visit`).
pub(super) fn steps_of(h: &Hierarchy, u: &Uniforms, i: usize) -> u32 {
    let node = &h.nodes[i];
    if node.is_leaf() {
        u.control.steps
    } else {
        march_steps(u.control.steps, u.march.finest.saturating_sub(node.level()))
    }
}
