//! One pixel of the CPU twin: its rays through the observer plane, the march of each across
//! the boxes it meets, the roots found on it, and the shading of the nearest hits, step for
//! step as `templates/raycast.wgsl` does them (but for the roots' steps: `root`).

use crate::formula::CompiledFormula;
use crate::render::view::{
    FLAG_CERTIFIED, FLAG_RANDOM, FLAG_SLAB, FLAG_SLICE, PLANE_ROOT, Uniforms, plane_ray_dir,
    slope_along,
};
use crate::tree::Curvature;

use super::certify::SignChange;
use super::evals::{Deferred, Evaluators};
use super::march::{Along, Crossing, March, Skips, Stretch, same_side};
use super::root::{self, RootSearch};
use super::shading::{V4, add, clip_to_slab, dot, rand01, scale, slope, sub};

/// The ray index of a hit along the ray aimed through a certified root (the shader's
/// `AIMED`).
pub(super) const AIMED: u32 = u32::MAX;

/// How many of the rays' closest samples the search between the rays starts from (the
/// shader's SEEK_STARTS).
const SEEK_STARTS: usize = 4;

pub(super) struct Pixel<'a, 'e> {
    pub(super) u: &'a Uniforms,
    pub(super) formula: &'a CompiledFormula,
    pub(super) params: &'a [f64],
    pub(super) eval: &'e mut Evaluators,
    pub(super) seed: u32,
    pub(super) offset: f32,
    /// The nearest hits so far, (t, ray), nearest first (at most `k_max`).
    pub(super) hits: &'e mut Vec<(f32, u32)>,
    pub(super) k_max: usize,
    /// Where a slice's roots are sought later, all of a tile's together (see
    /// `tile::draw_tile`), the sign changes found so far, in the order found; their hits
    /// hold the brackets' far ends meanwhile. Only while the hits are not full, when no
    /// step of the march reads them (`full`): the one that would fill them first finds
    /// these roots, one by one, and puts their hits where they go.
    pub(super) deferred: Option<&'e mut Vec<Deferred>>,
    /// The direction of ray AIMED in (n1, n2).
    pub(super) aim: [f32; 2],
    /// With certification: the pixel's origin in its observer plane, and the first sign
    /// change a ray found, its two ends' (s, t) there (as the shader's `bracket`) and the
    /// march's samples at them.
    pub(super) plane: V4,
    pub(super) bracket: Option<SignChange>,
    /// The sample of the ray being marched, over its span in the box, that M may be nearest:
    /// its (s, t) in the observer plane and |F| over |∇F| there (the shader's `closest`).
    pub(super) closest: ([f32; 2], f32),
    /// A slice's stretches of the line, in its tile's boxes, on which F keeps one sign
    /// (each [`Marched`] box says which are its; empty where there are none).
    pub(super) one_signed: &'a [Stretch],
    /// The closest samples of the spans the rays marched, the nearest [`SEEK_STARTS`] by
    /// |F| over |∇F|, nearest first (+∞: none): where the search between the rays starts
    /// (the shader's `starts`).
    pub(super) starts: [([f32; 2], f32); SEEK_STARTS],
}

/// A box the pixel marches, as `trace_box` takes it.
#[derive(Clone, Copy)]
pub(super) struct Marched {
    pub(super) lo: V4,
    pub(super) hi: V4,
    pub(super) steps: u32,
    pub(super) slope: V4,
    pub(super) curvature: Curvature,
    /// Its node in the hierarchy walked (None: brute force's domain).
    pub(super) node: Option<usize>,
    /// The range of the pixel's [`Pixel::one_signed`] stretches that lie in this box, and
    /// for a slice its bounds along the rays, worked out for its tile.
    pub(super) one_signed: (u32, u32),
    pub(super) along: Option<Along>,
}

impl<'a, 'e> Pixel<'a, 'e> {
    /// A pixel whose plane starts at `plane` and whose rays take `seed` and `offset`, with
    /// a worker's evaluators, its hits so far and a slice's tile's one-signed stretches;
    /// no bracket, no roots left for later.
    pub(super) fn new(
        (u, formula, params): (&'a Uniforms, &'a CompiledFormula, &'a [f64]),
        (eval, hits): (&'e mut Evaluators, &'e mut Vec<(f32, u32)>),
        one_signed: &'a [Stretch],
        plane: V4,
        (seed, offset): (u32, f32),
    ) -> Self {
        Self {
            u,
            formula,
            params,
            eval,
            seed,
            offset,
            hits,
            k_max: hits_kept(u),
            deferred: None,
            aim: [1.0, 0.0],
            plane,
            bracket: None,
            closest: ([0.0; 2], f32::INFINITY),
            one_signed,
            starts: [([0.0; 2], f32::INFINITY); SEEK_STARTS],
        }
    }
}

impl Pixel<'_, '_> {
    pub(super) fn f(&mut self, p: V4) -> f32 {
        let p = p.map(f64::from);
        self.eval.f.eval(&self.formula.tape_f, p, self.params) as f32
    }

    /// F and ∇F at `p`, in f32.
    pub(super) fn f_grad(&mut self, p: V4) -> (f32, V4) {
        let mut out = [0.0; 5];
        self.eval.all.eval_into(
            &self.formula.tape_all,
            p.map(f64::from),
            self.params,
            &mut out,
        );
        (out[0] as f32, std::array::from_fn(|k| out[k + 1] as f32))
    }

    /// F and dF/dt at `p` along `d` (dF/dt only if `bent`: else 0, unused).
    pub(super) fn f_slope(&mut self, p: V4, d: V4, bent: bool) -> [f32; 2] {
        if !bent {
            return [self.f(p), 0.0];
        }
        if let Some((along, eval)) = &mut self.eval.along {
            let mut out = [0.0; 2];
            eval.eval_into(&along.tape, p.map(f64::from), self.params, &mut out);
            return [out[0] as f32, along.slope(out[1], d)];
        }
        let (f, g) = self.f_grad(p);
        [f, slope(g, d)]
    }

    /// Whether the march keeps its closest sample: only the search between the rays reads
    /// it, which neither a slice nor brute force makes.
    fn keeps_closest(&self) -> bool {
        !self.slice() && !self.u.brute_force()
    }

    /// The march's sample at `p`, t along `d` (whose direction in the plane is `along`): F
    /// and dF/dt (see [`Self::f_slope`]), kept as the closest where it may be; one
    /// evaluation of F and ∇F for both, as the shader's `sample`.
    fn sample(&mut self, p: V4, t: f32, d: V4, along: [f32; 2], bent: bool) -> [f32; 2] {
        if !self.keeps_closest() {
            return self.f_slope(p, d, bent);
        }
        let (f, g) = self.f_grad(p);
        self.keep_closest(f, g, t, along);
        [f, if bent { slope(g, d) } else { 0.0 }]
    }

    pub(super) fn dir2(&self, k: u32) -> [f32; 2] {
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

    pub(super) fn direction(&self, k: u32) -> V4 {
        if self.slice() {
            return self.u.n1;
        }
        let d = self.plane_dir(k);
        add(scale(self.u.n1, d[0]), scale(self.u.n2, d[1]))
    }

    /// Ray k's direction in (n1, n2), ray AIMED's and those of roots found between the rays
    /// included.
    pub(super) fn plane_dir(&self, k: u32) -> [f32; 2] {
        if k == AIMED {
            self.aim
        } else if k & PLANE_ROOT != 0 {
            plane_ray_dir(k)
        } else {
            self.dir2(k)
        }
    }

    /// The plane's point where F changes sign between `a` (F > 0) and `b` (F < 0), by 24
    /// bisections in f32 (as the shader's `cert_root`: for shading; the root is proved).
    pub(super) fn root_between(&mut self, o: V4, a: [f64; 2], b: [f64; 2]) -> [f32; 2] {
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

    pub(super) fn slice(&self) -> bool {
        self.u.control.flags & FLAG_SLICE != 0
    }

    pub(super) fn insert(&mut self, t: f32, ray: u32) {
        insert_hit(self.hits, self.k_max, t, ray);
    }

    /// Finds the deferred roots now, one by one, and puts their hits where they go (in
    /// place of their brackets' far ends).
    fn find_deferred(&mut self) {
        let Some(deferred) = self.deferred.as_deref_mut() else {
            return;
        };
        if deferred.is_empty() {
            return;
        }
        let mut roots = std::mem::take(deferred);
        self.hits.clear();
        for r in &roots {
            let root = r.search.finish(|t| self.f(add(r.o, scale(r.d, t))));
            self.insert(root, r.ray);
        }
        roots.clear();
        if let Some(deferred) = self.deferred.as_deref_mut() {
            *deferred = roots;
        }
    }

    /// Keeps the sample with value `f` and gradient `g`, t along the ray whose direction in
    /// the plane is `along`, if M may be nearer it than the closest so far: by |F| over |∇F|
    /// in the plane (the shader's `keep_closest`).
    fn keep_closest(&mut self, f: f32, g: V4, t: f32, along: [f32; 2]) {
        let (gs, gt) = (dot(g, self.u.n1), dot(g, self.u.n2));
        let away = f.abs() / (gs * gs + gt * gt).sqrt();
        if away < self.closest.1 {
            self.closest = ([t * along[0], t * along[1]], away);
        }
    }

    /// Keeps the closest sample of a ray's span among the starts of the search, if it is
    /// among the nearest (the shader's `keep_start`: a new one goes after those as near).
    fn keep_start(&mut self) {
        let start = self.closest;
        if let Some(at) = self.starts.iter().position(|kept| start.1 < kept.1) {
            self.starts.copy_within(at..SEEK_STARTS - 1, at + 1);
            self.starts[at] = start;
        }
    }

    /// The root of F on p + t d in [lo, hi], where F changes sign from `f_lo` to `f_hi`
    /// (`root::refine`; the shader's `bisect` takes more steps to the same tolerance).
    pub(super) fn refine_root(
        &mut self,
        p: V4,
        d: V4,
        bracket: (f32, f32),
        ends: (f32, f32),
    ) -> f32 {
        let (iters, approximation) = (self.u.control.bisection_iters, self.u.root.approximation);
        root::refine(
            |t| self.f(add(p, scale(d, t))),
            bracket,
            ends,
            iters,
            approximation,
        )
    }

    /// Marches `march` to its end, a sample at a time; the span's closest sample is a
    /// start of the search.
    fn find_roots(&mut self, mut march: March) {
        self.closest = ([0.0; 2], f32::INFINITY);
        let (o, d, bent) = (march.o, march.d, march.bent);
        let along = [dot(d, self.u.n1), dot(d, self.u.n2)];
        while let Some(t) = march.next(self.stop(), self.one_signed) {
            let sample = self.sample(add(o, scale(d, t)), t, d, along, bent);
            if let Some(crossing) = march.take(t, sample) {
                let f_ta = self.f_at_start(&march, &crossing);
                self.cross(&march, crossing, f_ta);
            }
        }
        if self.keeps_closest() {
            self.keep_start();
        }
    }

    /// Where a march stops: at the farthest hit where the hits are full (+∞: nowhere).
    pub(super) fn stop(&self) -> f32 {
        stop_at(self.hits, self.k_max)
    }

    /// F at the near end of the sign change `c` that `march` found: the root's steps need
    /// its value, of which a skip kept the sign only.
    fn f_at_start(&mut self, march: &March, c: &Crossing) -> f32 {
        if c.fresh {
            c.fa
        } else {
            self.f(add(march.o, scale(march.d, c.ta)))
        }
    }

    /// A sign change `march` found, F at its near end being `f_ta` (see
    /// [`Self::f_at_start`]): the pixel's bracket, if it has none and is certified, and the
    /// root, found now or left for later (see [`Self::deferred`]), as a hit.
    pub(super) fn cross(&mut self, march: &March, c: Crossing, f_ta: f32) {
        let (o, d, ray) = (march.o, march.d, march.ray);
        let (pa, pb) = (add(o, scale(d, c.ta)), add(o, scale(d, c.tb)));
        if self.u.control.flags & FLAG_CERTIFIED != 0 && self.bracket.is_none() {
            let at = |p: V4| {
                let p = sub(p, self.plane);
                [f64::from(dot(p, self.u.n1)), f64::from(dot(p, self.u.n2))]
            };
            self.bracket = Some(SignChange {
                ends: [at(pa), at(pb)],
                samples: Some([(pa, f_ta), (pb, c.fb)]),
            });
        }
        let f_lo = if same_side(c.fa, f_ta) { f_ta } else { c.fa };
        let defer = self.hits.len() + 1 < self.k_max;
        match self.deferred.as_deref_mut().filter(|_| defer) {
            Some(deferred) => {
                let (iters, approximation) =
                    (self.u.control.bisection_iters, self.u.root.approximation);
                let search = RootSearch::new((c.ta, c.tb), (f_lo, c.fb), iters, approximation);
                deferred.push(Deferred { search, o, d, ray });
                self.insert(c.tb, ray);
            }
            None => {
                self.find_deferred();
                let root = self.refine_root(o, d, (c.ta, c.tb), (f_lo, c.fb));
                self.insert(root, ray);
            }
        }
    }

    /// Tries every ray in the box [lo, hi], over which `slope` bounds |∂F/∂x_k| (+∞: no
    /// bound) and `curvature` F's second derivatives.
    pub(super) fn trace_box(&mut self, o: V4, b: &Marched) {
        let rays = if self.slice() { 1 } else { self.u.size.rays };
        for k in 0..rays {
            self.trace_ray(o, b, k);
        }
    }

    /// Marches ray k (or AIMED) over its span in the box `b`.
    pub(super) fn trace_ray(&mut self, o: V4, b: &Marched, k: u32) {
        if let Some(march) = self.march_of(o, b, k) {
            self.find_roots(march);
        }
    }

    /// The march of ray k (or AIMED) over its span in the box `b`, if it has one that
    /// starts before the march would stop.
    pub(super) fn march_of(&self, o: V4, b: &Marched, k: u32) -> Option<March> {
        let Marched {
            lo,
            hi,
            steps,
            slope,
            curvature,
            one_signed,
            along,
            ..
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
        let (slope, bend) = match along {
            Some(a) if self.slice() => (a.slope, a.bend),
            _ => (
                slope_along(slope, d.map(f64::from)),
                curvature.along(d.map(f64::from)),
            ),
        };
        let skips = Skips {
            steps,
            slope,
            bend,
            one_signed,
        };
        (t0 < t1 && t0 < self.stop()).then(|| March::new(o, d, (t0, t1), skips, k))
    }
}

/// How many hits a pixel keeps, nearest first (as the shader's: 1 to 16).
pub(super) fn hits_kept(u: &Uniforms) -> usize {
    u.size.hits.clamp(1, 16) as usize
}

/// Where a march stops with `hits` (nearest first, at most `k_max`): at the farthest where
/// they are full (+∞: nowhere).
pub(super) fn stop_at(hits: &[(f32, u32)], k_max: usize) -> f32 {
    match hits.last() {
        Some(&(t, _)) if hits.len() == k_max => t,
        _ => f32::INFINITY,
    }
}

/// Inserts the hit (t, ray) into `hits` (nearest first, at most `k_max`): after those as
/// near, the farthest dropped where they are full.
pub(super) fn insert_hit(hits: &mut Vec<(f32, u32)>, k_max: usize, t: f32, ray: u32) {
    let full = hits.len() == k_max;
    if full && t >= hits.last().map_or(f32::INFINITY, |h| h.0) {
        return;
    }
    if full {
        hits.pop();
    }
    let at = hits.partition_point(|h| h.0 <= t);
    hits.insert(at, (t, ray));
}
