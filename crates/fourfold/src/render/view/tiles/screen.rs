//! The view as the binning sees it: pixel units, each level's reach on the screen, and the
//! footprints of the marched boxes' cover boxes, in the view's order.

use rayon::prelude::*;

use crate::gpu_layout::BoxRecord;
use crate::render::view::Camera;
use crate::tree::{CoverBox, Hierarchy};

use super::footprint::{Footprint, Projection, Reach, Run, order_key, pixel_range, record};
use super::section::SectionTest;
use super::{COVER_PER_TILE, MAX_TILE, MIN_TILE};

/// The view as the binning sees it: pixel units, and each level's reach on the screen.
pub(super) struct Screen<'a> {
    pub(super) camera: &'a Camera,
    pub(super) w: u32,
    pub(super) h: u32,
    /// Per level, the box's reach (see [`Reach`]).
    pub(super) reach: Vec<Reach>,
    /// For the runs' parents (see `Bins::parent_reach`).
    pub(super) parent_reach: Vec<Reach>,
}

impl<'a> Screen<'a> {
    pub(super) fn new(hierarchy: &Hierarchy, camera: &'a Camera) -> Self {
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
    pub(super) fn project(&self, center: [f32; 4]) -> (f32, f32, [f64; 4]) {
        let c = self.camera;
        let rel: [f64; 4] = std::array::from_fn(|k| f64::from(center[k]) - c.center[k]);
        let dot = |v: &[f64; 4]| -> f64 { (0..4).map(|k| rel[k] * v[k]).sum() };
        let (a, b) = (dot(&c.v1), dot(&c.v2));
        let cx = (a / c.pixel_size + 0.5 * f64::from(self.w)) as f32;
        let cy = (0.5 * f64::from(self.h) - b / c.pixel_size) as f32;
        (cx, cy, [a, b, dot(&c.n1), dot(&c.n2)])
    }

    /// The marched boxes on screen that meet the section searched, nearest first (by
    /// |q| − r, or a slice's entry: see `SectionTest`; then node), with their records; and
    /// each node's place in that order (`u32::MAX`: not binned).
    #[allow(clippy::type_complexity)]
    pub(super) fn boxes_on_screen(
        &self,
        hierarchy: &Hierarchy,
    ) -> (Vec<(u32, u32, BoxRecord)>, Vec<u32>) {
        let section = SectionTest::new(hierarchy, self.camera);
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
                let mut record = record(hierarchy, i as u32, view, self.camera);
                record.view[2] =
                    section.key(node.level() as usize, [view[2], view[3]], record.view[2])?;
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
    pub(super) fn footprint_runs(
        &self,
        hierarchy: &Hierarchy,
        rank: &[u32],
    ) -> (Vec<Footprint>, Vec<Run>) {
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
    pub(super) fn tile_side(&self, feet: &[Footprint], max_entries: usize) -> u32 {
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
