//! A whole frame on the CPU: each pixel's boxes (a walk of the hierarchy, shared by a tile
//! of pixels), its rays, and with certified pixels its verdict, in parallel over bands of
//! rows.

use std::ops::Range;

use rayon::prelude::*;

use crate::formula::CompiledFormula;
use crate::render::verdict::Verdict;
use crate::render::view::{FLAG_CERTIFIED, FLAG_SLICE, Uniforms, slope_along};
use crate::tree::Hierarchy;

use super::bundle::Bundle;
use super::evals::AxisSlope;
use super::march::Along;
use super::section::Band;
use super::shading::{add, origins, slice_reach, sub, unorm8};
use super::tile::{Scratch, TILE, draw_tile};
use super::walk::{Tile, steps_of, tile_nodes};

/// Renders like the GPU would, returning tightly packed RGBA8 rows (alpha as the shader's:
/// 255, or with `FLAG_CERTIFIED` the pixel's `Verdict::alpha`).
pub fn render_rgba(
    formula: &CompiledFormula,
    params: &[f64],
    hierarchy: &Hierarchy,
    certifying: Option<&Hierarchy>,
    u: &Uniforms,
) -> Vec<u8> {
    render(formula, params, (hierarchy, certifying), u, true)
}

/// [`render_rgba`], a slice's pixels marched side by side where `abreast` and their tapes
/// allow (see `abreast`), else one by one: the same picture.
fn render(
    formula: &CompiledFormula,
    params: &[f64],
    (hierarchy, certifying): (&Hierarchy, Option<&Hierarchy>),
    u: &Uniforms,
    abreast: bool,
) -> Vec<u8> {
    let certifying = certifying.unwrap_or(hierarchy);
    let certified = u.control.flags & FLAG_CERTIFIED != 0;
    let slice = u.control.flags & FLAG_SLICE != 0;
    // The certified search's forms of its boxes' curvature bounds in this view's plane (as
    // the shader's box records), once per frame.
    let forms: Vec<[f32; 6]> = if certified {
        let (n1, n2) = (u.n1.map(f64::from), u.n2.map(f64::from));
        (0..certifying.nodes.len())
            .map(|i| certifying.curvature(i).in_plane(n1, n2))
            .collect()
    } else {
        Vec::new()
    };
    // A slice seen square on: its samples' slopes from F and one partial (see AxisSlope).
    let along = slice.then(|| AxisSlope::of(formula, u.n1)).flatten();
    // The section's bands from the rays' origin and from the plane's, once per frame.
    let bands = [Band::of(u, true), Band::of(u, false)];
    let (width, height) = (u.size.width, u.size.height);
    // A pixel of a tile with nothing to march: the background, proved empty.
    let bg = u.background.map(unorm8);
    let empty = [bg[0], bg[1], bg[2], Verdict::Empty.alpha()];
    // Bands of TILE rows in parallel, each walked a tile of TILE × TILE pixels at a time,
    // each drawn into its part of the picture; a worker's scratch serves all its bands.
    let mut rgba = vec![0u8; (width * height * 4) as usize];
    let band_bytes = (TILE * width * 4) as usize;
    rgba.par_chunks_mut(band_bytes).enumerate().for_each_init(
        || {
            let mut scratch = Scratch::new(formula, params, u, along.as_ref(), (&forms, &bands));
            scratch.abreast &= abreast;
            scratch
        },
        |scratch, (strip, out)| {
            let strip = strip as u32;
            let rows = strip * TILE..((strip + 1) * TILE).min(height);
            for x0 in (0..width).step_by(TILE as usize) {
                let columns = x0..(x0 + TILE).min(width);
                // (The certifying hierarchy's only where pixels are certified.)
                let walked = if certified { 2 } else { 1 };
                let bundle = slice.then(|| Bundle::of_pixels(u, (columns.clone(), rows.clone())));
                let mut free = |lo, hi| {
                    bundle
                        .as_ref()
                        .is_some_and(|b| scratch.root_free.proves(b, lo, hi))
                };
                for (k, h) in [hierarchy, certifying].into_iter().enumerate().take(walked) {
                    let tile = tile_around(u, (columns.clone(), rows.clone()), k == 0);
                    tile_nodes(h, u, (tile, &bands[k]), &mut free, &mut scratch.kept[k]);
                }
                // A tile whose walks kept no node has no box to march or search: each of
                // its pixels is the background, proved empty (what `draw_tile` finds).
                if !u.brute_force() && scratch.kept[..walked].iter().all(Vec::is_empty) {
                    for py in rows.clone() {
                        let at = (((py - rows.start) * width + columns.start) * 4) as usize;
                        let row = &mut out[at..at + columns.len() * 4];
                        row.chunks_exact_mut(4)
                            .for_each(|p| p.copy_from_slice(&empty));
                    }
                    continue;
                }
                scratch.one_signed.clear();
                if let Some(bundle) = &bundle {
                    one_signed_stretches(hierarchy, u, bundle, scratch);
                }
                let h = [hierarchy, certifying];
                draw_tile(formula, params, h, u, scratch, (columns, rows.clone()), out);
            }
        },
    );
    rgba
}

/// The pixels `columns` × `rows` as a [`Tile`]: around the origin of their plane (or, with
/// `rays` in a slice, of their rays' line) at the square's centre.
fn tile_around(u: &Uniforms, (columns, rows): (Range<u32>, Range<u32>), rays: bool) -> Tile {
    let middle = |r: Range<u32>| 0.5 * (r.start + r.end) as f32;
    let (plane, line) = origins(u, (middle(columns.clone()), middle(rows.clone())));
    let centre = if rays { line } else { plane };
    let (w, h) = (f64::from(u.size.width), f64::from(u.size.height));
    let s = f64::from(u.misc.pixel_size);
    let half = 0.5 * f64::from((columns.end - columns.start).max(rows.end - rows.start));
    let centre_size: f64 = u.center.iter().map(|c| f64::from(*c).abs()).sum();
    let (reach, offset) = (slice_reach(u), u.root.section_offset.abs());
    Tile {
        centre: centre.map(f64::from),
        radius: s * half * std::f64::consts::SQRT_2 * (1.0 + 1e-6),
        rounding: 1e-5 * (centre_size + s * (w + h) + f64::from(reach + offset)),
    }
}

/// The stretches of a slice's tile's lines on which F keeps one sign, in each box of the
/// rays' hierarchy that the tile's walk kept: halved until a stretch is about 4 of the box's
/// steps long, as the march could not skip a shorter one by much; and each box's bounds
/// along the lines.
fn one_signed_stretches(h: &Hierarchy, u: &Uniforms, bundle: &Bundle, scratch: &mut Scratch) {
    let n1 = u.n1.map(f64::from);
    for kept in scratch.kept[0].iter_mut() {
        let node = &h.nodes[kept.node()];
        if !node.is_marched() {
            continue;
        }
        kept.along = Some(Along {
            slope: slope_along(h.slope(kept.node()), n1),
            bend: h.curvature(kept.node()).along(n1),
        });
        let half = u.levels[node.level() as usize].half;
        let depth = (steps_of(h, u, kept.node()) / 4).max(1).ilog2();
        let sides = (sub(node.center, half), add(node.center, half));
        let stretches = &mut scratch.stretches;
        scratch
            .root_free
            .one_signed(bundle, sides, depth, stretches);
        let first = scratch.one_signed.len() as u32;
        scratch.one_signed.extend_from_slice(stretches);
        kept.one_signed = (first, scratch.one_signed.len() as u32);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::prepare::Prepared;
    use crate::render::view::FrameOptions;
    use crate::scene::Scene;

    /// A slice's pixels marched side by side draw, byte for byte, the picture they draw one
    /// by one: square on and turned, certified and plain, one hit and several, on shapes
    /// with thin parts, kinks and parameters.
    #[test]
    fn slices_marched_abreast_are_the_pixels_marched_one_by_one() {
        let shapes = [
            ("(x^2 + y^2 + z^2 + R^2 - r^2)^2 - 4R^2(x^2 + y^2) - w", 0.5),
            ("x^6 + y^6 + z^6 + w^6 + 4x^2 y^2 z^2 - 1", 0.5),
            ("abs(x) + abs(y) + abs(z) + abs(w) - 1", -0.2),
            ("(x^2 + y^2 - 0.6)^2 + z^2 - 0.003 - 0.01 w", 0.1),
            ("x y z - w^3 + 0.1", 0.4),
        ];
        let views = [
            ("[0, 0, 0, 0, 0, 0]", 4, true),
            ("[0.3, -0.2, 0.5, 0.1, 0.7, -0.4]", 4, true),
            ("[0, 0, 0, 0, 0, 0]", 1, false),
            ("[0.9, 0.1, -0.3, 0.2, 0, 0.5]", 1, true),
        ];
        for (source, slice) in shapes {
            for (angles, hits, certified) in views {
                let text = format!(
                    "formula = \"{source}\"\n[params]\nR = 1.0\nr = 0.4\n\
                     [view]\nangles = {angles}\nslice = {slice}\n\
                     [render]\nhits = {hits}\ncertified = {certified}\n\
                     [domain]\nx = [-1.5, 1.5]\ny = [-1.5, 1.5]\nz = [-1.5, 1.5]\nw = [-1.5, 1.5]\n"
                );
                let scene = Scene::parse(&text, "test").unwrap();
                let formula = CompiledFormula::compile(&scene.formula).unwrap();
                let prepared = Prepared::new(&formula, &scene).unwrap();
                let (_, u) = prepared.frame(&scene, 48, 40, FrameOptions::default());
                let certifying = certified.then(|| prepared.certifying(&formula));
                let h = (&prepared.hierarchy, certifying);
                let params = &prepared.params;
                let abreast = render(&formula, params, h, &u, true);
                let one_by_one = render(&formula, params, h, &u, false);
                let differ = abreast.chunks(4).zip(one_by_one.chunks(4));
                let differ = differ.filter(|(a, b)| a != b).count();
                assert_eq!(differ, 0, "{source} at {slice}, {angles}, {hits} hits");
                let shown = abreast.chunks(4).filter(|p| p[..3] != abreast[..3]).count();
                assert!(shown > 0, "{source} at {slice}, {angles}: nothing drawn");
            }
        }
    }
}
