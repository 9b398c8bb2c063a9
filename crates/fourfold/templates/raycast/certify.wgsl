// Certified pixels (docs/method.md §5.9). Each pixel's observer plane, within its boxes (the
// certifying lists', see certify), is covered by cells (s, t ranges along n1, n2 from the
// pixel's origin); F and its gradient are enclosed over each cell's box with the rigorous
// interval arithmetic of templates/interval.wgsl. A cell whose enclosure (or mean-value
// form) excludes 0 holds no root; another is sampled (rigorously signed) and split in two,
// depth first. Two samples of opposite sign, where F is continuous on the segment between
// them, prove a root: HIT. No cell left: EMPTY. Budget (march.y cells) or stack spent
// first: UNDECIDED.
const CERT_STACK: u32 = 24u;

struct Box {
    lo: vec4<f32>,
    hi: vec4<f32>,
}

struct Cert {
    budget: u32,
    hit: bool,
    undecided: bool,
    pos: bool,
    neg: bool,
    // (s, t) of a point where F > 0 and one where F < 0, on a segment where F is continuous.
    a: vec2<f32>,
    b: vec2<f32>,
}

// The box around the points o + s n1 + t n2, s in S and t in T, its bounds rounded outward.
fn plane_box(o: vec4<f32>, s: vec2<f32>, t: vec2<f32>) -> Box {
    let a = s.x * u.n1;
    let b = s.y * u.n1;
    let c = t.x * u.n2;
    let d = t.y * u.n2;
    var x: Box;
    x.lo = iv_down4(iv_down4(o + iv_down4(min(a, b))) + iv_down4(min(c, d)));
    x.hi = iv_up4(iv_up4(o + iv_up4(max(a, b))) + iv_up4(max(c, d)));
    return x;
}

// Bounds on n . e over the box of e in [lo, hi], rounded outward.
fn plane_range(n: vec4<f32>, lo: vec4<f32>, hi: vec4<f32>) -> vec2<f32> {
    let p = n * lo;
    let q = n * hi;
    let l = iv_down4(min(p, q));
    let h = iv_up4(max(p, q));
    return vec2<f32>(iv_down(iv_down(iv_down(l.x + l.y) + l.z) + l.w), iv_up(iv_up(iv_up(h.x + h.y) + h.z) + h.w));
}

// Whether an enclosure of F proves F != 0 (an empty one: F is undefined there).
fn excludes_zero(f: vec2<f32>) -> bool {
    return iv_is_empty(f) | (f.x > 0.0) | (f.y < 0.0);
}

// The sign an enclosure of F proves: 1, -1, or 0 (none).
fn proved_sign(f: vec2<f32>) -> i32 {
    if (iv_is_empty(f)) {
        return 0;
    }
    return select(select(0, -1, f.y < 0.0), 1, f.x > 0.0);
}

// The sign of F at the plane's point (s, t), proved (1 or -1) or not (0); 0 too where the
// point may lie outside [lo, hi].
fn cert_sign(o: vec4<f32>, p: vec2<f32>, lo: vec4<f32>, hi: vec4<f32>) -> i32 {
    let x = plane_box(o, p.xx, p.yy);
    if (any(x.lo < lo) | any(x.hi > hi)) {
        return 0;
    }
    return proved_sign(ff_f_box(x.lo, x.hi));
}

// An enclosure of grad F . n (F's slope along n) from the gradient's enclosures.
fn plane_slope(fg: IvFGrad, n: vec4<f32>) -> vec2<f32> {
    let x = iv_add(iv_mul(fg.gx, vec2<f32>(n.x)), iv_mul(fg.gy, vec2<f32>(n.y)));
    let y = iv_add(iv_mul(fg.gz, vec2<f32>(n.z)), iv_mul(fg.gw, vec2<f32>(n.w)));
    return iv_add(x, y);
}

// The sign still missing: 1, -1, or 0 (both, or neither, missing).
fn cert_wanted(cert: Cert) -> i32 {
    return select(select(0, -1, cert.pos & !cert.neg), 1, cert.neg & !cert.pos);
}

// Records a proved sign at p; a pair of opposite signs is a hit.
fn cert_note(cert: ptr<function, Cert>, sign: i32, p: vec2<f32>) {
    if ((sign > 0) & !(*cert).pos) {
        (*cert).pos = true;
        (*cert).a = p;
    }
    if ((sign < 0) & !(*cert).neg) {
        (*cert).neg = true;
        (*cert).b = p;
    }
    (*cert).hit = (*cert).pos & (*cert).neg;
}

// The part of the cell (s in c.xy, t in c.zw) where o + s n1 + t n2 may lie in the box
// [o + lo, o + hi], bounded (empty: s.x > s.y): each of the box's four ranges, n1_i s +
// n2_i t in [lo_i, hi_i], narrows s given t and t given s, twice over. Every range is
// moved outward by 1e-5 of the magnitudes involved (reach bounds |s| and |t|), far beyond
// f32's rounding here; directions within 1e-3 of a range's plane are not used to narrow.
fn shrink_cell(c: vec4<f32>, lo: vec4<f32>, hi: vec4<f32>, reach: f32) -> vec4<f32> {
    let slack = 1e-5 * (reach * (abs(u.n1) + abs(u.n2)) + abs(lo) + abs(hi)) + vec4<f32>(1e-30);
    let lo_s = lo - slack;
    let hi_s = hi + slack;
    var s = c.xy;
    var t = c.zw;
    for (var round = 0u; round < 2u; round = round + 1u) {
        s = narrow(s, u.n1, u.n2, t, lo_s, hi_s);
        t = narrow(t, u.n2, u.n1, s, lo_s, hi_s);
    }
    let e = 1e-5 * reach + 1e-30;
    return vec4<f32>(max(c.x, s.x - e), min(c.y, s.y + e), max(c.z, t.x - e), min(c.w, t.y + e));
}

// The range a takes where a n + b m (b in `other`) lies in [lo, hi], per coordinate,
// intersected with `range`.
fn narrow(range: vec2<f32>, n: vec4<f32>, m: vec4<f32>, other: vec2<f32>, lo: vec4<f32>, hi: vec4<f32>) -> vec2<f32> {
    let q_lo = lo - max(m * other.x, m * other.y);
    let q_hi = hi - min(m * other.x, m * other.y);
    let usable = abs(n) > vec4<f32>(1e-3);
    let safe = select(vec4<f32>(1.0), n, usable);
    let a = q_lo / safe;
    let b = q_hi / safe;
    let low = select(vec4<f32>(-IV_BIG), min(a, b), usable);
    let high = select(vec4<f32>(IV_BIG), max(a, b), usable);
    return vec2<f32>(max(range.x, max(max(low.x, low.y), max(low.z, low.w))), min(range.y, min(min(high.x, high.y), min(high.z, high.w))));
}

// A point of the plane within the cell c (s in c.xy, t in c.zw), in the box [lo, hi]
// where three rounds find one: the cell's centre `mid`, or else its point clamped into
// the box (shrunk by a thousandth) and projected back on the plane, kept in the cell. The
// forms expand about it, and must expand about a point of the box (where the plane cuts
// a box's corner, a cell's centre often lies outside it).
fn cell_point(o: vec4<f32>, c: vec4<f32>, mid: vec2<f32>, lo: vec4<f32>, hi: vec4<f32>) -> vec2<f32> {
    let m = 1e-3 * (hi - lo);
    var p = mid;
    for (var round = 0u; round < 3u; round = round + 1u) {
        let x = o + p.x * u.n1 + p.y * u.n2;
        if (all(x > lo) & all(x < hi)) {
            break;
        }
        let q = clamp(x, lo + m, hi - m) - o;
        p = clamp(vec2<f32>(dot(q, u.n1), dot(q, u.n2)), c.xz, c.yw);
    }
    return p;
}

// Whether a + g1 s + g2 t + (A s^2 + B s t + C t^2) / 2 > 0 for every (s, t) and every
// A >= al, C >= cl, B in b (a, g1, g2: enclosures). With q = B's middle / 2 and w half B's
// width, the quadratic is at least (al - w) s^2 + 2q s t + (cl - w) t^2; where that is
// positive definite (P), the least value of the whole is a - g^T P^-1 g / 2 =
// a - num / (2 det) with num = r g1^2 - 2q g1 g2 + p g2^2 and det = pr - q^2.
fn bowl_above_zero(a: vec2<f32>, g1: vec2<f32>, g2: vec2<f32>, al: f32, b: vec2<f32>, cl: f32) -> bool {
    let q = 0.25 * (b.x + b.y);
    let w = iv_up(max(iv_up(0.5 * b.y - q), iv_up(q - 0.5 * b.x)));
    let p = vec2<f32>(iv_down(al - w));
    let r = vec2<f32>(iv_down(cl - w));
    let det = iv_sub(iv_mul(p, r), iv_sqr(vec2<f32>(q)));
    if (iv_is_empty(a) | !((a.x > 0.0) & (p.x > 0.0) & (r.x > 0.0) & (det.x > 0.0))) {
        return false;
    }
    // (a - num / (2 det) > 0 as 2 a det > num: no division.)
    let num = iv_add(iv_sub(iv_mul(r, iv_sqr(g1)), iv_mul(vec2<f32>(2.0 * q), iv_mul(g1, g2))), iv_mul(p, iv_sqr(g2)));
    return 2.0 * iv_mul(a, det).x > num.y;
}

// Whether every bound of a plane curvature form is finite and below IV_LARGE (from the
// bits: ±∞ marks a box without bounds, and a compiler may assume no infinity in floats).
fn form_bounded(form: PlaneCurvature) -> bool {
    let big = bitcast<u32>(IV_LARGE);
    let ab = bitcast<vec4<u32>>(form.ab) & vec4<u32>(0x7fffffffu);
    let c = bitcast<vec2<u32>>(form.c) & vec2<u32>(0x7fffffffu);
    return all(ab < vec4<u32>(big)) & all(c < vec2<u32>(big));
}

// Certifies the part of the pixel's observer plane (origin o) within the box [blo, bhi]
// and the domain, spending at most `cap` cells of the budget. `form` bounds F's second
// derivatives along the plane over the box (its curvature bounds, Hierarchy::curvature:
// d²F along s·n1 + t·n2 within s²·A + st·B + t²·C; unbounded where F may not be twice
// continuously differentiable there).
fn certify_box(cert: ptr<function, Cert>, o: vec4<f32>, blo: vec4<f32>, bhi: vec4<f32>, cap: u32, form: PlaneCurvature) {
    // The budget this box may spend down to.
    let floor = select(0u, (*cert).budget - cap, (*cert).budget > cap);
    // The box within the domain (boxes are padded beyond it; both rounded outward).
    let lo = max(iv_down4(blo), iv_down4(u.domain_lo));
    let hi = min(iv_up4(bhi), iv_up4(u.domain_hi));
    if (any(lo > hi)) {
        return;
    }
    let rel_lo = iv_down4(lo - o);
    let rel_hi = iv_up4(hi - o);
    var s = plane_range(u.n1, rel_lo, rel_hi);
    var t = plane_range(u.n2, rel_lo, rel_hi);
    // n1 and n2 are orthonormal only to f32's rounding: widen for it (generously).
    let m = 1e-5 * (max(abs(s.x), abs(s.y)) + max(abs(t.x), abs(t.y))) + 1e-30;
    s = s + vec2<f32>(-m, m);
    t = t + vec2<f32>(-m, m);
    if (slice_on()) {
        if ((u.root.z < t.x) | (u.root.z > t.y)) {
            return;
        }
        t = vec2<f32>(u.root.z);
    } else if (slab_on()) {
        t = vec2<f32>(max(t.x, u.root.z - u.root.w), min(t.y, u.root.z + u.root.w));
        if (t.x > t.y) {
            return;
        }
    }
    // The plane meets the box where o + s n1 + t n2 lies within each of its four ranges:
    // cells are cut down to where they may meet it (shrink_cell).
    let reach = max(max(abs(s.x), abs(s.y)), max(abs(t.x), abs(t.y)));
    // Where a sample counts pixel-wide: in the domain, where F is continuous (flag 2048).
    let global = (u.control.z & 2048u) != 0u;
    let inner_lo = iv_up4(u.domain_lo);
    let inner_hi = iv_down4(u.domain_hi);
    // (Unbounded, the form takes no part: Taylor's is never tried.)
    let curved = form_bounded(form);
    var stack: array<vec4<f32>, CERT_STACK>;
    stack[0] = vec4<f32>(s, t);
    var top = 1u;
    loop {
        if ((top == 0u) | (*cert).hit) {
            break;
        }
        top = top - 1u;
        let c = shrink_cell(stack[top], rel_lo, rel_hi, reach);
        if ((c.x > c.y) | (c.z > c.w)) {
            continue;
        }
        if ((*cert).budget == floor) {
            (*cert).undecided = true;
            break;
        }
        let x = plane_box(o, c.xy, c.zw);
        let xlo = max(x.lo, lo);
        let xhi = min(x.hi, hi);
        if (any(xlo > xhi)) {
            continue;
        }
        (*cert).budget = (*cert).budget - 1u;
        let mid = vec2<f32>(0.5 * (c.x + c.y), 0.5 * (c.z + c.w));
        // The point c0 the forms expand about (in the box where it can be found), and the
        // cell's offsets from it.
        let c0 = cell_point(o, c, mid, lo, hi);
        let ds = iv_sub(c.xy, vec2<f32>(c0.x));
        let dt = iv_sub(c.zw, vec2<f32>(c0.y));
        // Half the second-order term of Taylor's form over the cell, d^T H d / 2 for d =
        // s n1 + t n2 (s in ds, t in dt), H over the box.
        // (Only where the box has bounds: Taylor's form is tried nowhere else.)
        var half_quad = vec2<f32>(0.0);
        if (curved) {
            half_quad = iv_mul(vec2<f32>(0.5), iv_add(iv_add(iv_mul(form.ab.xy, iv_sqr(ds)), iv_mul(form.ab.zw, iv_mul(ds, dt))), iv_mul(form.c, iv_sqr(dt))));
        }
        // F's slope along n1 and n2 over the cell, estimated (where bounded), and the
        // most it may be (1, 1 where unknown: then the longer side is split).
        var slope = vec2<f32>(0.0);
        var smear = vec2<f32>(1.0);
        var excluded = false;
        var guess = vec2<f32>(0.0);
        var guessing = false;
        var local: Cert;
        var fg: IvFGrad;
        var steady = false;
        // F at c0, and its box, for Taylor's form.
        var c0_f = vec2<f32>(0.0);
        var c0_box: Box;
        var taylor = false;
        // The cell's enclosure of F and grad F, then (where Taylor's form may prove the cell)
        // c0's: one call site (a compiler inlines F and grad F at each).
        for (var e = 0u; e < 2u; e = e + 1u) {
            iv_jump = false;
            let r = ff_f_grad_box(select(xlo, c0_box.lo, e == 1u), select(xhi, c0_box.hi, e == 1u));
            if (e == 1u) {
                // Taylor's form of second order, F(c0) + grad F(c0) . d + d^T H d / 2 with H
                // over the box: its linear part taken at c0, it proves the cells where the
                // plane passes near M but F bends away from 0 (near silhouettes) and where
                // F's enclosures overestimate (near the domain's walls). (The segment from
                // c0 to any point of the cell in the box lies in both.) Where the form bounds
                // a bowl (or a cap), its least (greatest) value over the whole plane proves
                // it too: beside a convex M's silhouette the interval form still holds 0
                // over cells the bowl clears.
                let g1 = plane_slope(r, u.n1);
                let g2 = plane_slope(r, u.n2);
                let lin = iv_add(c0_f, iv_add(iv_mul(g1, ds), iv_mul(g2, dt)));
                excluded = excludes_zero(iv_add(lin, half_quad));
                // (F < 0 at c0: the cap is -F's bowl.)
                let up = c0_f.x > 0.0;
                let a = select(-form.ab.y, form.ab.x, up);
                let cc = select(-form.c.y, form.c.x, up);
                if (!excluded & (a > 0.0) & (cc > 0.0)) {
                    let b = select(iv_neg(form.ab.zw), form.ab.zw, up);
                    let f = select(iv_neg(c0_f), c0_f, up);
                    let h1 = select(iv_neg(g1), g1, up);
                    let h2 = select(iv_neg(g2), g2, up);
                    excluded = bowl_above_zero(f, h1, h2, a, b, cc);
                }
                break;
            }
            fg = r;
            steady = !iv_jump;
            if (excludes_zero(fg.f)) {
                excluded = true;
                break;
            }
            // The samples, from one place (a compiler inlines F at each call): 0 at c0, 1
            // where F more likely has the sign still missing (see below), 2 and 3 two
            // corners (where F is continuous on this cell's box only, its own samples must
            // show both signs). Each counts only where it surely lies in the box.
            for (var k = 0u; k < 4u; k = k + 1u) {
                let used = select(select(!global & steady, guessing, k == 1u), true, k == 0u);
                if (!used) {
                    continue;
                }
                let p = select(select(select(c.yw, c.xz, k == 2u), guess, k == 1u), c0, k == 0u);
                let x = plane_box(o, p.xx, p.yy);
                if (any(x.lo < lo) | any(x.hi > hi)) {
                    continue;
                }
                let f = ff_f_box(x.lo, x.hi);
                let in_domain = all(x.lo >= inner_lo) & all(x.hi <= inner_hi);
                let in_cell = all(x.lo >= xlo) & all(x.hi <= xhi);
                if ((k == 0u) & steady) {
                    // The mean-value form over the cell, F(c) + grad F . (p - c) with p - c
                    // in the plane (the segment from c0 to any point of the cell in
                    // the box lies in both): far narrower than F's own enclosure near a root.
                    let g1 = plane_slope(fg, u.n1);
                    let g2 = plane_slope(fg, u.n2);
                    let mv = iv_add(f, iv_add(iv_mul(g1, ds), iv_mul(g2, dt)));
                    if (excludes_zero(iv_meet(fg.f, mv))) {
                        excluded = true;
                        break;
                    }
                    // Taylor's form can exclude 0 only where F(c) + d^T H d / 2 does.
                    // (F is defined on a box with curvature bounds: an empty enclosure
                    // would be a fault, and proves nothing.)
                    taylor = curved & !iv_is_empty(f) & excludes_zero(iv_add(f, half_quad));
                    c0_f = f;
                    c0_box = x;
                    let most = vec2<f32>(max(abs(g1.x), abs(g1.y)), max(abs(g2.x), abs(g2.y)));
                    smear = select(smear, most, all(most < vec2<f32>(IV_LARGE)) & (most.x + most.y > 0.0));
                    let estimate = 0.5 * vec2<f32>(g1.x + g1.y, g2.x + g2.y);
                    slope = select(vec2<f32>(0.0), estimate, abs(estimate) < vec2<f32>(IV_LARGE));
                }
                if (global & in_domain) {
                    cert_note(cert, proved_sign(f), p);
                }
                if (!global & steady & (k != 1u) & in_cell) {
                    cert_note(&local, proved_sign(f), p);
                }
                if ((k == 0u) & global & in_domain) {
                    // Twice the Newton step of the linear model towards 0, within the cell,
                    // towards the sign still missing (with neither found, the sign opposite
                    // to F's at c0).
                    let v = 0.5 * (f.x + f.y);
                    let want = select(f32(cert_wanted(*cert)), -sign(v), !(*cert).pos & !(*cert).neg);
                    let norm = dot(slope, slope);
                    guessing = !iv_is_empty(f) & (want * v < 0.0) & (norm > 0.0) & (norm < IV_LARGE) & (abs(v) < IV_LARGE);
                    guess = clamp(c0 - (2.0 * v / max(norm, 1e-30)) * slope, c.xz, c.yw);
                }
            }
            if (excluded | !taylor | local.hit | (*cert).hit) {
                break;
            }
        }
        if (excluded) {
            continue;
        }
        if (local.hit) {
            (*cert).hit = true;
            (*cert).a = local.a;
            (*cert).b = local.b;
        }
        if ((*cert).hit) {
            break;
        }
        // Split the side along which F may change the most (its slope's bound times its
        // length: the mean-value form's width falls the most), or the other where f32 cannot
        // split that one (a slice's cells are segments along n1).
        let split_s = (mid.x > c.x) & (mid.x < c.y);
        let split_t = (mid.y > c.z) & (mid.y < c.w);
        let along_s = split_s & (!split_t | ((c.y - c.x) * smear.x >= (c.w - c.z) * smear.y));
        let cut = select(mid.y, mid.x, along_s);
        if (!(split_s | split_t) | (top + 2u > CERT_STACK)) {
            // Too small for f32 to split, or too deep: this part stays undecided.
            (*cert).undecided = true;
            continue;
        }
        // The half where F more likely has the sign still missing is searched first
        // (pushed last).
        let lower = select(vec4<f32>(c.xy, c.z, cut), vec4<f32>(c.x, cut, c.zw), along_s);
        let upper = select(vec4<f32>(c.xy, cut, c.w), vec4<f32>(cut, c.y, c.zw), along_s);
        let swap = f32(cert_wanted(*cert)) * select(slope.y, slope.x, along_s) < 0.0;
        stack[top] = select(lower, upper, swap);
        stack[top + 1u] = select(upper, lower, swap);
        top = top + 2u;
    }
}

// The plane's point where F changes sign between the certificate's two samples, by
// bisection in f32 (for shading: the sign change itself is already proved).
fn cert_root(o: vec4<f32>, cert: Cert) -> vec2<f32> {
    var pa = cert.a;
    var pb = cert.b;
    for (var i = 0u; i < 24u; i = i + 1u) {
        let m = 0.5 * (pa + pb);
        let positive = ff_f(o + m.x * u.n1 + m.y * u.n2) > 0.0;
        pa = select(pa, m, positive);
        pb = select(m, pb, positive);
    }
    return 0.5 * (pa + pb);
}

// Whether F is continuous on the segment between a ray's two samples (s, t in ab.xy and
// ab.zw): everywhere in the domain (flag 2048), or else on the box around the segment,
// within the domain, as F's enclosure there says (F undefined in part of the domain, as a
// sqrt's or ln's, is continuous away from that part: most hits are proved so, without a
// search that must find both signs in one cell).
// (inner_lo and inner_hi: the domain, rounded inward.)
fn bracket_continuous(o: vec4<f32>, ab: vec4<f32>, inner_lo: vec4<f32>, inner_hi: vec4<f32>) -> bool {
    if ((u.control.z & 2048u) != 0u) {
        return true;
    }
    let x = plane_box(o, vec2<f32>(min(ab.x, ab.z), max(ab.x, ab.z)), vec2<f32>(min(ab.y, ab.w), max(ab.y, ab.w)));
    if (any(x.lo < inner_lo) | any(x.hi > inner_hi)) {
        return false;
    }
    iv_jump = false;
    let f = ff_f_box(x.lo, x.hi);
    return !iv_jump & !iv_is_empty(f);
}

// Searches the pixel's boxes, each with at most `cap` cells (stopping at once after a
// hit): the certifying lists' where bound, else the walk's marched boxes, or for brute
// force the domain.
fn search_boxes(tr: ptr<function, Tracer>, cert: ptr<function, Cert>, px: vec2<u32>, cap: u32) {
    let o = (*tr).plane;
    // The boxes are the certifying list's entries c..end, the hierarchy's nodes from c
    // (skipping subtrees), or for brute force the domain once: one loop, and one call of
    // certify_box for all three (a compiler inlines it, and F, at each call).
    let listed = (MODE == 1u) & (u.cert_tiling.z != 0u);
    var c = 0u;
    var end = 1u;
    if (listed) {
        let tile = px / max(u.cert_tiling.x, 1u);
        let t = tile.x + tile.y * u.cert_tiling.y;
        c = cert_tiles[t];
        end = cert_tiles[t + 1u];
    } else if (MODE != 0u) {
        end = u.counts.x;
    }
    loop {
        if ((c >= end) | (*cert).hit | (((*cert).budget == 0u) & (*cert).undecided)) {
            break;
        }
        var lo = u.domain_lo;
        var hi = u.domain_hi;
        var form: PlaneCurvature;
        form.ab = vec4<f32>(IV_BIG);
        form.c = vec2<f32>(IV_BIG);
        var search = MODE == 0u;
        var next = c + 1u;
        if (listed) {
            let i = cert_tiles[u.cert_tiling.w + c];
            let half = level_half(cert_boxes[i].level);
            // (The tile's boxes that cannot meet this pixel's plane, as visit_box tests.)
            let view = cert_boxes[i].view;
            search = meets_plane(view.x - (*tr).shift.x, view.y - (*tr).shift.y, half, sphere_radius(half));
            lo = cert_boxes[i].center - half;
            hi = cert_boxes[i].center + half;
            form = cert_boxes[i].form;
        } else if (MODE != 0u) {
            let node = nodes[c];
            let center = vec4<f32>(node.cx, node.cy, node.cz, node.cw);
            let half = level_half(node.info);
            let rel = center - o;
            let meets = meets_plane(dot(rel, u.v1), dot(rel, u.v2), half, sphere_radius(half));
            let boxed = (node.info & MARCHED) != 0u;
            search = meets & boxed;
            lo = center - half;
            hi = center + half;
            next = select(node.skip, c + 1u, meets & !boxed);
        }
        if (search) {
            certify_box(cert, o, lo, hi, cap, form);
        }
        c = next;
    }
}

// Classifies the pixel (CERT_EMPTY, CERT_HIT or CERT_UNDECIDED) over its boxes
// (search_boxes). For a hit the rays found nothing for, aims a ray through the proved root
// and marches it through the tile's boxes, so its hits are shaded as the others are (the
// root itself if the march misses it).
fn certify(tr: ptr<function, Tracer>, px: vec2<u32>) -> u32 {
    let o = (*tr).plane;
    var cert: Cert;
    cert.budget = u.march.y;
    let inner_lo = iv_up4(u.domain_lo);
    let inner_hi = iv_down4(u.domain_hi);
    if ((*tr).bracketed && bracket_continuous(o, (*tr).bracket, inner_lo, inner_hi)) {
        // A ray's sign change, proved at its two ends (in the domain) where it can be: no
        // search needed.
        for (var k = 0u; k < 2u; k = k + 1u) {
            let p = select((*tr).bracket.zw, (*tr).bracket.xy, k == 0u);
            cert_note(&cert, cert_sign(o, p, inner_lo, inner_hi), p);
        }
    }
    // Two passes over the boxes: in the first each box may spend an eighth of the budget,
    // so that one hard box (a kink, a pole, a grazing plane) cannot spend it all before a
    // later one shows the root; what stays undecided is searched again, whole, with what
    // is left (brute force's one box is searched whole at once).
    for (var round = 0u; round < 2u; round = round + 1u) {
        if ((round == 1u) & ((MODE == 0u) | cert.hit | !cert.undecided | (cert.budget == 0u))) {
            break;
        }
        cert.undecided = false;
        let cap = select(cert.budget, max(u.march.y / 8u, 1u), (round == 0u) & (MODE != 0u));
        search_boxes(tr, &cert, px, cap);
    }
    if (!cert.hit) {
        return select(CERT_EMPTY, CERT_UNDECIDED, cert.undecided);
    }
    if ((*tr).hits.count == 0u) {
        let h = cert_root(o, cert);
        (*tr).k = AIMED;
        if (slice_on()) {
            // The slice's ray runs along n1 from reach behind the plane's origin.
            (*tr).aim = vec2<f32>(1.0, 0.0);
            insert_hit(tr, h.x + 0.5 * length(u.domain_hi - u.domain_lo));
        } else {
            let len = length(h);
            (*tr).aim = select(vec2<f32>(1.0, 0.0), h / len, len > 0.0);
            if (MODE == 1u) {
                trace_aimed(tr, px);
            }
            if ((*tr).hits.count == 0u) {
                insert_hit(tr, len);
            }
        }
    }
    return CERT_HIT;
}

// Marches the ray aimed at `(*tr).aim` through the pixel's tile list (as trace_box
// marches a pencil's ray).
fn trace_aimed(tr: ptr<function, Tracer>, px: vec2<u32>) {
    let tile = px / max(u.tiling.x, 1u);
    let t = tile.x + tile.y * u.tiling.y;
    let end = tiles[t + 1u];
    var c = tiles[t];
    loop {
        if (c >= end) {
            break;
        }
        let i = tiles[u.tiling.w + c];
        let half = level_half(boxes[i].level);
        let center = boxes[i].center;
        march_through(tr, AIMED, (*tr).aim, center - half, center + half, max(box_steps(boxes[i].level), 1u), boxes[i].slope, boxes[i].form);
        c = c + 1u;
    }
}

// The certified pixels' entry points (see entry.wgsl for the plain ones).
@fragment
fn fs_tiles_certified(fl: Flat) -> @location(0) vec4<f32> {
    var tr = start_pixel(fl);
    cast_tiles(&tr, vec2<u32>(fl.pos.xy));
    return certified_color(&tr, fl);
}

@fragment
fn fs_walk_certified(fl: Flat) -> @location(0) vec4<f32> {
    var tr = start_pixel(fl);
    cast_walk(&tr);
    return certified_color(&tr, fl);
}

@fragment
fn fs_brute_force_certified(fl: Flat) -> @location(0) vec4<f32> {
    var tr = start_pixel(fl);
    cast_brute_force(&tr);
    return certified_color(&tr, fl);
}

// (The verdict first: a hit the rays missed is aimed at and added to the tracer.)
fn certified_color(tr: ptr<function, Tracer>, fl: Flat) -> vec4<f32> {
    let px = vec2<u32>(fl.pos.xy);
    let verdict = certify(tr, px);
    return pixel_color(*tr, px, verdict);
}
