//! Screen tiles: for each square block of pixels, the boxes the ray caster marches (the
//! hierarchy's cut: the nodes marked marched, see `Hierarchy::for_formula`) that may hold a
//! root for some pixel in it. Built on the CPU per view, so that each pixel tests only its
//! tile's boxes instead of walking the hierarchy: the walk's inner-node tests (16 children
//! per passing node) were most of a frame on a software GPU.
//!
//! A marched box goes into the tiles reached by the boxes it covers (`Hierarchy::cover`: its
//! descendants at a level at or below the march level; their ancestors for small images, see
//! [`COVER_PER_TILE`]), not by its own sphere. The tree keeps every box that may
//! hold M, so where a pixel's observer plane meets none of them the box holds no root for
//! that pixel, however large the box: a coarse box (the glome is marched as the root box)
//! costs only the pixels near M.
//!
//! A box's sphere (centre c, radius r) meets pixel p's observer plane iff the projection of c
//! on the (v1, v2) plane is within r of p's origin there; its box can only meet it if that
//! projection is also within the box's support along v1 and along v2. In pixel units that is
//! a disk of radius r / pixel_size around the projected centre, cut by a rectangle: a cover
//! box puts its marched box into every tile with a pixel centre in both (the same tests as
//! the shader's, padded for its f32 rounding), once. Layout, one `u32` buffer:
//! `[offset of tile 0, …, offset of tile T, entries…]`, offsets counted from the start of
//! the entries, each entry an index in the view's box records (see [`BoxRecord`]).
//!
//! Each tile's boxes are in order of their least possible distance from the pixel's origin in
//! the observer plane, |q| − r, where q is the projection of the centre on (n1, n2). That
//! projection is the same for every pixel (o moves only along v1 and v2), so one global order
//! serves all tiles, and a pixel stops at the first box that cannot hold a hit nearer than
//! the K it keeps: every later one is at least as far (nearest-first with early exit).

use rayon::prelude::*;

pub use crate::gpu_layout::BoxRecord;
use crate::gpu_layout::PlaneCurvature;
use crate::tree::{CoverBox, Hierarchy};

use super::camera::Camera;

/// Largest and smallest tile side in pixels. The pixels of a tile read one list in one
/// order, so a SIMD group of pixels (llvmpipe shades 4x4 blocks; a GPU, warps of 32 or 64)
/// visits the same boxes at the same time. 4-pixel tiles drew as fast as 1-pixel ones on
/// lavapipe (`cargo bench --bench frame`), with a binning 5–10x cheaper.
pub const MAX_TILE: u32 = 16;
pub const MIN_TILE: u32 = 4;

/// Most cover boxes (see `Hierarchy::cover`) per tile of the smallest side that a view
/// bins by: where there are more, their ancestors stand in for them.
pub const COVER_PER_TILE: usize = 4;

/// Height in pixels of the bands of [`TileLists::rects`].
pub const RECT_BAND: u32 = 32;

/// Words (tile offsets and box indices) the lists may hold: the tile side grows until they
/// fit (96 MiB).
pub const MAX_ENTRIES: usize = 24 << 20;

/// The per-tile box lists of one view, and the records of the boxes they index.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TileLists {
    /// Tile side in pixels, a power of two in MIN_TILE..=MAX_TILE: the smallest whose lists
    /// fit in MAX_ENTRIES (larger tiles hold more boxes per pixel but fewer in all).
    pub tile: u32,
    pub tiles_x: u32,
    pub tiles_y: u32,
    /// `tiles_x·tiles_y + 1` offsets, then the entries: indices in `boxes`.
    pub data: Vec<u32>,
    /// The boxes on screen, nearest first (by |q| − r).
    pub boxes: Vec<BoxRecord>,
}

/// Where a marched box reaches the screen: the centre of the projection of one of its cover
/// boxes in pixel units (pixel (px, py) has its centre at (px + 0.5, py + 0.5)) and that
/// box's level, and the marched box's place in the view's order (its record's index).
#[derive(Debug, Clone, Copy)]
struct Footprint {
    slot: u32,
    cx: f32,
    cy: f32,
    level: u32,
}

impl Footprint {
    fn level(&self) -> usize {
        self.level as usize
    }
}

/// A run of footprints of one marched box (`slot`): the children of one box of the next
/// coarser cover, or a single footprint where there is none. The coarser box's footprint
/// (`parent`, None where off screen or no coarser cover) holds theirs: where every tile it
/// reaches is already marked for the box, the run adds nothing and is skipped.
#[derive(Debug, Clone, Copy)]
struct Run {
    slot: u32,
    parent: Option<Footprint>,
    /// The run's footprints, `start..end` in the view's footprints.
    feet: (u32, u32),
}

impl Run {
    /// The footprint that reaches every band the run's footprints reach (without a parent
    /// a run holds one footprint).
    fn bound<'a>(&'a self, feet: &'a [Footprint]) -> &'a Footprint {
        self.parent.as_ref().unwrap_or(&feet[self.feet.0 as usize])
    }
}

/// A level's sizes in pixel units, padded a little for the shader's f32 rounding: the
/// box's half widths along x and y (its support along v1 and v2) and its projection.
#[derive(Debug, Clone, Copy)]
struct Reach {
    hx: f32,
    hy: f32,
    shape: Projection,
}

/// The projection of a level's box on the screen, about its centre, in pixel units (y
/// down): the pixels whose observer plane meets the box are those whose centres lie in
/// it. A 4D box with half extents h projects (along n1, n2) to the zonotope Σ [−1, 1]·g_i,
/// g_i = h_i (v1_i, −v2_i) / s: a centrally symmetric polygon of up to 8 vertices. It is
/// half the area of the disk ∩ rectangle that the sphere and the supports bound (what the
/// binning used before) at the chapter's fig. 3.9 view, and 1.3 to 1.4x smaller at the
/// other figures' views, so fewer tiles get a box. Padded by `slack` pixels all round (the
/// shader's f32 rounding).
#[derive(Debug, Clone, Copy)]
struct Projection {
    vertices: [[f32; 2]; 8],
    count: usize,
    slack: f32,
}

impl Projection {
    /// The zonotope of the generators `g` (pixel units), scaled by `scale` and padded by
    /// `slack`.
    fn new(g: [[f64; 2]; 4], scale: f64, slack: f32) -> Self {
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
    fn x_range(&self, y0: f32, y1: f32) -> Option<(f32, f32)> {
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
fn order_key(x: f32) -> u32 {
    let bits = x.to_bits();
    if bits >> 31 == 1 {
        !bits
    } else {
        bits | 1 << 31
    }
}

/// Inclusive range of pixel indices whose centres (i + 0.5) lie within `half` of `c`, in
/// `0..pixels`; None if empty.
fn pixel_range(c: f32, half: f32, pixels: u32) -> Option<(u32, u32)> {
    let p0 = (c - half - 0.5).ceil().max(0.0);
    let p1 = (c + half - 0.5).floor().min(pixels as f32 - 1.0);
    (p0 <= p1).then_some((p0 as u32, p1 as u32))
}

/// The tile rows (side `t`) whose pixel rows the footprint may reach; None if off screen.
fn tile_rows(f: &Footprint, r: &Reach, t: u32, h: u32) -> Option<(u32, u32)> {
    pixel_range(f.cy, r.hy, h).map(|(y0, y1)| (y0 / t, y1 / t))
}

/// The tiles (side `t`) of tile row `ty` that hold a pixel the footprint reaches (its
/// centre in the box's projection, `Projection`); None if none.
fn row_span(f: &Footprint, r: &Reach, t: u32, ty: u32, w: u32) -> Option<(u32, u32)> {
    let lo = (ty * t) as f32 + 0.5 - f.cy;
    let hi = lo + (t - 1) as f32;
    let (a, b) = r.shape.x_range(lo, hi)?;
    let p0 = (f.cx + a - 0.5).ceil().max(0.0);
    let p1 = (f.cx + b - 0.5).floor().min(w as f32 - 1.0);
    (p0 <= p1).then_some((p0 as u32 / t, p1 as u32 / t))
}

/// The record of node `i`, given its centre minus the camera's centre projected on v1, v2,
/// n1 and n2 (see [`BoxRecord`]).
fn record(hierarchy: &Hierarchy, i: u32, [a, b, q1, q2]: [f64; 4], camera: &Camera) -> BoxRecord {
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

/// The footprints of one view, by band of tile rows.
struct Bins<'a> {
    feet: &'a [Footprint],
    runs: &'a [Run],
    reach: &'a [Reach],
    /// `reach` a little wider, for the parents' test: a child box's sphere touches its
    /// parent's from inside, so rounding must not let a child reach further.
    parent_reach: &'a [Reach],
    /// Per band, the runs that reach it, in order.
    members: &'a [Vec<u32>],
    tile: u32,
    tiles_x: u32,
    tiles_y: u32,
    band_rows: u32,
    w: u32,
    h: u32,
}

impl Bins<'_> {
    /// The entries of `band`: (tile index within the band, box slot) once for every tile
    /// of the band that a footprint of the box reaches, boxes in order. A box's footprints are
    /// consecutive (sorted by box) and overlap a lot near M (a pixel there can be reached by
    /// hundreds of cover boxes), so they are first marked as bit ranges per tile row, one
    /// word operation per row instead of one per tile, and the union's tiles read off once.
    fn entries(&self, band: usize) -> Vec<(u32, u32)> {
        let mut entries = Vec::new();
        let r0 = band as u32 * self.band_rows;
        let r1 = (r0 + self.band_rows).min(self.tiles_y) - 1;
        let words = self.tiles_x.div_ceil(64) as usize;
        let mut bits = vec![0u64; (r1 - r0 + 1) as usize * words];
        let members = &self.members[band];
        let mut k = 0;
        while k < members.len() {
            let slot = self.runs[members[k] as usize].slot;
            // The rows and words this box marked.
            let (mut rows, mut cols) = ((usize::MAX, 0), (usize::MAX, 0));
            while let Some(run) = members.get(k).map(|&m| &self.runs[m as usize]) {
                if run.slot != slot {
                    break;
                }
                k += 1;
                if let Some(p) = &run.parent
                    && self.marked(&bits, words, p, r0, r1)
                {
                    continue;
                }
                for f in &self.feet[run.feet.0 as usize..run.feet.1 as usize] {
                    let r = &self.reach[f.level()];
                    let Some((ty0, ty1)) = tile_rows(f, r, self.tile, self.h) else {
                        continue;
                    };
                    for ty in ty0.max(r0)..=ty1.min(r1) {
                        if let Some((tx0, tx1)) = row_span(f, r, self.tile, ty, self.w) {
                            let row = (ty - r0) as usize;
                            let (w0, w1) = (tx0 as usize / 64, tx1 as usize / 64);
                            set_bits(
                                &mut bits[row * words..][w0..=w1],
                                tx0 % 64,
                                w1 - w0,
                                tx1 % 64,
                            );
                            rows = (rows.0.min(row), rows.1.max(row));
                            cols = (cols.0.min(w0), cols.1.max(w1));
                        }
                    }
                }
            }
            for row in rows.0..=rows.1 {
                for word in cols.0..=cols.1 {
                    let mut b = std::mem::take(&mut bits[row * words + word]);
                    while b != 0 {
                        let tx = word * 64 + b.trailing_zeros() as usize;
                        b &= b - 1;
                        entries.push(((row * self.tiles_x as usize + tx) as u32, slot));
                    }
                }
            }
        }
        entries
    }

    /// Whether every tile of the band's rows `r0..=r1` that the parent footprint `p`
    /// reaches (widened, see `parent_reach`) is marked in `bits`.
    fn marked(&self, bits: &[u64], words: usize, p: &Footprint, r0: u32, r1: u32) -> bool {
        let r = &self.parent_reach[p.level()];
        let Some((ty0, ty1)) = tile_rows(p, r, self.tile, self.h) else {
            return true;
        };
        (ty0.max(r0)..=ty1.min(r1)).all(|ty| {
            row_span(p, r, self.tile, ty, self.w).is_none_or(|(tx0, tx1)| {
                let (w0, w1) = (tx0 as usize / 64, tx1 as usize / 64);
                let row = &bits[(ty - r0) as usize * words..][w0..=w1];
                row.iter().enumerate().all(|(i, &word)| {
                    let mask = span_mask(i, tx0 % 64, w1 - w0, tx1 % 64);
                    word & mask == mask
                })
            })
        })
    }
}

/// Sets the bits from bit `lo` of `words[0]` to bit `hi` of `words[last]`.
fn set_bits(words: &mut [u64], lo: u32, last: usize, hi: u32) {
    for (i, word) in words.iter_mut().enumerate() {
        *word |= span_mask(i, lo, last, hi);
    }
}

/// Of the bits from bit `lo` of word 0 to bit `hi` of word `last`, those in word `i`.
fn span_mask(i: usize, lo: u32, last: usize, hi: u32) -> u64 {
    let from = if i == 0 { u64::MAX << lo } else { u64::MAX };
    let to = if i == last {
        u64::MAX >> (63 - hi)
    } else {
        u64::MAX
    };
    from & to
}

/// The view as the binning sees it: pixel units, and each level's reach on the screen.
struct Screen<'a> {
    camera: &'a Camera,
    w: u32,
    h: u32,
    /// Per level, the box's reach (see [`Reach`]).
    reach: Vec<Reach>,
    /// For the runs' parents (see `Bins::parent_reach`).
    parent_reach: Vec<Reach>,
}

impl<'a> Screen<'a> {
    fn new(hierarchy: &Hierarchy, camera: &'a Camera) -> Self {
        let s = camera.pixel_size;
        let (v1, v2) = (camera.v1, camera.v2);
        let pad = |x: f64| (x * (1.0 + 1e-4) + 2e-3) as f32;
        let reach: Vec<Reach> = hierarchy
            .levels
            .iter()
            .map(|info| {
                // As in Uniforms::new.
                let support = |v: &[f64; 4]| -> f64 {
                    (0..4).map(|i| f64::from(info.half[i]) * v[i].abs()).sum()
                };
                let g = std::array::from_fn(|i| {
                    let h = f64::from(info.half[i]) / s;
                    [h * v1[i], -h * v2[i]]
                });
                Reach {
                    hx: pad(support(&v1) / s),
                    hy: pad(support(&v2) / s),
                    shape: Projection::new(g, 1.0 + 1e-4, 2e-3),
                }
            })
            .collect();
        // Wider by far more than the rounding of f32 centres and their projections (~1e-5
        // pixels).
        let widen = |x: f32| x * 1.001 + 0.01;
        let parent_reach = reach
            .iter()
            .map(|r| Reach {
                hx: widen(r.hx),
                hy: widen(r.hy),
                shape: Projection {
                    vertices: r.shape.vertices.map(|[x, y]| [x * 1.001, y * 1.001]),
                    slack: widen(r.shape.slack),
                    ..r.shape
                },
            })
            .collect();
        Self {
            camera,
            w: camera.width.max(1),
            h: camera.height.max(1),
            reach,
            parent_reach,
        }
    }

    /// A centre's position in pixel units (inverting `Camera::origin`), and its offset from
    /// the camera's centre along v1, v2, n1 and n2.
    fn project(&self, center: [f32; 4]) -> (f32, f32, [f64; 4]) {
        let c = self.camera;
        let rel: [f64; 4] = std::array::from_fn(|k| f64::from(center[k]) - c.center[k]);
        let dot = |v: &[f64; 4]| -> f64 { (0..4).map(|k| rel[k] * v[k]).sum() };
        let (a, b) = (dot(&c.v1), dot(&c.v2));
        let cx = (a / c.pixel_size + 0.5 * f64::from(self.w)) as f32;
        let cy = (0.5 * f64::from(self.h) - b / c.pixel_size) as f32;
        (cx, cy, [a, b, dot(&c.n1), dot(&c.n2)])
    }

    /// The marched boxes on screen, nearest first (by |q| − r, then node), with their
    /// records; and each node's place in that order (`u32::MAX`: off screen).
    #[allow(clippy::type_complexity)]
    fn boxes_on_screen(&self, hierarchy: &Hierarchy) -> (Vec<(u32, u32, BoxRecord)>, Vec<u32>) {
        let mut on_screen: Vec<(u32, u32, BoxRecord)> = hierarchy
            .nodes
            .par_iter()
            .enumerate()
            .filter_map(|(i, node)| {
                let r = self
                    .reach
                    .get(node.level() as usize)
                    .filter(|_| hierarchy.marches(node))?;
                let (cx, cy, view) = self.project(node.center);
                pixel_range(cx, r.hx, self.w)?;
                pixel_range(cy, r.hy, self.h)?;
                let record = record(hierarchy, i as u32, view, self.camera);
                Some((order_key(record.view[2]), i as u32, record))
            })
            .collect();
        on_screen
            .par_sort_unstable_by_key(|&(key, node, _)| (u64::from(key) << 32) | u64::from(node));
        let mut rank = vec![u32::MAX; hierarchy.nodes.len()];
        for (k, &(_, node, _)) in on_screen.iter().enumerate() {
            rank[node as usize] = k as u32;
        }
        (on_screen, rank)
    }

    /// The marched boxes' footprints: those of the boxes they cover (see
    /// `Hierarchy::cover`), in the boxes' order (`rank`), in runs under the boxes of the next
    /// coarser cover (see `Run`), each box's runs together. Where the cover holds more than
    /// COVER_PER_TILE boxes per smallest tile, its boxes' ancestors stand in for them (the
    /// binning's cost grows with their number; a small image gains little from boxes much
    /// smaller than a tile).
    fn footprint_runs(&self, hierarchy: &Hierarchy, rank: &[u32]) -> (Vec<Footprint>, Vec<Run>) {
        let (w, h) = (self.w, self.h);
        let limit = COVER_PER_TILE * (w.div_ceil(MIN_TILE) * h.div_ceil(MIN_TILE)) as usize;
        let footprint = |c: &CoverBox| {
            let slot = *rank.get(c.node as usize).filter(|&&k| k != u32::MAX)?;
            let r = self.reach.get(c.level as usize)?;
            let (cx, cy, _) = self.project(c.center);
            pixel_range(cx, r.hx, w)?;
            pixel_range(cy, r.hy, h)?;
            Some(Footprint {
                slot,
                cx,
                cy,
                level: c.level,
            })
        };
        let level = hierarchy.cover_level_within(limit);
        let fine = level.map_or(&[][..], |k| hierarchy.cover[k].as_slice());
        let coarse = level.and_then(|k| hierarchy.cover.get(k + 1));
        let mut runs: Vec<(Option<Footprint>, Vec<Footprint>)> = match coarse {
            Some(coarse) => (0..coarse.len())
                .into_par_iter()
                .flat_map_iter(|j| {
                    let end = coarse
                        .get(j + 1)
                        .map_or(fine.len(), |c| c.first_child as usize);
                    let children = &fine[coarse[j].first_child as usize..end];
                    let feet: Vec<Footprint> = children.iter().filter_map(footprint).collect();
                    // A parent off screen (its children can be on it only by rounding):
                    // a run per child, each binned by its own footprint.
                    match footprint(&coarse[j]) {
                        Some(parent) if !feet.is_empty() => vec![(Some(parent), feet)],
                        _ => feet.into_iter().map(|f| (None, vec![f])).collect(),
                    }
                })
                .collect(),
            None => fine
                .par_iter()
                .filter_map(|c| Some((None, vec![footprint(c)?])))
                .collect(),
        };
        runs.par_sort_by_key(|(_, feet)| feet[0].slot);
        let mut feet = Vec::with_capacity(runs.iter().map(|(_, f)| f.len()).sum());
        let runs: Vec<Run> = runs
            .into_iter()
            .map(|(parent, run)| {
                let start = feet.len() as u32;
                feet.extend(run);
                Run {
                    slot: feet[start as usize].slot,
                    parent,
                    feet: (start, feet.len() as u32),
                }
            })
            .collect();
        (feet, runs)
    }

    /// The smallest tile side whose lists fit in `max_entries` words (estimated from the
    /// footprints' rectangles, for every side in one pass).
    fn tile_side(&self, feet: &[Footprint], max_entries: usize) -> u32 {
        const SIDES: usize = (MAX_TILE.ilog2() - MIN_TILE.ilog2() + 1) as usize;
        let (w, h) = (self.w, self.h);
        let estimates = feet
            .par_iter()
            .map(|f| {
                let r = &self.reach[f.level()];
                let mut n = [0usize; SIDES];
                if let (Some((x0, x1)), Some((y0, y1))) =
                    (pixel_range(f.cx, r.hx, w), pixel_range(f.cy, r.hy, h))
                {
                    for (i, n) in n.iter_mut().enumerate() {
                        let t = MIN_TILE << i;
                        *n = ((x1 / t - x0 / t + 1) * (y1 / t - y0 / t + 1)) as usize;
                    }
                }
                n
            })
            .reduce(|| [0; SIDES], |a, b| std::array::from_fn(|i| a[i] + b[i]));
        let words = |i: usize| {
            let t = MIN_TILE << i;
            estimates[i] + (w.div_ceil(t) * h.div_ceil(t)) as usize + 1
        };
        (0..SIDES)
            .find(|&i| words(i) <= max_entries)
            .map_or(MAX_TILE, |i| MIN_TILE << i)
    }
}

/// The lists' words: `tiles + 1` offsets, then each tile's entries, from the bands' entries
/// (tile index within the band, box slot), each band `band_tiles` tiles.
fn lay_out(entries: &[Vec<(u32, u32)>], tiles: usize, band_tiles: usize) -> Vec<u32> {
    let mut counts = vec![0u32; tiles];
    counts
        .par_chunks_mut(band_tiles)
        .zip(entries)
        .for_each(|(counts, band)| {
            for &(t, _) in band {
                counts[t as usize] += 1;
            }
        });
    let mut offsets = vec![0u32; tiles + 1];
    for t in 0..tiles {
        offsets[t + 1] = offsets[t] + counts[t];
    }
    let total = offsets[tiles] as usize;
    let mut data = Vec::with_capacity(tiles + 1 + total);
    data.extend_from_slice(&offsets);
    data.resize(tiles + 1 + total, 0);
    // Split the entries into the bands' own slices.
    let mut slices = Vec::new();
    let mut rest = &mut data[tiles + 1..];
    for start in (0..tiles).step_by(band_tiles) {
        let end = (start + band_tiles).min(tiles);
        let (band, tail) = rest.split_at_mut((offsets[end] - offsets[start]) as usize);
        slices.push((start, band));
        rest = tail;
    }
    slices
        .into_par_iter()
        .zip(entries)
        .for_each(|((start, out), band)| {
            let first = offsets[start];
            let mut fill: Vec<u32> = offsets[start..(start + band_tiles).min(tiles)]
                .iter()
                .map(|o| o - first)
                .collect();
            for &(t, slot) in band {
                out[fill[t as usize] as usize] = slot;
                fill[t as usize] += 1;
            }
        });
    data
}

impl TileLists {
    /// Bins the marched boxes of `hierarchy` for `camera`.
    pub fn build(hierarchy: &Hierarchy, camera: &Camera) -> Self {
        Self::build_within(hierarchy, camera, MAX_ENTRIES)
    }

    /// Bins the marched boxes in at most about `max_entries` words, offsets included (the smallest
    /// tile side whose estimate fits; MAX_TILE if none does).
    pub fn build_within(hierarchy: &Hierarchy, camera: &Camera, max_entries: usize) -> Self {
        let screen = Screen::new(hierarchy, camera);
        let (w, h) = (screen.w, screen.h);
        let (on_screen, rank) = screen.boxes_on_screen(hierarchy);
        let (feet, runs) = screen.footprint_runs(hierarchy, &rank);
        let tile = screen.tile_side(&feet, max_entries);
        let (reach, parent_reach) = (&screen.reach, &screen.parent_reach);
        let tiles_x = w.div_ceil(tile);
        let tiles_y = h.div_ceil(tile);
        let tiles = (tiles_x * tiles_y) as usize;
        // Bands of tile rows, binned in parallel; each visits its runs of footprints in
        // order and writes only its own tiles, so the order survives. Four bands per thread, so that
        // rayon can balance dense and empty ones (a footprint reaching more bands costs
        // more: 64 bands of 2 rows at 512² on 2 threads were 20% slower).
        let band_rows = tiles_y
            .div_ceil(4 * rayon::current_num_threads() as u32)
            .max(1);
        let band_tiles = (band_rows * tiles_x) as usize;
        let bands = tiles_y.div_ceil(band_rows) as usize;
        // Each band's runs, in order: per chunk of runs in parallel, then joined per band
        // in chunk order.
        const CHUNK: usize = 1 << 14;
        let chunks: Vec<Vec<Vec<u32>>> = runs
            .par_chunks(CHUNK)
            .enumerate()
            .map(|(c, chunk)| {
                let mut per_band: Vec<Vec<u32>> = vec![Vec::new(); bands];
                for (k, run) in chunk.iter().enumerate() {
                    let f = run.bound(&feet);
                    if let Some((ty0, ty1)) = tile_rows(f, &parent_reach[f.level()], tile, h) {
                        for band in (ty0 / band_rows)..=(ty1 / band_rows) {
                            per_band[band as usize].push((c * CHUNK + k) as u32);
                        }
                    }
                }
                per_band
            })
            .collect();
        let members: Vec<Vec<u32>> = (0..bands)
            .into_par_iter()
            .map(|b| chunks.iter().flat_map(|c| c[b].iter().copied()).collect())
            .collect();
        let bins = Bins {
            feet: &feet,
            runs: &runs,
            reach,
            parent_reach,
            members: &members,
            tile,
            tiles_x,
            tiles_y,
            band_rows,
            w,
            h,
        };
        // The bands' entries, worked out once; counted, then laid out.
        let entries: Vec<Vec<(u32, u32)>> = (0..bands)
            .into_par_iter()
            .map(|b| bins.entries(b))
            .collect();
        let data = lay_out(&entries, tiles, band_tiles);
        let boxes = on_screen.iter().map(|&(_, _, r)| r).collect();
        Self {
            tile,
            tiles_x,
            tiles_y,
            data,
            boxes,
        }
    }

    /// The hierarchy's node indices of tile (tx, ty)'s boxes, in list order.
    pub fn tile_nodes(&self, tx: u32, ty: u32) -> Vec<u32> {
        self.tile(tx, ty)
            .iter()
            .map(|&b| self.boxes[b as usize].node)
            .collect()
    }

    /// The entries (indices in `boxes`) of tile (tx, ty).
    pub fn tile(&self, tx: u32, ty: u32) -> &[u32] {
        let tiles = (self.tiles_x * self.tiles_y) as usize;
        let t = (ty * self.tiles_x + tx) as usize;
        let (a, b) = (self.data[t] as usize, self.data[t + 1] as usize);
        &self.data[tiles + 1 + a..tiles + 1 + b]
    }

    /// Pixel rectangles (x0, y0, x1, y1, rows from the top; they may reach past the
    /// picture) that hold every tile with boxes to march, and few others: per band of
    /// [`RECT_BAND`] pixel rows, the runs of tiles with boxes in any of its rows, joined
    /// across gaps narrower than the band. A draw costs a SIMD rasterizer more than
    /// shading a band's gap (~60 µs per draw on llvmpipe), and a pixel outside them all
    /// shows the background.
    pub fn rects(&self) -> Vec<[u32; 4]> {
        let t = self.tile;
        let band = (RECT_BAND / t).max(1);
        let mut rects = Vec::new();
        for ty0 in (0..self.tiles_y).step_by(band as usize) {
            let ty1 = (ty0 + band).min(self.tiles_y);
            let has_boxes = |tx: u32| {
                (ty0..ty1).any(|ty| {
                    let i = (ty * self.tiles_x + tx) as usize;
                    self.data[i + 1] > self.data[i]
                })
            };
            let mut run: Option<[u32; 2]> = None;
            for tx in (0..self.tiles_x).filter(|&tx| has_boxes(tx)) {
                run = match run {
                    Some([a, b]) if tx - b <= band => Some([a, tx + 1]),
                    Some([a, b]) => {
                        rects.push([a * t, ty0 * t, b * t, ty1 * t]);
                        Some([tx, tx + 1])
                    }
                    None => Some([tx, tx + 1]),
                };
            }
            if let Some([a, b]) = run {
                rects.push([a * t, ty0 * t, b * t, ty1 * t]);
            }
        }
        rects
    }

    /// Leaf entries in all tiles.
    pub fn entries(&self) -> usize {
        self.data.len() - (self.tiles_x * self.tiles_y) as usize - 1
    }
}
