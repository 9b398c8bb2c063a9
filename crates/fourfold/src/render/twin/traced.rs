//! A pixel's start (where it is, its origins, its rays' seed and offset) and the pixel
//! after its rays' march, its hits and roots kept in its tile's until the tile's brackets
//! are proved and its roots found (see `tile`).

use crate::formula::CompiledFormula;
use crate::render::view::Uniforms;

use super::certify::SignChange;
use super::evals::{Deferred, Evaluators};
use super::march::Stretch;
use super::pixel::Pixel;
use super::shading::{V4, origins, pcg, stratified_offset};

/// A pixel's first sign change (see [`Pixel::bracket`]).
pub(super) type PlaneBracket = Option<SignChange>;

/// Where a pixel is, its plane's and its rays' origins, and its rays' seed and offset.
#[derive(Debug, Clone, Copy)]
pub(super) struct Start {
    pub(super) at: (u32, u32),
    pub(super) plane: V4,
    pub(super) o: V4,
    seed: u32,
    offset: f32,
}

impl Start {
    /// Pixel (px, py) of the frame `u`.
    pub(super) fn of(u: &Uniforms, (px, py): (u32, u32)) -> Self {
        let (plane, o) = origins(u, (px as f32 + 0.5, py as f32 + 0.5));
        let frame = u
            .control
            .seed
            .wrapping_add(7919u32.wrapping_mul(u.counts.frame));
        Self {
            at: (px, py),
            plane,
            o,
            seed: pcg(px.wrapping_add(pcg(py.wrapping_add(pcg(frame))))),
            offset: stratified_offset(u.control.seed, u.counts.frame, px, py),
        }
    }

    /// The pixel, with a worker's evaluators, its hits so far and its tile's one-signed
    /// stretches (see [`Pixel::new`]).
    pub(super) fn pixel<'a, 'e>(
        &self,
        (u, formula, params): (&'a Uniforms, &'a CompiledFormula, &'a [f64]),
        (eval, hits): (&'e mut Evaluators, &'e mut Vec<(f32, u32)>),
        one_signed: &'a [Stretch],
    ) -> Pixel<'a, 'e> {
        let rays = (self.seed, self.offset);
        Pixel::new(
            (u, formula, params),
            (eval, hits),
            one_signed,
            self.plane,
            rays,
        )
    }
}

/// A pixel after its rays' march, until its bracket's signs are proved with its tile's:
/// its start, its hits (in the tile's, from the first, how many) and its bracket (see
/// [`Pixel::bracket`]).
pub(super) struct Traced {
    pub(super) start: Start,
    pub(super) hits: (usize, usize),
    /// Its roots left for later (see `Pixel::deferred`), in the tile's: from, how many.
    pub(super) roots: (usize, usize),
    pub(super) bracket: PlaneBracket,
}

impl Traced {
    /// A pixel from `start` whose rays found `hits`, the roots `deferred` left for later
    /// (taken) and `bracket`: its hits and roots kept in its tile's.
    pub(super) fn keep(
        start: Start,
        (hits, deferred, bracket): (&[(f32, u32)], &mut Vec<Deferred>, PlaneBracket),
        (tile_hits, tile_roots): (&mut Vec<(f32, u32)>, &mut Vec<Deferred>),
    ) -> Self {
        let first = tile_hits.len();
        tile_hits.extend_from_slice(hits);
        let roots = tile_roots.len();
        tile_roots.append(deferred);
        Self {
            start,
            hits: (first, hits.len()),
            roots: (roots, tile_roots.len() - roots),
            bracket,
        }
    }
}
