//! The binning's inner loop: which tiles of a band each marched box reaches, marked as bit
//! ranges per tile row.

use super::footprint::{Footprint, Reach, Run, row_span, tile_rows};

/// The footprints of one view, by band of tile rows.
pub(super) struct Bins<'a> {
    pub(super) feet: &'a [Footprint],
    pub(super) runs: &'a [Run],
    pub(super) reach: &'a [Reach],
    /// `reach` a little wider, for the parents' test: a child box's sphere touches its
    /// parent's from inside, so rounding must not let a child reach further.
    pub(super) parent_reach: &'a [Reach],
    /// Per band, the runs that reach it, in order.
    pub(super) members: &'a [Vec<u32>],
    pub(super) tile: u32,
    pub(super) tiles_x: u32,
    pub(super) tiles_y: u32,
    pub(super) band_rows: u32,
    pub(super) w: u32,
    pub(super) h: u32,
}

impl Bins<'_> {
    /// The entries of `band`: (tile index within the band, box slot) once for every tile
    /// of the band that a footprint of the box reaches, boxes in order. A box's footprints are
    /// consecutive (sorted by box) and overlap a lot near M (a pixel there can be reached by
    /// hundreds of cover boxes), so they are first marked as bit ranges per tile row, one
    /// word operation per row instead of one per tile, and the union's tiles read off once.
    pub(super) fn entries(&self, band: usize) -> Vec<(u32, u32)> {
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
    pub(super) fn marked(
        &self,
        bits: &[u64],
        words: usize,
        p: &Footprint,
        r0: u32,
        r1: u32,
    ) -> bool {
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
