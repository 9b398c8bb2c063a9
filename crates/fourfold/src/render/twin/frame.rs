//! A whole frame on the CPU: each pixel's boxes (its tile's, or a walk of the hierarchy),
//! its rays, and with certified pixels its verdict, in parallel over the rows.

use rayon::prelude::*;

use crate::formula::CompiledFormula;
use crate::render::verdict::Verdict;
use crate::render::view::{FLAG_CERTIFIED, FLAG_SLICE, Uniforms, march_steps};
use crate::tree::{Curvature, Hierarchy};

use super::certify::{Certifier, SearchBox};
use super::pixel::{AIMED, Evaluators, Marched, Pixel, SEEK_STARTS};
use super::section::Band;
use super::shading::{V4, add, dot, pcg, scale, stratified_offset, sub, undecided_color};

/// Renders like the GPU would, returning tightly packed RGBA8 rows (alpha as the shader's:
/// 255, or with `FLAG_CERTIFIED` the pixel's `Verdict::alpha`).
pub fn render_rgba(
    formula: &CompiledFormula,
    params: &[f64],
    hierarchy: &Hierarchy,
    certifying: Option<&Hierarchy>,
    u: &Uniforms,
) -> Vec<u8> {
    let certifying = certifying.unwrap_or(hierarchy);
    // The certified search's forms of its boxes' curvature bounds in this view's plane (as
    // the shader's box records), once per frame.
    let forms: Vec<[f32; 6]> = if u.control.flags & FLAG_CERTIFIED != 0 {
        let (n1, n2) = (u.n1.map(f64::from), u.n2.map(f64::from));
        (0..certifying.nodes.len())
            .map(|i| certifying.curvature(i).in_plane(n1, n2))
            .collect()
    } else {
        Vec::new()
    };
    // The section's bands from the rays' origin and from the plane's, once per frame.
    let bands = [Band::of(u, true), Band::of(u, false)];
    let (width, height) = (u.size.width, u.size.height);
    let rows: Vec<Vec<u8>> = (0..height)
        .into_par_iter()
        .map(|py| {
            let mut scratch = Scratch {
                certifier: Certifier::new(formula, params, u),
                evals: Evaluators::new(),
                boxes: Vec::new(),
                forms: &forms,
                bands: &bands,
                covered: Vec::new(),
                bounds: Vec::new(),
            };
            let mut row = Vec::with_capacity(width as usize * 4);
            for px in 0..width {
                let pixel = (px, py);
                let (c, verdict) = render_pixel(
                    formula,
                    params,
                    [hierarchy, certifying],
                    u,
                    &mut scratch,
                    pixel,
                );
                row.extend(c.map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8));
                row.push(verdict.alpha());
            }
            row
        })
        .collect();
    rows.concat()
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

/// What a row's pixels reuse from one to the next.
struct Scratch<'a> {
    certifier: Certifier<'a>,
    evals: Evaluators,
    /// The boxes of the pixel's rays.
    boxes: Vec<Marched>,
    /// The certifying hierarchy's forms, by node (see `render_rgba`).
    forms: &'a [[f32; 6]],
    /// The section's band from the rays' origin and from the plane's (see `render_rgba`).
    bands: &'a [Option<Band>; 2],
    /// The boxes of the pixel's certified search, walked and then with their forms.
    covered: Vec<Marched>,
    bounds: Vec<SearchBox>,
}

/// The boxes pixel `o`'s rays march (or, for `certifying`'s hierarchy, its certified search
/// covers), into `boxes`: a walk of the hierarchy's marched boxes whose sphere meets its
/// observer plane (the shader's MODE 2), or the domain for brute force. With a `band` (a
/// slice's or slab's, from `o`), a box that cannot meet it is left out with its subtree,
/// as the shader's tile lists leave it out.
fn boxes_of(h: &Hierarchy, u: &Uniforms, o: V4, band: &Option<Band>, boxes: &mut Vec<Marched>) {
    boxes.clear();
    if u.brute_force() {
        boxes.push(Marched {
            lo: u.domain_lo,
            hi: u.domain_hi,
            steps: u.counts.brute_steps,
            slope: [f32::INFINITY; 4],
            curvature: Curvature::NONE,
            node: None,
        });
        return;
    }
    let mut i = 0usize;
    while i < h.nodes.len() {
        let node = &h.nodes[i];
        let level = &u.levels[node.level() as usize];
        let rel = sub(node.center, o);
        let (a, b) = (dot(rel, u.v1), dot(rel, u.v2));
        if a * a + b * b > level.radius * level.radius
            || band
                .as_ref()
                .is_some_and(|b| !b.meets(rel, node.level() as usize))
        {
            i = node.skip as usize;
            continue;
        }
        // As the shader's `visit`: the boxes of the cut are marched whole.
        if node.is_marched() {
            boxes.push(Marched {
                lo: sub(node.center, level.half),
                hi: add(node.center, level.half),
                steps: if node.is_leaf() {
                    u.control.steps
                } else {
                    march_steps(u.control.steps, u.march.finest.saturating_sub(node.level()))
                },
                slope: h.slope(i),
                curvature: h.curvature(i),
                node: Some(i),
            });
            i = node.skip as usize;
            continue;
        }
        i += 1;
    }
}

/// A pixel's colour and verdict; `h` holds the hierarchy the rays march and the one the
/// certified search covers.
fn render_pixel(
    formula: &CompiledFormula,
    params: &[f64],
    h: [&Hierarchy; 2],
    u: &Uniforms,
    scratch: &mut Scratch<'_>,
    (px, py): (u32, u32),
) -> ([f32; 3], Verdict) {
    let (w, hgt) = (u.size.width as f32, u.size.height as f32);
    let s = u.misc.pixel_size;
    let (fx, fy) = (px as f32 + 0.5, py as f32 + 0.5);
    let plane = add(
        u.center,
        add(
            scale(u.v1, s * (fx - 0.5 * w)),
            scale(u.v2, s * (0.5 * hgt - fy)),
        ),
    );
    let mut o = plane;
    // As the shader: the slice's line, from where it enters the sphere around the domain.
    let extent = sub(u.domain_hi, u.domain_lo);
    let reach = 0.5 * dot(extent, extent).sqrt();
    if u.control.flags & FLAG_SLICE != 0 {
        o = sub(
            add(o, scale(u.n2, u.root.section_offset)),
            scale(u.n1, reach),
        );
    }
    let seed = pcg(px.wrapping_add(pcg(py.wrapping_add(pcg(u
        .control
        .seed
        .wrapping_add(7919u32.wrapping_mul(u.counts.frame)))))));
    let mut pixel = Pixel {
        u,
        formula,
        params,
        eval: &mut scratch.evals,
        seed,
        offset: stratified_offset(u.control.seed, u.counts.frame, px, py),
        hits: Vec::with_capacity(16),
        k_max: u.size.hits.clamp(1, 16) as usize,
        aim: [1.0, 0.0],
        plane,
        bracket: None,
        closest: ([0.0; 2], f32::INFINITY),
        starts: [([0.0; 2], f32::INFINITY); SEEK_STARTS],
    };
    let boxes = &mut scratch.boxes;
    boxes_of(h[0], u, o, &scratch.bands[0], boxes);
    for b in boxes.iter() {
        pixel.trace_box(o, b);
    }
    // As the shader: a pixel whose rays found nothing searches its boxes between them.
    if pixel.hits.is_empty() && !u.brute_force() && !pixel.slice() {
        for b in boxes.iter() {
            pixel.seek_in_plane(o, b);
        }
    }
    let mut verdict = Verdict::Empty;
    if u.control.flags & FLAG_CERTIFIED != 0 {
        boxes_of(h[1], u, plane, &scratch.bands[1], &mut scratch.covered);
        let forms = scratch.forms;
        scratch.bounds.clear();
        scratch
            .bounds
            .extend(scratch.covered.iter().map(|b| SearchBox {
                lo: b.lo,
                hi: b.hi,
                form: b.node.map_or(UNBOUNDED, |i| forms[i]),
            }));
        let outcome = scratch
            .certifier
            .pixel(plane, &scratch.bounds, pixel.bracket);
        verdict = outcome.verdict;
        if let (Some((a, b)), true) = (outcome.bracket, pixel.hits.is_empty()) {
            // As the shader's `certify`: aim a ray through the proved root.
            let root = pixel.root_between(plane, a, b);
            if pixel.slice() {
                pixel.insert(root[0] + reach, AIMED);
            } else {
                let len = (root[0] * root[0] + root[1] * root[1]).sqrt();
                pixel.aim = if len > 0.0 {
                    [root[0] / len, root[1] / len]
                } else {
                    [1.0, 0.0]
                };
                for b in boxes.iter() {
                    pixel.trace_ray(o, b, AIMED);
                }
                if pixel.hits.is_empty() {
                    pixel.insert(len, AIMED);
                }
            }
        }
    }
    if pixel.hits.is_empty() {
        let color = if verdict == Verdict::Undecided {
            undecided_color(u, px, py)
        } else {
            [u.background[0], u.background[1], u.background[2]]
        };
        return (color, verdict);
    }
    let alpha = u.misc.alpha;
    let hits = pixel.hits.clone();
    let mut color = [0.0f32; 3];
    for (j, &(t, ray)) in hits.iter().rev().enumerate() {
        let d = pixel.direction(ray);
        let c = pixel.shade(add(o, scale(d, t)), d);
        color = if j == 0 {
            c
        } else {
            std::array::from_fn(|i| color[i] * (1.0 - alpha) + c[i] * alpha)
        };
    }
    (color, verdict)
}
