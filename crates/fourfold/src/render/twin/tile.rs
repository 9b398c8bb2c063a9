//! A tile's pixels, in phases that let the work of many pixels be done at once: each
//! pixel's rays; a slice's roots, their steps side by side, and F's signs at the ends of
//! all the brackets, sixteen at a time; each pixel's verdict and the hits it shades; ∇F at
//! all those hits, sixteen at a time; then each pixel's colour.

use std::ops::Range;

use crate::formula::CompiledFormula;
use crate::render::verdict::Verdict;
use crate::render::view::{FLAG_CERTIFIED, FLAG_SLICE, Uniforms};
use crate::tree::Hierarchy;

use super::abreast::{self, Lane, Work};
use super::bundle::{Bundle, RootFree};
use super::certify::{Certifier, SearchBox};
use super::evals::{AxisSlope, Deferred, Evaluators};
use super::march::Stretch;
use super::pixel::{AIMED, Marched, hits_kept, insert_hit};
use super::section::Band;
use super::shading::{V4, add, scale, shade, slice_reach, undecided_color, unorm8};
use super::traced::{Start, Traced};
use super::walk::{Kept, boxes_of, narrow_kept};

/// Draws the pixels `columns` × `rows` into `out` (the band of rows from `rows.start`,
/// `u.size.width` pixels wide), with the tile's walks of the hierarchies in `h` (the rays'
/// and the certifying one) in `scratch.kept`.
pub(super) fn draw_tile(
    formula: &CompiledFormula,
    params: &[f64],
    h: [&Hierarchy; 2],
    u: &Uniforms,
    scratch: &mut Scratch<'_>,
    (columns, rows): (Range<u32>, Range<u32>),
    out: &mut [u8],
) {
    let mut traced = std::mem::take(&mut scratch.traced);
    traced.clear();
    scratch.tile_hits.clear();
    let pixels = rows
        .clone()
        .flat_map(|py| columns.clone().map(move |px| (px, py)));
    if u.control.flags & FLAG_SLICE != 0 && scratch.abreast {
        let mut work = Work {
            lanes: &mut scratch.lanes,
            evals: &mut scratch.evals,
            one_signed: &scratch.one_signed,
            walk: (&scratch.bands[0], &scratch.kept[0]),
            tile: (&mut scratch.tile_hits, &mut scratch.tile_roots),
        };
        let context = (formula, params);
        abreast::trace_pixels(context, (h[0], u), &mut work, pixels, &mut traced);
    } else {
        for at in pixels {
            traced.push(trace_pixel(formula, params, h[0], u, scratch, at));
        }
    }
    find_deferred_roots(formula, params, u, scratch, &traced);
    let mut signs = std::mem::take(&mut scratch.signs);
    signs.clear();
    if u.control.flags & FLAG_CERTIFIED != 0 {
        let brackets = traced.iter().map(|t| (t.start.plane, t.bracket));
        scratch.certifier.bracket_signs(brackets, &mut signs);
    }
    let mut settled = std::mem::take(&mut scratch.settled);
    settled.clear();
    scratch.shades.clear();
    scratch.quads_walked = [false; QUADS];
    let (tile, context) = ((columns.clone(), rows.clone()), (formula, params, h, u));
    for (k, t) in traced.iter().enumerate() {
        let signs = signs.get(k).copied().flatten();
        settled.push(settle_pixel(context, scratch, &tile, t, signs));
    }
    let shades = scratch.shades.iter().map(|&(p, _)| p);
    let gradients = &mut scratch.gradients;
    scratch.evals.gradients(formula, params, shades, gradients);
    let width = u.size.width;
    for s in &settled {
        let c = color_of(u, s, &scratch.shades, &scratch.gradients);
        let (px, py) = s.at;
        let at = (((py - rows.start) * width + px) * 4) as usize;
        let rgb = c.map(unorm8);
        out[at..at + 4].copy_from_slice(&[rgb[0], rgb[1], rgb[2], s.verdict.alpha()]);
    }
    (scratch.traced, scratch.signs, scratch.settled) = (traced, signs, settled);
}

/// The roots the tile's slice rays left for later (see `Pixel::deferred`), found together,
/// each pixel's hits then put where they go in place of its brackets' far ends.
fn find_deferred_roots(
    formula: &CompiledFormula,
    params: &[f64],
    u: &Uniforms,
    scratch: &mut Scratch<'_>,
    traced: &[Traced],
) {
    if scratch.tile_roots.is_empty() {
        return;
    }
    let roots = &mut scratch.tile_roots;
    scratch.evals.find_roots(formula, params, roots);
    let k_max = hits_kept(u);
    for t in traced.iter().filter(|t| t.roots.1 > 0) {
        let ((first, count), (hits, n)) = (t.roots, t.hits);
        scratch.hits.clear();
        for r in &scratch.tile_roots[first..first + count] {
            insert_hit(&mut scratch.hits, k_max, r.search.root(), r.ray);
        }
        debug_assert_eq!(scratch.hits.len(), n, "a deferred root's hit, and no other");
        scratch.tile_hits[hits..hits + n].copy_from_slice(&scratch.hits);
    }
    scratch.tile_roots.clear();
}

/// The form of a box without curvature bounds (brute force's domain).
const UNBOUNDED: [f32; 6] = [
    f32::NEG_INFINITY,
    f32::INFINITY,
    f32::NEG_INFINITY,
    f32::INFINITY,
    f32::NEG_INFINITY,
    f32::INFINITY,
];

/// What a worker's tiles reuse from one to the next.
pub(super) struct Scratch<'a> {
    certifier: Certifier<'a>,
    /// Proves a slice's boxes free of M for a whole tile (see `bundle`).
    pub(super) root_free: RootFree<'a>,
    /// A slice's tile's stretches of its lines on which F keeps one sign, box after box
    /// (each kept box's range of them in `kept[0]`), and one box's.
    pub(super) one_signed: Vec<Stretch>,
    pub(super) stretches: Vec<Stretch>,
    evals: Evaluators,
    /// A slice's pixels' lanes, and whether its pixels are marched side by side in them
    /// (see `abreast`; always but in a test).
    lanes: Vec<Lane>,
    pub(super) abreast: bool,
    /// The pixel's hits (see `Pixel::hits`), kept for its storage.
    hits: Vec<(f32, u32)>,
    /// The boxes of the pixel's rays.
    boxes: Vec<Marched>,
    /// The certifying hierarchy's forms, by node (see `render_rgba`).
    forms: &'a [[f32; 6]],
    /// The section's band from the rays' origin and from the plane's (see `render_rgba`).
    bands: &'a [Option<Band>; 2],
    /// The nodes of the two hierarchies the pixel's tile may visit (see `walk`), and of
    /// the certifying one a slice's quad may (see [`quad_walk`]), and which are walked.
    pub(super) kept: [Vec<Kept>; 2],
    quads: [Vec<Kept>; QUADS],
    quads_walked: [bool; QUADS],
    /// The boxes of the pixel's certified search, walked and then with their forms.
    covered: Vec<Marched>,
    bounds: Vec<SearchBox>,
    /// The tile's pixels after their rays, their hits, and F's signs at their brackets'
    /// ends (see [`draw_tile`]).
    traced: Vec<Traced>,
    tile_hits: Vec<(f32, u32)>,
    signs: Vec<Option<[i8; 2]>>,
    /// A pixel's roots left for later, and the tile's (see `Pixel::deferred`).
    deferred: Vec<Deferred>,
    tile_roots: Vec<Deferred>,
    /// The tile's pixels settled, the hits they shade (point, direction), farthest first
    /// by pixel, and ∇F at each (see [`draw_tile`]).
    settled: Vec<Settled>,
    shades: Vec<(V4, V4)>,
    gradients: Vec<V4>,
}

impl<'a> Scratch<'a> {
    /// A worker's scratch for a frame: `along` a square-on slice's tape (see
    /// `AxisSlope`), `forms` the certifying boxes' forms and `bands` the section's bands
    /// (see `render_rgba`).
    pub(super) fn new(
        formula: &'a CompiledFormula,
        params: &'a [f64],
        u: &'a Uniforms,
        along: Option<&AxisSlope>,
        (forms, bands): (&'a [[f32; 6]], &'a [Option<Band>; 2]),
    ) -> Self {
        Self {
            certifier: Certifier::new(formula, params, u),
            root_free: RootFree::new(formula, params),
            one_signed: Vec::new(),
            stretches: Vec::new(),
            abreast: true,
            evals: Evaluators::new(formula, along),
            lanes: abreast::lanes(),
            hits: Vec::with_capacity(16),
            boxes: Vec::new(),
            forms,
            bands,
            kept: [Vec::new(), Vec::new()],
            quads: Default::default(),
            quads_walked: [false; QUADS],
            covered: Vec::new(),
            bounds: Vec::new(),
            traced: Vec::new(),
            tile_hits: Vec::new(),
            deferred: Vec::new(),
            tile_roots: Vec::new(),
            signs: Vec::new(),
            settled: Vec::new(),
            shades: Vec::new(),
            gradients: Vec::new(),
        }
    }
}

/// A pixel's verdict, and its hits to shade: in the tile's, from the first, how many.
struct Settled {
    at: (u32, u32),
    verdict: Verdict,
    shades: (usize, usize),
}

/// Pixel `at`'s rays across the boxes of `h` they meet (and, where they find nothing,
/// the search between them): its hits, kept in the tile's, and its bracket.
fn trace_pixel(
    formula: &CompiledFormula,
    params: &[f64],
    h: &Hierarchy,
    u: &Uniforms,
    scratch: &mut Scratch<'_>,
    at: (u32, u32),
) -> Traced {
    let start = Start::of(u, at);
    let o = start.o;
    let defers = u.control.flags & FLAG_SLICE != 0 && scratch.evals.defers_roots();
    scratch.hits.clear();
    let mut pixel = start.pixel(
        (u, formula, params),
        (&mut scratch.evals, &mut scratch.hits),
        &scratch.one_signed,
    );
    pixel.deferred = defers.then_some(&mut scratch.deferred);
    let boxes = &mut scratch.boxes;
    boxes_of(h, u, o, (&scratch.bands[0], &scratch.kept[0]), boxes);
    for b in boxes.iter() {
        pixel.trace_box(o, b);
    }
    // As the shader: a pixel whose rays found nothing searches its boxes between them.
    if pixel.hits.is_empty() && !u.brute_force() && !pixel.slice() {
        for b in boxes.iter() {
            pixel.seek_in_plane(o, b);
        }
    }
    let bracket = pixel.bracket;
    let (hits, deferred) = (&scratch.hits, &mut scratch.deferred);
    let tile = (&mut scratch.tile_hits, &mut scratch.tile_roots);
    Traced::keep(start, (hits, deferred, bracket), tile)
}

/// A traced pixel's verdict, F's signs at its bracket's ends proved as `signs` (see
/// `Certifier::bracket_signs`), and its hits to shade, into the tile's; `h` holds the
/// hierarchy the rays march and the one the certified search covers, `tile` the pixels
/// of the pixel's tile.
fn settle_pixel(
    (formula, params, h, u): (&CompiledFormula, &[f64], [&Hierarchy; 2], &Uniforms),
    scratch: &mut Scratch<'_>,
    tile: &(Range<u32>, Range<u32>),
    traced: &Traced,
    signs: Option<[i8; 2]>,
) -> Settled {
    let &Traced {
        start,
        hits: (first, count),
        bracket,
        ..
    } = traced;
    let Start {
        at: (px, py),
        plane,
        o,
        ..
    } = start;
    scratch.hits.clear();
    let mut pixel = start.pixel(
        (u, formula, params),
        (&mut scratch.evals, &mut scratch.hits),
        &scratch.one_signed,
    );
    pixel
        .hits
        .extend_from_slice(&scratch.tile_hits[first..first + count]);
    pixel.bracket = bracket;
    let mut verdict = Verdict::Empty;
    if u.control.flags & FLAG_CERTIFIED != 0 {
        let (covered, bounds) = (&mut scratch.covered, &mut scratch.bounds);
        let band = &scratch.bands[1];
        let quads = (&mut scratch.quads, &mut scratch.quads_walked);
        let (kept, root_free) = (scratch.kept[1].as_slice(), &mut scratch.root_free);
        let forms = scratch.forms;
        let search_boxes = move || {
            // (Moved out of the closure's capture, so that the slice returned may outlive it.)
            let bounds = { bounds };
            let kept = if u.control.flags & FLAG_SLICE != 0 {
                quad_walk((h[1], u), (kept, root_free), quads, tile, (px, py))
            } else {
                kept
            };
            boxes_of(h[1], u, plane, (band, kept), covered);
            bounds.clear();
            bounds.extend(covered.iter().map(|b| SearchBox {
                lo: b.lo,
                hi: b.hi,
                form: b.node.map_or(UNBOUNDED, |i| forms[i]),
            }));
            bounds.as_slice()
        };
        let outcome = scratch
            .certifier
            .pixel((plane, bracket), signs, search_boxes);
        verdict = outcome.verdict;
        if let (Some((a, b)), true) = (outcome.bracket, pixel.hits.is_empty()) {
            // As the shader's `certify`: aim a ray through the proved root.
            let root = pixel.root_between(plane, a, b);
            if pixel.slice() {
                pixel.insert(root[0] + slice_reach(u), AIMED);
            } else {
                let len = (root[0] * root[0] + root[1] * root[1]).sqrt();
                pixel.aim = if len > 0.0 {
                    [root[0] / len, root[1] / len]
                } else {
                    [1.0, 0.0]
                };
                // (The boxes the rays marched, walked again: seldom needed.)
                let boxes = &mut scratch.boxes;
                boxes_of(h[0], u, o, (&scratch.bands[0], &scratch.kept[0]), boxes);
                for b in boxes.iter() {
                    pixel.trace_ray(o, b, AIMED);
                }
                if pixel.hits.is_empty() {
                    pixel.insert(len, AIMED);
                }
            }
        }
    }
    let first = scratch.shades.len();
    for j in 0..pixel.hits.len() {
        let (t, ray) = pixel.hits[pixel.hits.len() - 1 - j];
        let d = pixel.direction(ray);
        scratch.shades.push((add(o, scale(d, t)), d));
    }
    Settled {
        at: (px, py),
        verdict,
        shades: (first, scratch.shades.len() - first),
    }
}

/// The side of the squares of pixels that share a walk of the hierarchy (see `walk`).
pub(super) const TILE: u32 = 8;

/// The side of the squares of a slice's tile whose pixels' certified searches share a walk
/// of the certifying hierarchy narrowed to their lines (see [`quad_walk`]): 2, where 4
/// took 1.01–1.06x as long.
const QUAD: u32 = TILE / 4;

/// The quads of a tile.
const QUADS: usize = ((TILE / QUAD) * (TILE / QUAD)) as usize;

/// The walk of the certifying hierarchy that pixel `at` of a slice's `tile` searches:
/// the tile's (`kept`) narrowed to the lines of the pixel's quad ([`QUAD`]² pixels),
/// left out where `root_free` proves a box free of M on all of them; worked out for the
/// quad's first pixel that searches, into `quads`, as `walked` says.
fn quad_walk<'q>(
    (h, u): (&Hierarchy, &Uniforms),
    (kept, root_free): (&[Kept], &mut RootFree<'_>),
    (quads, walked): (&'q mut [Vec<Kept>; QUADS], &mut [bool; QUADS]),
    (columns, rows): &(Range<u32>, Range<u32>),
    (px, py): (u32, u32),
) -> &'q [Kept] {
    let (qx, qy) = ((px - columns.start) / QUAD, (py - rows.start) / QUAD);
    let q = (qy * (TILE / QUAD) + qx) as usize;
    if !walked[q] {
        let (x0, y0) = (columns.start + qx * QUAD, rows.start + qy * QUAD);
        let pixels = (
            x0..(x0 + QUAD).min(columns.end),
            y0..(y0 + QUAD).min(rows.end),
        );
        let bundle = Bundle::of_pixels(u, pixels);
        let free = |lo, hi| root_free.proves(&bundle, lo, hi);
        narrow_kept(h, u, kept, free, &mut quads[q]);
        walked[q] = true;
    }
    &quads[q]
}

/// A settled pixel's colour: its hits shaded (∇F at each in `gradients`, by the tile's
/// `shades`) and blended farthest first, or with none the background or the undecided
/// marker.
fn color_of(u: &Uniforms, settled: &Settled, shades: &[(V4, V4)], gradients: &[V4]) -> [f32; 3] {
    let (first, count) = settled.shades;
    if count == 0 {
        let (px, py) = settled.at;
        return if settled.verdict == Verdict::Undecided {
            undecided_color(u, px, py)
        } else {
            [u.background[0], u.background[1], u.background[2]]
        };
    }
    let alpha = u.misc.alpha;
    let mut color = [0.0f32; 3];
    for j in 0..count {
        let (p, d) = shades[first + j];
        let c = shade(u, p, d, gradients[first + j]);
        color = if j == 0 {
            c
        } else {
            std::array::from_fn(|i| color[i] * (1.0 - alpha) + c[i] * alpha)
        };
    }
    color
}
