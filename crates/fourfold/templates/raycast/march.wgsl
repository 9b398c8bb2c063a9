// The pixel's work (docs/method.md §5.1-§5.5), as nested loops: candidates (a screen tile's list of
// boxes, a walk of the hierarchy, or for the brute-force baseline the whole domain as one
// box) → the rays that can meet the box → equal steps along the ray → the bisection of a
// sign change. A SIMD rasterizer (llvmpipe) or a GPU runs a loop for a group of pixels
// until none of them needs it, so the loops pay off when the group's pixels do the same
// work at the same time: the pixels of a tile read the same list in the same order, try
// the same rays of each box (by index) and march them with the same step count.
// llvmpipe also runs a loop's body at least once, and runs the rest of an iteration after
// a `break` for the pixels that broke, masked: a loop that tests whether to go on at the
// top of its body pays a masked pass of the whole body when it ends (for the loop over a
// box's rays, a march). So the loops over a tile's boxes, a box's rays and a pixel's hits
// test at the end, inside a branch that skips them on a GPU when there is nothing to do; the
// march's loops stay as they are (both measured: docs/benchmarks.md, "Design choices").
struct Tracer {
    o: vec4<f32>,
    shift: vec2<f32>, // o - u.center along v1 and v2
    pixel_seed: u32,
    offset: f32,
    k_max: u32,
    hits: Hits,
    k: u32, // the ray being marched (for insert_hit)
    plane: vec4<f32>, // the pixel's origin in its observer plane (o but for a slice)
    aim: vec2<f32>, // the ray aimed through a certified root (ray AIMED), in (n1, n2)
    // CERTIFY: the first sign change a ray found, as its two ends' (s, t) in the observer
    // plane (its sign change is then proved, or not, by certify), and whether there is one.
    bracket: vec4<f32>,
    bracketed: bool,
    // The sample of the ray being marched, over its span in the box, that M may be nearest
    // (by |F| over |grad F| in the plane), as its (s, t) there and that ratio (+inf: none).
    closest: vec3<f32>,
    // The closest samples of the spans marched, the nearest four (SEEK_STARTS), nearest
    // first: where seek_in_plane starts. (Four fields, not an array: an array indexed in a
    // loop put the whole Tracer in memory on llvmpipe, a tenth slower a frame.)
    start0: vec3<f32>,
    start1: vec3<f32>,
    start2: vec3<f32>,
    start3: vec3<f32>,
}

// F and dF/dt at o + t d, and |F| over |grad F| in the observer plane, how far M may be (for
// brute force, MODE 0, F alone: it steps over nothing).
fn sample(tr: ptr<function, Tracer>, d: vec4<f32>, t: f32) -> vec3<f32> {
    let p = (*tr).o + t * d;
    if (MODE == 0u) {
        return vec3<f32>(ff_f(p), 0.0, ff_inf());
    }
    let fg = ff_f_grad(p);
    let away = abs(fg.f) / length(vec2<f32>(dot(fg.g, u.n1), dot(fg.g, u.n2)));
    return vec3<f32>(fg.f, dot(fg.g, d), away);
}

// Keeps the sample at (s, t) in the observer plane if M may be nearer it than the closest
// so far (`away`: see sample; NaN is not).
fn keep_closest(tr: ptr<function, Tracer>, st: vec2<f32>, away: f32) {
    (*tr).closest = select((*tr).closest, vec3<f32>(st, away), away < (*tr).closest.z);
}

// Keeps the closest sample of a ray's span among the starts of seek_in_plane, if it is
// among the nearest (a new one goes after those as near).
fn keep_start(tr: ptr<function, Tracer>) {
    let c = (*tr).closest;
    let s0 = (*tr).start0;
    let s1 = (*tr).start1;
    let s2 = (*tr).start2;
    let s3 = (*tr).start3;
    (*tr).start0 = select(s0, c, c.z < s0.z);
    (*tr).start1 = select(s1, select(c, s0, c.z < s0.z), c.z < s1.z);
    (*tr).start2 = select(s2, select(c, s1, c.z < s1.z), c.z < s2.z);
    (*tr).start3 = select(s3, select(c, s2, c.z < s2.z), c.z < s3.z);
}

// The k-th start of seek_in_plane (k < SEEK_STARTS).
fn nth_start(tr: ptr<function, Tracer>, k: u32) -> vec3<f32> {
    return select(select(select((*tr).start3, (*tr).start2, k == 2u), (*tr).start1, k == 1u), (*tr).start0, k == 0u);
}

// Whether F keeps its sign from fa to fb. Signs compared, not multiplied: the product of
// two tiny values of one sign is below f32's normals, which a GPU may flush to 0.
fn same_side(fa: f32, fb: f32) -> bool {
    return !((((fa <= 0.0) & (fb >= 0.0)) | ((fa >= 0.0) & (fb <= 0.0))) & !((fa == 0.0) & (fb == 0.0)));
}

// The root of F on p + t d between lo and hi, where F changes sign (F(lo) < 0 iff neg_lo),
// by bisection (Algorithm 3.1): stop at a tiny |F| or after the set iterations; the last
// midpoint is the root (the middle of the bracket with no iterations). Once f32 cannot
// split the bracket, the midpoint is one of its ends, and every further iteration keeps
// it: stop there (the same root, fewer samples of F). F(lo) keeps its side of 0 (lo moves
// only to a midpoint on that side), so its sign is not carried through the loop.
fn bisect(p: vec4<f32>, d: vec4<f32>, lo0: f32, hi0: f32, neg_lo: bool) -> f32 {
    let iters = u.control.y;
    var lo = lo0;
    var hi = hi0;
    var tm = 0.5 * (lo + hi);
    var it = 0u;
    // (One exit, tested at the end: llvmpipe updates its lane masks at each `break`.)
    if (iters > 0u) {
        loop {
            tm = 0.5 * (lo + hi);
            let split = (tm != lo) & (tm != hi);
            let fm = ff_f(p + tm * d);
            let go = split & !(abs(fm) < u.root.x);
            let keep_lo = (fm < 0.0) == neg_lo;
            lo = select(lo, tm, go & keep_lo);
            hi = select(hi, tm, go & !keep_lo);
            it = it + 1u;
            if (!go | (it >= iters)) {
                break;
            }
        }
    }
    return tm;
}

// Marches the ray o + t d over [t0, t1] in `steps` equal steps, bisecting each sign change
// (Algorithm 3.1) and keeping the root among the K nearest; stops beyond the K kept.
// Except for brute force (MODE 0) the march steps over the samples that cannot differ in
// sign from the last one, by two bounds on the span: `slope` bounds |dF/dt| (+inf or NaN:
// no bound), so none lies within |F| / slope of it; and `bend` bounds d2F/dt2 (see
// bend_in_plane), so from the last sample's F and dF/dt, F stays between two parabolas, and
// none lies before the nearest zero of the one on F's side of 0. That finds the sign
// changes, and so the roots, of the plain march, with fewer samples of F. The span's
// closest sample is kept as a start of seek_in_plane.
fn march_ray(tr: ptr<function, Tracer>, d: vec4<f32>, t0: f32, t1: f32, steps: u32, slope: f32, bend: vec2<f32>) {
    let dt = (t1 - t0) / f32(steps);
    // Samples per unit of t, and per unit of |F| that are sure to keep its sign (with a
    // margin for rounding).
    let per_t = 0.999 / dt;
    let reach = per_t / slope;
    let along = vec2<f32>(dot(d, u.n1), dot(d, u.n2));
    var ta = t0;
    var fa = sample(tr, d, ta);
    (*tr).closest = vec3<f32>(0.0, 0.0, ff_inf());
    keep_closest(tr, ta * along, fa.z);
    var s = 1u;
    loop {
        // March to the next sign change, the span's end, or a point beyond the K kept.
        // (Loops, not branches: a SIMD rasterizer stops a loop once no pixel of the group
        // needs it, but runs a branch's body for all of them whatever its condition.)
        var tb = ta;
        var fb = fa;
        var found = false;
        loop {
            if (MODE != 0u) {
                // Samples s .. s + j - 1 keep fa's sign: the pair to test is (s + j - 1, s + j).
                // |F| from ta on is at least f + g h - c h^2 / 2 (g: its slope at ta, c: how
                // fast it can bend down), which stays above 0 until the parabola's first
                // zero (none: +inf). (NaN or a zero F, or no bounds, give j = 0; where F, its
                // slope or c is not finite, only the slope bound counts.)
                let f = abs(fa.x);
                let g = select(-fa.y, fa.y, fa.x > 0.0);
                let c = select(bend.y, -bend.x, fa.x > 0.0);
                let disc = g * g + 2.0 * c * f;
                let root = sqrt(max(disc, 0.0));
                let finite = (abs(f) < ff_inf()) & (abs(g) < ff_inf()) & (abs(c) < ff_inf());
                let zero = select(0.0, select(ff_inf(), 2.0 * f / (root - g), (disc >= 0.0) & (root > g)), finite);
                let m1 = f * reach;
                let m2 = zero * per_t;
                let m = select(m1, max(m1, m2), m2 == m2);
                let j = select(0u, u32(min(m, f32(steps))), m >= 1.0);
                s = s + j;
                ta = select(ta, t0 + f32(s - 1u) * dt, j > 0u);
            }
            if ((s > steps) | (ta >= (*tr).hits.far)) {
                break;
            }
            tb = t0 + f32(s) * dt;
            fb = sample(tr, d, tb);
            keep_closest(tr, tb * along, fb.z);
            if (!same_side(fa.x, fb.x)) {
                found = true;
                break;
            }
            ta = tb;
            fa = fb;
            s = s + 1u;
        }
        if (!found) {
            break;
        }
        if ((CERTIFY == 1u) & !(*tr).bracketed) {
            let pa = (*tr).o + ta * d - (*tr).plane;
            let pb = (*tr).o + tb * d - (*tr).plane;
            (*tr).bracket = vec4<f32>(dot(pa, u.n1), dot(pa, u.n2), dot(pb, u.n1), dot(pb, u.n2));
            (*tr).bracketed = true;
        }
        insert_hit(tr, bisect((*tr).o, d, ta, tb, fa.x < 0.0));
        // The march goes on from the step's end.
        ta = tb;
        fa = fb;
        s = s + 1u;
    }
    keep_start(tr);
}

// The angle of q (a sphere's centre projected on the observer plane, from o) and the half
// angle its sphere of radius r spans from o, with a margin; -1 where o is within r of q
// (every ray is tried).
fn angles(q: vec2<f32>, r: f32) -> vec2<f32> {
    let dist = length(q);
    let delta = select(-1.0, asin(min(r / max(dist, 1e-30), 1.0)) + 1e-3, dist > r);
    return vec2<f32>(atan2(q.y, q.x), delta);
}

// A box's curvature bounds `c` (binding 4) in the observer plane (fourfold works this out
// on the CPU for the boxes of the tile lists: Curvature::in_plane): each form is the sum
// of H_ij's bounds times its coefficient, widened for f32's rounding.
fn plane_curvature(c: Curvature) -> PlaneCurvature {
    let n1 = u.n1;
    let n2 = u.n2;
    var out: PlaneCurvature;
    var lo = vec3<f32>(0.0);
    var hi = vec3<f32>(0.0);
    var mag = vec3<f32>(0.0);
    // (i, j) in the order of Curvature: xx, yy, zz, ww, xy, xz, xw, yz, yw, zw.
    let hl = array<f32, 10>(c.diag_lo.x, c.diag_lo.y, c.diag_lo.z, c.diag_lo.w, c.off_lo.x, c.off_lo.y, c.off_lo.z, c.off_lo.w, c.rest.x, c.rest.y);
    let hh = array<f32, 10>(c.diag_hi.x, c.diag_hi.y, c.diag_hi.z, c.diag_hi.w, c.off_hi.x, c.off_hi.y, c.off_hi.z, c.off_hi.w, c.rest.z, c.rest.w);
    let pi = array<u32, 10>(0u, 1u, 2u, 3u, 0u, 0u, 0u, 1u, 1u, 2u);
    let pj = array<u32, 10>(0u, 1u, 2u, 3u, 1u, 2u, 3u, 2u, 3u, 3u);
    for (var k = 0u; k < 10u; k = k + 1u) {
        let i = pi[k];
        let j = pj[k];
        let twice = select(2.0, 1.0, i == j);
        let p = twice * vec3<f32>(n1[i] * n1[j], n1[i] * n2[j] + n2[i] * n1[j], n2[i] * n2[j]);
        let l = hl[k] * p;
        let h = hh[k] * p;
        lo = lo + min(l, h);
        hi = hi + max(l, h);
        mag = mag + max(abs(l), abs(h));
    }
    let margin = mag * 1e-5;
    out.ab = vec4<f32>(lo.x - margin.x, hi.x + margin.x, lo.y - margin.y, hi.y + margin.y);
    out.c = vec2<f32>(lo.z - margin.z, hi.z + margin.z);
    return out;
}

// Bounds [lo, hi] on d2F/dt2 along the ray a n1 + b n2 (dir = (a, b)) in a box whose
// curvature in the observer plane is `f`, with a margin for f32's rounding; (-inf, +inf)
// where unbounded.
fn bend_in_plane(f: PlaneCurvature, dir: vec2<f32>) -> vec2<f32> {
    let a2 = dir.x * dir.x;
    let b2 = dir.y * dir.y;
    let ab = dir.x * dir.y;
    let pos = ab >= 0.0;
    let bl = select(f.ab.w, f.ab.z, pos) * ab;
    let bh = select(f.ab.z, f.ab.w, pos) * ab;
    let lo = a2 * f.ab.x + bl + b2 * f.c.x;
    let hi = a2 * f.ab.y + bh + b2 * f.c.y;
    let mag = a2 * max(abs(f.ab.x), abs(f.ab.y)) + max(abs(bl), abs(bh)) + b2 * max(abs(f.c.x), abs(f.c.y));
    let margin = mag * 1e-5 + 1e-30;
    let b = vec2<f32>(lo - margin, hi + margin);
    // 0 * inf (an unbounded box, a ray along n1 or n2) is NaN: no bound.
    return select(vec2<f32>(-ff_inf(), ff_inf()), b, (b.x == b.x) & (b.y == b.y));
}

// Marches ray k, along dir in (n1, n2), over its span in the box [lo, hi] (and the slab).
fn march_through(tr: ptr<function, Tracer>, k: u32, dir: vec2<f32>, lo: vec4<f32>, hi: vec4<f32>, steps: u32, slope: vec4<f32>, form: PlaneCurvature) {
    let d = dir.x * u.n1 + dir.y * u.n2;
    var span = clip_to_box((*tr).o, d, lo, hi);
    if (slab_on()) {
        span = clip_to_slab(span, dir.y);
    }
    if ((span.x < span.y) & (span.x < (*tr).hits.far)) {
        (*tr).k = k;
        march_ray(tr, d, span.x, span.y, steps, dot(abs(d), slope), bend_in_plane(form, dir));
    }
}

// Tries the rays that can meet the box [lo, hi] (its sphere seen at angles `ang` from o,
// see `angles`) and marches each over its span in the box, with the box's bounds (brute
// force, MODE 0, has none: +inf): `slope` bounds |dF/dx|, |dF/dy|, |dF/dz|, |dF/dw| in the
// box, so |grad F . d| <= slope . |d| along a ray d; `form` bounds F's second derivatives
// along the rays of the observer plane (see bend_in_plane).
fn trace_box(tr: ptr<function, Tracer>, lo: vec4<f32>, hi: vec4<f32>, ang: vec2<f32>, steps: u32, slope: vec4<f32>, form: PlaneCurvature) {
    if (slice_on()) {
        // One ray, along n1 from behind the domain (see start_pixel).
        let span = clip_to_box((*tr).o, u.n1, lo, hi);
        if ((span.x < span.y) & (span.x < (*tr).hits.far)) {
            (*tr).k = 0u;
            march_ray(tr, u.n1, span.x, span.y, max(steps, 1u), dot(abs(u.n1), slope), bend_in_plane(form, vec2<f32>(1.0, 0.0)));
        }
        return;
    }
    let n = u.size.z;
    let ni = i32(n);
    // Stratified rays are at angles TAU (k + offset) / n: only the k within the sphere's
    // span are tried. Random rays (or o inside the sphere): all n, each clipped to the box.
    let stratified = !random_rays() & (ang.y >= 0.0);
    let scale = f32(n) / TAU;
    let k0 = i32(ceil((ang.x - ang.y) * scale - (*tr).offset));
    let k1 = i32(floor((ang.x + ang.y) * scale - (*tr).offset));
    let rcount = select(n, u32(clamp(k1 - k0 + 1, 0, ni)), stratified);
    let nsteps = max(steps, 1u);
    // (Tested at the end: see "The pixel's work".)
    var j = 0u;
    if (rcount > 0u) {
        loop {
            // k0 + j wrapped into [0, n) (selects: a SIMD CPU has no vector integer
            // division).
            var kw = k0 + i32(j);
            kw = select(kw, kw + ni, kw < 0);
            kw = select(kw, kw - ni, kw >= ni);
            let k = select(j, u32(kw), stratified);
            march_through(tr, k, ray_dir2(k, n, (*tr).pixel_seed, (*tr).offset), lo, hi, nsteps, slope, form);
            j = j + 1u;
            if (j >= rcount) {
                break;
            }
        }
    }
}

// The half extents of a box at the level in `info` (bits 0-7), as u.levels[level].half,
// computed rather than read (a table read at a varying index costs a gather per component
// on a SIMD rasterizer); and the radius of the sphere around a box, with a margin.
fn level_half(info: u32) -> vec4<f32> {
    let scale = bitcast<f32>((127u - (info & 255u)) << 23u); // 2^-level, exact
    return u.half0 * scale + vec4<f32>(u.root.y);
}

fn sphere_radius(half: vec4<f32>) -> f32 {
    return length(half) * 1.000001;
}

// Whether a box (half extents `half`, sphere radius r) whose centre lies at (a, b) from the
// pixel's origin along v1 and v2 can meet the pixel's observer plane. Its sphere meets the
// plane iff (a, b) is within r: one 2D test for all rays of the pixel. The box itself must
// also reach the pixel along v1 and along v2 (its support).
fn meets_plane(a: f32, b: f32, half: vec4<f32>, r: f32) -> bool {
    let support = vec2<f32>(dot(half, abs(u.v1)), dot(half, abs(u.v2))) * 1.00001;
    return (a * a + b * b <= r * r) & (abs(a) <= support.x) & (abs(b) <= support.y);
}

// The step count for a box: a leaf's (the chapter's m per span), or for a coarser box the
// finest leaves' step length: m 2^(finest - level) per span, at most 2^16.
fn box_steps(info: u32) -> u32 {
    let up = min(u.march.x - min(info & 255u, u.march.x), 16u);
    let coarse = select(65536u, u.control.x << up, u.control.x <= (65536u >> up));
    return select(coarse, u.control.x, (info & LEAF) != 0u);
}

// Tests node i of the hierarchy against the pixel's observer plane and marches it (or, when
// `seeking`, searches it between the rays: seek_in_plane) if it is a box to march (marked
// by fourfold; its subtree, if any, is not kept) that passes. Returns whether it passes,
// and (.y) whether anything in it can be nearer than the K hits kept (nothing in the sphere
// is nearer than |q| - r).
fn visit(tr: ptr<function, Tracer>, i: u32, seeking: bool) -> vec2<bool> {
    let node = nodes[i];
    let c = vec4<f32>(node.cx, node.cy, node.cz, node.cw);
    let half = level_half(node.info);
    let r = sphere_radius(half);
    let rel = c - (*tr).o;
    let meets = meets_plane(dot(rel, u.v1), dot(rel, u.v2), half, r);
    let q = vec2<f32>(dot(rel, u.n1), dot(rel, u.n2));
    let near = length(q) - r < (*tr).hits.far;
    let boxed = (node.info & MARCHED) != 0u;
    if (meets & near & boxed) {
        if (seeking) {
            seek_in_plane(tr, c - half, c + half);
        } else {
            trace_box(tr, c - half, c + half, angles(q, r), box_steps(node.info), bounds[i].slope, plane_curvature(bounds[i].curvature));
        }
    }
    return vec2<bool>(meets, near);
}

// Tests box record i of the tile lists as `visit` tests a node, with what is the same for
// every pixel read from the record, and marches (or seeks in) it if it passes. Returns
// whether anything in it can be nearer than the K hits kept.
fn visit_box(tr: ptr<function, Tracer>, i: u32, seeking: bool) -> bool {
    let view = boxes[i].view;
    let level = boxes[i].level;
    let half = level_half(level);
    let meets = meets_plane(view.x - (*tr).shift.x, view.y - (*tr).shift.y, half, sphere_radius(half));
    // (For a slice, view.z bounds where its ray enters the box: see tiles/section.rs.)
    let near = view.z < (*tr).hits.far;
    if (meets & near) {
        let c = boxes[i].center;
        if (seeking) {
            seek_in_plane(tr, c - half, c + half);
        } else {
            trace_box(tr, c - half, c + half, boxes[i].angles, box_steps(level), boxes[i].slope, boxes[i].form);
        }
    }
    return near;
}
