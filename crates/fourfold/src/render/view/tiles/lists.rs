//! The per-tile box lists of one view: binned band by band in parallel, laid out in one
//! buffer.

use rayon::prelude::*;

use crate::gpu_layout::BoxRecord;
use crate::render::view::Camera;
use crate::tree::Hierarchy;

use super::bins::Bins;
use super::footprint::tile_rows;
use super::screen::Screen;
use super::{MAX_ENTRIES, RECT_BAND};

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
        // more).
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
