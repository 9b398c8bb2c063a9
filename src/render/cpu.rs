//! The CPU reference ray caster: the method of `templates/raycast.wgsl`, step for step, in
//! Rust (f32 geometry like the GPU, F evaluated in f64 by the point evaluator). Same
//! hierarchy, same uniforms, same hash and sampling, so GPU and CPU pictures can be compared.

use rayon::prelude::*;

use crate::eval::PointEvaluator;
use crate::formula::CompiledFormula;
use crate::tree::{Curvature, Hierarchy};

use super::certify::{Certifier, Verdict};
use super::march::{march_steps, slope_along};

use super::uniforms::{
    FLAG_BORDER, FLAG_CERTIFIED, FLAG_HATCH, FLAG_HIDDEN, FLAG_LIGHTING, FLAG_MARK, FLAG_RANDOM,
    FLAG_SILHOUETTE, FLAG_SLAB, FLAG_SLICE, Uniforms,
};

type V4 = [f32; 4];

/// The ray index of a hit along the ray aimed through a certified root (the shader's
/// `AIMED`).
const AIMED: u32 = u32::MAX;

/// Undecided pixels' colour (as the shader's `UNDECIDED_COLOR`).
const UNDECIDED_COLOR: [f32; 3] = [1.0, 0.0, 1.0];

/// The colour of the hits where a slice cuts (as the shader's `MARK_COLOR`).
const MARK_COLOR: [f32; 3] = [1.0, 0.35, 0.1];

/// Nine samples of the viridis colour map, 0 to 255 (as the shader's `viridis`).
const VIRIDIS: [[f32; 3]; 9] = [
    [68.0, 1.0, 84.0],
    [71.0, 45.0, 123.0],
    [59.0, 82.0, 139.0],
    [44.0, 114.0, 142.0],
    [33.0, 145.0, 140.0],
    [40.0, 174.0, 128.0],
    [94.0, 201.0, 98.0],
    [173.0, 220.0, 48.0],
    [253.0, 231.0, 37.0],
];

/// The viridis colour map at t in [0, 1], linear between its samples.
pub fn viridis(t: f32) -> [f32; 3] {
    let x = t.clamp(0.0, 1.0) * 8.0;
    let i = (x as usize).min(7);
    let f = x - i as f32;
    std::array::from_fn(|c| (VIRIDIS[i][c] + (VIRIDIS[i + 1][c] - VIRIDIS[i][c]) * f) / 255.0)
}

/// The colour of a hit at p before lighting, as the shader's `base_color`.
fn base_color(u: &Uniforms, p: V4) -> [f32; 3] {
    if u.control.flags & FLAG_HIDDEN == 0 {
        return [u.surface[0], u.surface[1], u.surface[2]];
    }
    let centre: V4 = std::array::from_fn(|i| 0.5 * (u.domain_lo[i] + u.domain_hi[i]));
    let (lo, hi) = (u.hidden.lo, u.hidden.hi);
    viridis((dot(sub(p, centre), u.n2) - lo) / (hi - lo))
}

/// The part of a ray's span within the slab, as the shader's `clip_to_slab`.
fn clip_to_slab(u: &Uniforms, (t0, t1): (f32, f32), b: f32) -> (f32, f32) {
    let lo = u.root.section_offset - u.root.section_half;
    let hi = u.root.section_offset + u.root.section_half;
    if b.abs() < 1e-30 {
        return if lo <= 0.0 && 0.0 <= hi {
            (t0, t1)
        } else {
            (1.0, 0.0)
        };
    }
    let (ta, tb) = (lo / b, hi / b);
    (t0.max(ta.min(tb)), t1.min(ta.max(tb)))
}

/// The pixel's offset of its stratified rays in a frame, as the shader's `fs_main`: the
/// frame's turn (the radical inverse of the frame) added to the pixel's own offset, so that
/// successive frames' pencils interleave.
fn stratified_offset(seed: u32, frame: u32, px: u32, py: u32) -> f32 {
    let base = pcg(px.wrapping_add(pcg(py.wrapping_add(pcg(seed)))));
    let turn = frame.reverse_bits() as f32 * 2f32.powi(-32);
    let x = rand01(base ^ 0x9e37_79b9) + turn;
    x - x.floor()
}

fn dot(a: V4, b: V4) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]
}
fn add(a: V4, b: V4) -> V4 {
    std::array::from_fn(|i| a[i] + b[i])
}
fn sub(a: V4, b: V4) -> V4 {
    std::array::from_fn(|i| a[i] - b[i])
}
fn scale(a: V4, s: f32) -> V4 {
    a.map(|v| v * s)
}

fn pcg(v: u32) -> u32 {
    let state = v.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

fn rand01(v: u32) -> f32 {
    (pcg(v) >> 8) as f32 / 16_777_216.0
}

struct Pixel<'a> {
    u: &'a Uniforms,
    formula: &'a CompiledFormula,
    params: &'a [f64],
    eval: PointEvaluator,
    seed: u32,
    offset: f32,
    hits: Vec<(f32, u32)>,
    k_max: usize,
    /// The direction of ray AIMED in (n1, n2).
    aim: [f32; 2],
    /// With certification: the pixel's origin in its observer plane, and the first sign
    /// change a ray found as its two ends' (s, t) there (as the shader's `bracket`).
    plane: V4,
    bracket: Option<([f64; 2], [f64; 2])>,
}

/// A box the pixel marches, as `trace_box` takes it.
#[derive(Clone, Copy)]
struct Marched {
    lo: V4,
    hi: V4,
    steps: u32,
    slope: V4,
    curvature: Curvature,
}

impl Pixel<'_> {
    fn f(&mut self, p: V4) -> f32 {
        let p = p.map(f64::from);
        self.eval.eval(&self.formula.tape_f, p, self.params) as f32
    }

    /// F and dF/dt at `p` along `d` (dF/dt only if `bent`: else 0, unused).
    fn f_slope(&mut self, p: V4, d: V4, bent: bool) -> [f32; 2] {
        if !bent {
            return [self.f(p), 0.0];
        }
        let mut out = [0.0; 5];
        let p = p.map(f64::from);
        self.eval
            .eval_into(&self.formula.tape_all, p, self.params, &mut out);
        let g = (0..4).map(|k| out[k + 1] * f64::from(d[k])).sum::<f64>();
        [out[0] as f32, g as f32]
    }

    fn dir2(&self, k: u32) -> [f32; 2] {
        let n = self.u.size.rays;
        if self.u.control.flags & FLAG_RANDOM != 0 {
            let a = [
                2.0 * rand01(self.seed.wrapping_add(2 * k)) - 1.0,
                2.0 * rand01(self.seed.wrapping_add(2 * k + 1)) - 1.0,
            ];
            let len = (a[0] * a[0] + a[1] * a[1]).sqrt();
            if len < 1e-6 {
                return [1.0, 0.0];
            }
            return [a[0] / len, a[1] / len];
        }
        let phi = std::f32::consts::TAU * (k as f32 + self.offset) / n as f32;
        [phi.cos(), phi.sin()]
    }

    fn direction(&self, k: u32) -> V4 {
        if self.slice() {
            return self.u.n1;
        }
        let d = self.plane_dir(k);
        add(scale(self.u.n1, d[0]), scale(self.u.n2, d[1]))
    }

    /// Ray k's direction in (n1, n2), ray AIMED's included.
    fn plane_dir(&self, k: u32) -> [f32; 2] {
        if k == AIMED { self.aim } else { self.dir2(k) }
    }

    /// The plane's point where F changes sign between `a` (F > 0) and `b` (F < 0), by 24
    /// bisections in f32 (as the shader's `cert_root`: for shading; the root is proved).
    fn root_between(&mut self, o: V4, a: [f64; 2], b: [f64; 2]) -> [f32; 2] {
        let (mut pa, mut pb) = (a.map(|v| v as f32), b.map(|v| v as f32));
        let point = |m: [f32; 2]| add(o, add(scale(self.u.n1, m[0]), scale(self.u.n2, m[1])));
        for _ in 0..24 {
            let m = [0.5 * (pa[0] + pb[0]), 0.5 * (pa[1] + pb[1])];
            if self.f(point(m)) > 0.0 {
                pa = m;
            } else {
                pb = m;
            }
        }
        [0.5 * (pa[0] + pb[0]), 0.5 * (pa[1] + pb[1])]
    }

    fn slice(&self) -> bool {
        self.u.control.flags & FLAG_SLICE != 0
    }

    fn full(&self) -> bool {
        self.hits.len() == self.k_max
    }

    fn farthest(&self) -> f32 {
        self.hits.last().map_or(f32::INFINITY, |h| h.0)
    }

    fn insert(&mut self, t: f32, ray: u32) {
        if self.full() && t >= self.farthest() {
            return;
        }
        if self.full() {
            self.hits.pop();
        }
        let at = self.hits.partition_point(|h| h.0 <= t);
        self.hits.insert(at, (t, ray));
    }

    /// Marches o + t d over [t0, t1] in `steps` equal steps (docs/method.md §5.3), stepping over
    /// the samples that cannot change sign when `slope` bounds |dF/dt| or `bend` bounds
    /// d²F/dt² (as the shader's `march_ray`: the same sign changes as taking every sample;
    /// +∞ and (−∞, +∞) take every sample).
    #[allow(clippy::too_many_arguments)]
    fn find_roots(
        &mut self,
        o: V4,
        d: V4,
        (t0, t1): (f32, f32),
        steps: u32,
        slope: f32,
        bend: (f32, f32),
        ray: u32,
    ) {
        let dt = (t1 - t0) / steps as f32;
        // Samples per unit of t and per unit of |F| sure to keep its sign (0.999: a margin
        // for rounding).
        let per_t = 0.999 / dt;
        let reach = per_t / slope;
        // (dF/dt serves only the curvature bound.)
        let bent = bend.0.is_finite() && bend.1.is_finite();
        let mut ta = t0;
        let [mut fa, mut ga] = self.f_slope(add(o, scale(d, ta)), d, bent);
        let mut s = 1;
        loop {
            let m = fa.abs() * reach;
            let m = m.max(zero_ahead(fa, ga, bend) * per_t);
            if m >= 1.0 {
                s += m.min(steps as f32) as u32;
                ta = t0 + (s - 1) as f32 * dt;
            }
            if s > steps || (self.full() && ta >= self.farthest()) {
                return;
            }
            let tb = t0 + s as f32 * dt;
            let [fb, gb] = self.f_slope(add(o, scale(d, tb)), d, bent);
            if fa * fb <= 0.0 && !(fa == 0.0 && fb == 0.0) {
                if self.u.control.flags & FLAG_CERTIFIED != 0 && self.bracket.is_none() {
                    let at = |t: f32| {
                        let p = sub(add(o, scale(d, t)), self.plane);
                        [f64::from(dot(p, self.u.n1)), f64::from(dot(p, self.u.n2))]
                    };
                    self.bracket = Some((at(ta), at(tb)));
                }
                let (mut lo, mut hi) = (ta, tb);
                // F(lo) stays on fa's side of 0 (as the shader: its sign is not carried).
                let neg_lo = fa < 0.0;
                let mut tm = 0.5 * (lo + hi);
                for _ in 0..self.u.control.bisection_iters {
                    tm = 0.5 * (lo + hi);
                    // As the shader: f32 cannot split the bracket, every further midpoint
                    // is this one.
                    if tm == lo || tm == hi {
                        break;
                    }
                    let fm = self.f(add(o, scale(d, tm)));
                    if fm.abs() < self.u.root.approximation {
                        break;
                    }
                    if (fm < 0.0) == neg_lo {
                        lo = tm;
                    } else {
                        hi = tm;
                    }
                }
                self.insert(tm, ray);
            }
            ta = tb;
            fa = fb;
            ga = gb;
            s += 1;
        }
    }

    /// Tries every ray in the box [lo, hi], over which `slope` bounds |∂F/∂x_k| (+∞: no
    /// bound) and `curvature` F's second derivatives.
    fn trace_box(&mut self, o: V4, b: &Marched) {
        let rays = if self.slice() { 1 } else { self.u.size.rays };
        for k in 0..rays {
            self.trace_ray(o, b, k);
        }
    }

    /// Marches ray k (or AIMED) over its span in the box `b`.
    fn trace_ray(&mut self, o: V4, b: &Marched, k: u32) {
        let Marched {
            lo,
            hi,
            steps,
            slope,
            curvature,
        } = *b;
        let d = self.direction(k);
        let (mut t0, mut t1) = (0.0f32, f32::INFINITY);
        for i in 0..4 {
            let di = if d[i].abs() < 1e-30 { 1e-30 } else { d[i] };
            let inv = 1.0 / di;
            let (ta, tb) = ((lo[i] - o[i]) * inv, (hi[i] - o[i]) * inv);
            t0 = t0.max(ta.min(tb));
            t1 = t1.min(ta.max(tb));
        }
        if self.u.control.flags & FLAG_SLAB != 0 {
            (t0, t1) = clip_to_slab(self.u, (t0, t1), self.plane_dir(k)[1]);
        }
        if t0 < t1 && !(self.full() && t0 >= self.farthest()) {
            let along = slope_along(slope, d.map(f64::from));
            let bend = curvature.along(d.map(f64::from));
            self.find_roots(o, d, (t0, t1), steps, along, bend, k);
        }
    }

    fn shade(&mut self, p: V4, d: V4) -> [f32; 3] {
        let u = self.u;
        let mut all = [0.0; 5];
        self.eval.eval_into(
            &self.formula.tape_all,
            p.map(f64::from),
            self.params,
            &mut all,
        );
        let mut g: V4 = [all[1] as f32, all[2] as f32, all[3] as f32, all[4] as f32];
        if self.slice() {
            // The slice is a surface in the hyperplane: its normal is ∇F within it.
            g = sub(g, scale(u.n2, dot(g, u.n2)));
        }
        let glen = dot(g, g).sqrt();
        let flags = u.control.flags;
        let rgb = |c: V4| [c[0], c[1], c[2]];
        if flags & FLAG_SILHOUETTE != 0 && glen > 0.0 {
            let gu = scale(g, 1.0 / glen);
            if dot(gu, u.n1).abs() < u.misc.silhouette_tolerance
                && dot(gu, u.n2).abs() < u.misc.silhouette_tolerance
            {
                return rgb(u.silhouette_color);
            }
        }
        if flags & FLAG_BORDER != 0 {
            let inside = (0..4)
                .map(|i| (p[i] - u.domain_lo[i]).min(u.domain_hi[i] - p[i]))
                .fold(f32::INFINITY, f32::min);
            if inside < u.misc.border_tolerance {
                return rgb(u.border_color);
            }
        }
        if flags & FLAG_MARK != 0 {
            let centre: V4 = std::array::from_fn(|i| 0.5 * (u.domain_lo[i] + u.domain_hi[i]));
            if (dot(sub(p, centre), u.n2) - u.root.section_offset).abs() < u.root.section_half {
                return MARK_COLOR;
            }
        }
        let surface = base_color(u, p);
        if flags & FLAG_LIGHTING == 0 {
            return surface;
        }
        let mut n = if glen > 0.0 {
            scale(g, 1.0 / glen)
        } else {
            [0.0; 4]
        };
        if dot(n, d) > 0.0 {
            n = scale(n, -1.0);
        }
        let l = u.light;
        let diffuse = dot(n, l).max(0.0);
        let r = sub(scale(n, 2.0 * dot(n, l)), l);
        let specular = dot(r, scale(d, -1.0)).max(0.0).powf(u.shading.shininess);
        std::array::from_fn(|i| {
            surface[i] * (u.shading.ambient + u.shading.diffuse * diffuse)
                + u.shading.specular * specular
        })
    }
}

/// How far from a sample with value `f` and slope `g` (dF/dt) F surely keeps its sign when
/// d²F/dt² lies in `bend`: the first zero of the parabola that bounds |F| from below
/// (+∞: none; 0 where F, its slope or the bound is not finite). The shader's rule (`march_ray`).
fn zero_ahead(f: f32, g: f32, (lo, hi): (f32, f32)) -> f32 {
    // |F|, its slope, and how fast it can bend towards 0.
    let (g, c) = if f > 0.0 { (g, -lo) } else { (-g, hi) };
    let f = f.abs();
    if !(f.is_finite() && g.is_finite() && c.is_finite()) {
        return 0.0;
    }
    let disc = g * g + 2.0 * c * f;
    let root = disc.max(0.0).sqrt();
    if disc >= 0.0 && root > g {
        2.0 * f / (root - g)
    } else {
        f32::INFINITY
    }
}

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
    let (width, height) = (u.size.width, u.size.height);
    let rows: Vec<Vec<u8>> = (0..height)
        .into_par_iter()
        .map(|py| {
            let mut certifier = Certifier::new(formula, params, u);
            let mut row = Vec::with_capacity(width as usize * 4);
            for px in 0..width {
                let pixel = (px, py);
                let (c, verdict) = render_pixel(
                    formula,
                    params,
                    [hierarchy, certifying],
                    u,
                    &mut certifier,
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

/// The boxes pixel `o`'s rays march (or, for `certifying`'s hierarchy, its certified search
/// covers): a walk of the hierarchy's marched boxes whose sphere meets its observer plane
/// (the shader's MODE 2), or the domain for brute force.
fn boxes_of(h: &Hierarchy, u: &Uniforms, o: V4) -> Vec<Marched> {
    if u.brute_force() {
        return vec![Marched {
            lo: u.domain_lo,
            hi: u.domain_hi,
            steps: u.counts.brute_steps,
            slope: [f32::INFINITY; 4],
            curvature: Curvature::NONE,
        }];
    }
    let mut boxes = Vec::new();
    let mut i = 0usize;
    while i < h.nodes.len() {
        let node = &h.nodes[i];
        let level = &u.levels[node.level() as usize];
        let rel = sub(node.center, o);
        let (a, b) = (dot(rel, u.v1), dot(rel, u.v2));
        if a * a + b * b > level.radius * level.radius {
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
            });
            i = node.skip as usize;
            continue;
        }
        i += 1;
    }
    boxes
}

/// A pixel's colour and verdict; `h` holds the hierarchy the rays march and the one the
/// certified search covers.
fn render_pixel(
    formula: &CompiledFormula,
    params: &[f64],
    h: [&Hierarchy; 2],
    u: &Uniforms,
    certifier: &mut Certifier<'_>,
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
        eval: PointEvaluator::new(),
        seed,
        offset: stratified_offset(u.control.seed, u.counts.frame, px, py),
        hits: Vec::with_capacity(16),
        k_max: u.size.hits.clamp(1, 16) as usize,
        aim: [1.0, 0.0],
        plane,
        bracket: None,
    };
    let boxes = boxes_of(h[0], u, o);
    for b in &boxes {
        pixel.trace_box(o, b);
    }
    let mut verdict = Verdict::Empty;
    if u.control.flags & FLAG_CERTIFIED != 0 {
        let bounds: Vec<(V4, V4)> = boxes_of(h[1], u, plane)
            .iter()
            .map(|b| (b.lo, b.hi))
            .collect();
        let outcome = certifier.pixel(plane, &bounds, pixel.bracket);
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
                for b in &boxes {
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

/// An undecided pixel with no hit: the marker colour, or its stripes over the background
/// (as the shader's `undecided_color`).
fn undecided_color(u: &Uniforms, px: u32, py: u32) -> [f32; 3] {
    let stripe = ((px + py) / 3).is_multiple_of(2);
    if u.control.flags & FLAG_HATCH != 0 && !stripe {
        [u.background[0], u.background[1], u.background[2]]
    } else {
        UNDECIDED_COLOR
    }
}
