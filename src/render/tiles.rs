//! Screen tiles: for each square block of pixels, the leaves whose sphere can meet the
//! observer plane of some pixel in it. Built on the CPU per view (one pass over the leaves),
//! so that each pixel tests only its tile's leaves instead of walking the hierarchy: the walk's
//! inner-node tests (16 children per passing node) were most of a frame on a software GPU.
//!
//! A leaf's sphere (centre c, radius r) meets pixel p's observer plane iff the projection of c
//! on the (v1, v2) plane is within r of p's origin there. In pixel units that is a disk of
//! radius r / pixel_size around the projected centre: the leaf goes into every tile that disk
//! overlaps (with one pixel of margin for rounding). Layout, one `u32` buffer:
//! `[offset of tile 0, …, offset of tile T, leaf indices…]`, offsets counted from the start of
//! the leaf indices.

use rayon::prelude::*;

use crate::tree::Hierarchy;

use super::camera::Camera;

/// Largest and smallest tile side in pixels.
pub const MAX_TILE: u32 = 16;
pub const MIN_TILE: u32 = 2;

/// The per-tile leaf lists of one view.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct TileLists {
    /// Tile side in pixels: about the radius of the smallest leaf sphere on screen, a power of
    /// two in MIN_TILE..=MAX_TILE. Smaller tiles mean shorter lists (less work per pixel) but
    /// more entries per leaf.
    pub tile: u32,
    pub tiles_x: u32,
    pub tiles_y: u32,
    /// `tiles_x·tiles_y + 1` offsets, then the leaf indices.
    pub data: Vec<u32>,
}

impl TileLists {
    /// Bins the leaves of `hierarchy` for `camera`.
    pub fn build(hierarchy: &Hierarchy, camera: &Camera) -> Self {
        let smallest = hierarchy
            .nodes
            .iter()
            .filter(|n| n.is_leaf())
            .map(|n| n.level())
            .max()
            .and_then(|l| hierarchy.levels.get(l as usize))
            .map_or(f64::INFINITY, |info| f64::from(info.radius));
        let radius_px = smallest / camera.pixel_size;
        let mut tile = MAX_TILE;
        while tile > MIN_TILE && f64::from(tile) > radius_px {
            tile /= 2;
        }
        let tiles_x = camera.width.div_ceil(tile);
        let tiles_y = camera.height.div_ceil(tile);
        let tf = f64::from(tile);
        let tiles = (tiles_x * tiles_y) as usize;
        let v1 = camera.v1;
        let v2 = camera.v2;
        let s = camera.pixel_size;
        let (w, h) = (f64::from(camera.width), f64::from(camera.height));
        // The tile rectangle of each leaf: (x0, x1, y0, y1), inclusive; None when off screen.
        let rects: Vec<Option<[u32; 4]>> = hierarchy
            .nodes
            .par_iter()
            .map(|node| {
                if !node.is_leaf() {
                    return None;
                }
                let radius = f64::from(hierarchy.levels.get(node.level() as usize)?.radius);
                let rel: [f64; 4] =
                    std::array::from_fn(|i| f64::from(node.center[i]) - camera.center[i]);
                let a: f64 = (0..4).map(|i| rel[i] * v1[i]).sum();
                let b: f64 = (0..4).map(|i| rel[i] * v2[i]).sum();
                // Invert Camera::origin: pixel centre (px + 0.5, py + 0.5).
                let cx = a / s + 0.5 * w;
                let cy = 0.5 * h - b / s;
                let rp = radius / s + 1.0;
                let x0 = ((cx - rp) / tf).floor().max(0.0);
                let x1 = ((cx + rp) / tf).floor();
                let y0 = ((cy - rp) / tf).floor().max(0.0);
                let y1 = ((cy + rp) / tf).floor();
                if !(x1 >= 0.0 && y1 >= 0.0 && x0 < f64::from(tiles_x) && y0 < f64::from(tiles_y)) {
                    return None;
                }
                Some([
                    x0 as u32,
                    (x1 as u32).min(tiles_x - 1),
                    y0 as u32,
                    (y1 as u32).min(tiles_y - 1),
                ])
            })
            .collect();
        // Counting sort into the tiles.
        let mut counts = vec![0u32; tiles + 1];
        for r in rects.iter().flatten() {
            for ty in r[2]..=r[3] {
                for tx in r[0]..=r[1] {
                    counts[(ty * tiles_x + tx) as usize] += 1;
                }
            }
        }
        let mut offsets = vec![0u32; tiles + 1];
        for t in 0..tiles {
            offsets[t + 1] = offsets[t] + counts[t];
        }
        let total = offsets[tiles] as usize;
        let mut data = Vec::with_capacity(tiles + 1 + total);
        data.extend_from_slice(&offsets);
        data.resize(tiles + 1 + total, 0);
        let mut fill = offsets.clone();
        for (i, r) in rects.iter().enumerate() {
            let Some(r) = r else { continue };
            for ty in r[2]..=r[3] {
                for tx in r[0]..=r[1] {
                    let t = (ty * tiles_x + tx) as usize;
                    data[tiles + 1 + fill[t] as usize] = i as u32;
                    fill[t] += 1;
                }
            }
        }
        Self {
            tile,
            tiles_x,
            tiles_y,
            data,
        }
    }

    /// The leaf indices of tile (tx, ty).
    pub fn tile(&self, tx: u32, ty: u32) -> &[u32] {
        let tiles = (self.tiles_x * self.tiles_y) as usize;
        let t = (ty * self.tiles_x + tx) as usize;
        let (a, b) = (self.data[t] as usize, self.data[t + 1] as usize);
        &self.data[tiles + 1 + a..tiles + 1 + b]
    }

    /// Leaf entries in all tiles.
    pub fn entries(&self) -> usize {
        self.data.len() - (self.tiles_x * self.tiles_y) as usize - 1
    }
}
