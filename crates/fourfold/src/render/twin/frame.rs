//! A whole frame on the CPU: each pixel's boxes (its tile's, or a walk of the hierarchy),
//! its rays, and with certified pixels its verdict, in parallel over the rows.

use rayon::prelude::*;

use crate::formula::CompiledFormula;
use crate::render::verdict::Verdict;
use crate::render::view::{FLAG_CERTIFIED, FLAG_SLAB, FLAG_SLICE, Uniforms, march_steps};
use crate::tree::{Curvature, Hierarchy};

use super::certify::{Certifier, SearchBox};
use super::pixel::{AIMED, Evaluators, Marched, Pixel, SEEK_STARTS};
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
    let (width, height) = (u.size.width, u.size.height);
    let rows: Vec<Vec<u8>> = (0..height)
        .into_par_iter()
        .map(|py| {
            let mut scratch = Scratch {
                certifier: Certifier::new(formula, params, u),
                evals: Evaluators::new(),
                boxes: Vec::new(),
                forms: &forms,
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
    /// The boxes of the pixel's certified search, walked and then with their forms.
    covered: Vec<Marched>,
    bounds: Vec<SearchBox>,
}

/// The boxes pixel `o`'s rays march (or, for `certifying`'s hierarchy, its certified search
/// covers), into `boxes`: a walk of the hierarchy's marched boxes whose sphere meets its
/// observer plane (the shader's MODE 2), or the domain for brute force. With a `band` of
/// n2 coordinates from `o` (a slice's or slab's, see `Band::of`), a box that cannot
/// meet it is left out with its subtree, as the shader's tile lists leave it out.
fn boxes_of(h: &Hierarchy, u: &Uniforms, o: V4, band: Option<Band>, boxes: &mut Vec<Marched>) {
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
            || band.is_some_and(|band| !band.meets(rel, level.half, u))
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

/// A range of n2 coordinates from a pixel's origin: where its slice or slab lies.
#[derive(Debug, Clone, Copy)]
struct Band {
    lo: f64,
    hi: f64,
}

impl Band {
    /// The section's band from the pixel's plane origin (`plane`) or, for a slice, from its
    /// line's start (`line`, which lies in the slice's hyperplane); None for a whole plane.
    fn of(u: &Uniforms, line: bool) -> Option<Self> {
        let (offset, half) = (
            f64::from(u.root.section_offset),
            f64::from(u.root.section_half),
        );
        if u.control.flags & FLAG_SLICE != 0 {
            let at = if line { 0.0 } else { offset };
            Some(Self { lo: at, hi: at })
        } else if u.control.flags & FLAG_SLAB != 0 {
            Some(Self {
                lo: offset - half,
                hi: offset + half,
            })
        } else {
            None
        }
    }

    /// Whether the box `rel` ± `half` (its centre from the origin) may meet the band: its
    /// range along n2, widened far beyond the f32 rounding of the origin and of n1, n2 and
    /// beyond the certified search's own widening of it (1e-5 of the ranges along n1 and
    /// n2), so that no box is left out that a ray or the search could use.
    fn meets(self, rel: V4, half: V4, u: &Uniforms) -> bool {
        let along = |n: V4| -> (f64, f64) {
            let q: f64 = (0..4).map(|i| f64::from(rel[i]) * f64::from(n[i])).sum();
            let r: f64 = (0..4)
                .map(|i| f64::from(half[i]) * f64::from(n[i]).abs())
                .sum();
            (q, r)
        };
        let ((q1, r1), (q2, r2)) = (along(u.n1), along(u.n2));
        let slack = 1e-4 * (q1.abs() + r1 + q2.abs() + r2 + self.lo.abs() + self.hi.abs()) + 1e-6;
        q2 - r2 <= self.hi + slack && q2 + r2 >= self.lo - slack
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
    boxes_of(h[0], u, o, Band::of(u, true), boxes);
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
        boxes_of(h[1], u, plane, Band::of(u, false), &mut scratch.covered);
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

#[cfg(test)]
mod tests {
    use super::*;
    use bytemuck::Zeroable;

    /// A slice's band keeps every box whose range along n2 reaches the slice, and leaves
    /// out those beyond it; from the slice's line (in its hyperplane) the band is 0.
    #[test]
    fn a_section_s_band_leaves_out_only_boxes_that_cannot_meet_it() {
        let mut u = Uniforms::zeroed();
        u.n1 = [0.6, 0.8, 0.0, 0.0];
        u.n2 = [0.0, 0.0, 0.6, 0.8];
        u.control.flags = FLAG_SLICE;
        u.root.section_offset = 0.5;
        let band = Band::of(&u, false).expect("a slice has a band");
        // A box's range along n2 is its centre's ± 0.14 (0.1 · (0.6 + 0.8)).
        let half = [0.1; 4];
        let at = |q2: f32| [0.0, 0.0, 0.6 * q2, 0.8 * q2];
        for q2 in [0.36, 0.5, 0.64] {
            assert!(band.meets(at(q2), half, &u), "{q2}");
        }
        for q2 in [0.3, 0.7, -0.5] {
            assert!(!band.meets(at(q2), half, &u), "{q2}");
        }
        let line = Band::of(&u, true).expect("a slice has a band");
        assert!(line.meets(at(0.1), half, &u) && !line.meets(at(0.2), half, &u));
        u.control.flags = 0;
        assert!(Band::of(&u, false).is_none());
    }
}
