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
//! the K it keeps: every later one is at least as far (nearest-first with early exit). A
//! slab or a slice bins only the boxes that meet it, and a slice orders them along its ray
//! (see `section`).

mod bins;
mod footprint;
mod lists;
mod screen;
mod section;

pub use crate::gpu_layout::BoxRecord;
pub use lists::TileLists;

/// Largest and smallest tile side in pixels. The pixels of a tile read one list in one
/// order, so a SIMD group of pixels (llvmpipe shades 4x4 blocks; a GPU, warps of 32 or 64)
/// visits the same boxes at the same time; small tiles draw as fast as single pixels, with
/// a far cheaper binning (docs/benchmarks.md, "Design choices").
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
