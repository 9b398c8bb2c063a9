// Where the pixel's observer plane grazes M, F takes its other sign on a small island of
// the plane that the pencil's rays pass beside, or cross between two of their samples: the
// pixel would show background where M is (issue 34 measured up to a quarter of a thin
// tube's pixels). So a pixel whose rays found nothing searches each of its boxes again: a
// few Newton steps on F within the plane, from the rays' samples where M may be nearest (or
// a point amid the plane's part in the box), look for a sign change inside the box; its
// root, found by bisection, is a hit along the ray through it (docs/method.md §5.4).

// A hit's ray with this bit was found by seek_in_plane: its low 24 bits hold the ray's
// angle in the observer plane as a fraction of a turn (fourfold's `plane_ray`).
const PLANE_ROOT: u32 = 0x80000000u;
// How far outside its box, as a share of the domain's extent along each axis, a root the
// search found may lie and still be kept (the twin's ROOT_MARGIN).
const ROOT_MARGIN: f32 = 1e-5;
// Evaluations of F and its gradient (a step's, a valley floor's) from each start, and how
// much each Newton step is lengthened (so that a step that nears a root crosses it, which
// gives the sign change; 1 would only approach it).
const SEEK_EVALS: u32 = 8u;
const SEEK_REACH: f32 = 1.5;
// How many of the rays' closest samples (one per ray and box, the nearest to M) the search
// starts from: one left islands between the other rays unvisited.
const SEEK_STARTS: u32 = 4u;
// The corners tried of the plane's part in a box: two of its sides, of four axes' eight.
const BOX_CORNERS: u32 = 24u;

fn plane_ray(dir: vec2<f32>) -> u32 {
    let turn = fract(atan2(dir.y, dir.x) / TAU + 1.0);
    return PLANE_ROOT | min(u32(turn * 16777216.0), 16777215u);
}

fn plane_ray_dir(ray: u32) -> vec2<f32> {
    let phi = TAU * f32(ray & 16777215u) / 16777216.0;
    return vec2<f32>(cos(phi), sin(phi));
}

// The point at (s, t) from the pixel's origin along n1 and n2.
fn in_plane(tr: ptr<function, Tracer>, st: vec2<f32>) -> vec4<f32> {
    return (*tr).o + st.x * u.n1 + st.y * u.n2;
}

fn in_box(p: vec4<f32>, lo: vec4<f32>, hi: vec4<f32>) -> bool {
    return all(p >= lo) & all(p <= hi);
}

// Corner i (of BOX_CORNERS tried) of the plane's part in the box [lo, hi] shrunk by a
// thousandth, as (s, t, 1), or (0, 0, 0) if it is not one: where the plane meets two of the
// box's sides (pair i / 4 of two axes, their bounds by i % 4) within the others, give or
// take half that margin.
fn box_corner(tr: ptr<function, Tracer>, lo: vec4<f32>, hi: vec4<f32>, i: u32) -> vec3<f32> {
    let m = 0.001 * (hi - lo);
    let l = lo + m;
    let h = hi - m;
    // The pair's axes as one-hot vectors: components picked by a variable index (of a
    // table of pairs, of o and n1) made llvmpipe's frames a tenth slower.
    let pair = i / 4u;
    let axes = vec4<u32>(0u, 1u, 2u, 3u);
    let first = select(select(0u, 1u, pair >= 3u), 2u, pair >= 5u);
    let second = select(select(1u, 2u, (pair == 1u) | (pair == 3u)), 3u, (pair == 2u) | (pair >= 4u));
    let ea = select(vec4<f32>(0.0), vec4<f32>(1.0), axes == vec4<u32>(first));
    let eb = select(vec4<f32>(0.0), vec4<f32>(1.0), axes == vec4<u32>(second));
    let n1a = dot(u.n1, ea);
    let n2a = dot(u.n2, ea);
    let n1b = dot(u.n1, eb);
    let n2b = dot(u.n2, eb);
    let det = n1a * n2b - n2a * n1b;
    let ra = dot(select(l, h, i % 4u >= 2u) - (*tr).o, ea);
    let rb = dot(select(l, h, i % 2u == 1u) - (*tr).o, eb);
    let st = vec2<f32>((ra * n2b - n2a * rb) / det, (n1a * rb - ra * n1b) / det);
    let p = in_plane(tr, st);
    let corner = (abs(det) >= 1e-12) & all(p >= l - 0.5 * m) & all(p <= h + 0.5 * m);
    return select(vec3<f32>(0.0), vec3<f32>(st, 1.0), corner);
}

// (s, t) moved onto the slab lo <= o + s n1 + t n2 <= hi of one axis (its components o, n1
// and n2 given), along the slab's normal in the plane.
fn onto_slab(st: vec2<f32>, o: f32, n1: f32, n2: f32, lo: f32, hi: f32) -> vec2<f32> {
    let a = vec2<f32>(n1, n2);
    let aa = dot(a, a);
    let v = o + dot(a, st);
    let to = clamp(v, lo, hi);
    return select(st, st + ((to - v) / aa) * a, aa > 1e-12);
}

// Whether the plane meets the box whose centre lies at `rel` from the pixel's origin, with
// half extents `half` (give or take rounding): the box's shadow along
// the plane on (v1, v2), a zonotope with a side along each axis's (v1_k, v2_k), holds the
// plane's point; tested across each side, and along v1 and v2 (for a flat shadow). Many of
// a pixel's boxes have only their sphere meet its plane.
fn plane_meets_box(rel: vec4<f32>, half: vec4<f32>) -> bool {
    let a = dot(rel, u.v1);
    let b = dot(rel, u.v2);
    // Across side k: |rel . w_k| within the shadow's reach along w_k = v1_k v2 - v2_k v1.
    let across = abs(b * u.v1 - a * u.v2);
    let reach = vec4<f32>(
        dot(half, abs(u.v1.x * u.v2 - u.v2.x * u.v1)),
        dot(half, abs(u.v1.y * u.v2 - u.v2.y * u.v1)),
        dot(half, abs(u.v1.z * u.v2 - u.v2.z * u.v1)),
        dot(half, abs(u.v1.w * u.v2 - u.v2.w * u.v1)),
    );
    let slack = 1e-5 * (abs(a) + abs(b) + length(half));
    return all(across <= reach * 1.0001 + slack)
        & (abs(a) <= dot(half, abs(u.v1)) * 1.0001 + slack)
        & (abs(b) <= dot(half, abs(u.v2)) * 1.0001 + slack);
}

// A point of the plane inside the box [lo, hi] as (s, t, 1), or (0, 0, 0) if the plane
// misses it: from the box's centre, alternate projections on its four slabs, each shrunk by
// a thousandth; where four rounds of them end outside (the plane cuts only a corner of the
// box: they converge slowly there), the mean of the corners of the plane's part in the box.
fn point_in_box(tr: ptr<function, Tracer>, lo: vec4<f32>, hi: vec4<f32>) -> vec3<f32> {
    let o = (*tr).o;
    let rel = 0.5 * (lo + hi) - o;
    if (!plane_meets_box(rel, 0.5 * (hi - lo))) {
        return vec3<f32>(0.0);
    }
    let m = 0.001 * (hi - lo);
    let l = lo + m;
    let h = hi - m;
    var p = vec2<f32>(dot(rel, u.n1), dot(rel, u.n2));
    for (var r = 0u; r < 4u; r = r + 1u) {
        p = onto_slab(p, o.x, u.n1.x, u.n2.x, l.x, h.x);
        p = onto_slab(p, o.y, u.n1.y, u.n2.y, l.y, h.y);
        p = onto_slab(p, o.z, u.n1.z, u.n2.z, l.z, h.z);
        p = onto_slab(p, o.w, u.n1.w, u.n2.w, l.w, h.w);
    }
    if (in_box(in_plane(tr, p), lo, hi)) {
        return vec3<f32>(p, 1.0);
    }
    var sum = vec3<f32>(0.0);
    for (var i = 0u; i < BOX_CORNERS; i = i + 1u) {
        sum = sum + box_corner(tr, lo, hi, i);
    }
    return select(vec3<f32>(0.0), vec3<f32>(sum.xy / sum.z, 1.0), sum.z > 0.0);
}

// The share of the step from (s, t) (inside the box) that stays in it, and the outward
// normal in the plane of the side where it would leave (0 where it stays).
fn within_box(tr: ptr<function, Tracer>, st: vec2<f32>, step: vec2<f32>, lo: vec4<f32>, hi: vec4<f32>) -> vec3<f32> {
    let p = in_plane(tr, st);
    let d = step.x * u.n1 + step.y * u.n2;
    // (A step along a side of the box never reaches it.)
    let along = abs(d) < vec4<f32>(1e-30);
    let room = select(select(lo - p, hi - p, d > vec4<f32>(0.0)) / select(d, vec4<f32>(1.0), along), vec4<f32>(ff_inf()), along);
    var k = 0u;
    var r = room.x;
    if (room.y < r) {
        k = 1u;
        r = room.y;
    }
    if (room.z < r) {
        k = 2u;
        r = room.z;
    }
    if (room.w < r) {
        k = 3u;
        r = room.w;
    }
    let a = vec2<f32>(u.n1[k], u.n2[k]) * sign(d[k]);
    let len = length(a);
    let wall = select(vec2<f32>(0.0), a / len, (len > 1e-6) & (r < 1.0));
    return vec3<f32>(clamp(r, 0.0, 1.0), wall);
}

// How far from the sample at (s, t) M may be for the search to start there when it is not
// the nearest start: an island the pencil passed beside lies within half the gap between
// two rays, |st| pi / n, of one of them (and within half a step of one of its samples: a
// margin of a thousandth of the domain's diagonal stands for it); four times that, as the
// distance |F| / |grad F| is a first-order guess.
fn between_rays(st: vec2<f32>) -> f32 {
    return 2.0 * (length(st) * (TAU / f32(u.size.z)) + 0.002 * length(u.domain_hi - u.domain_lo));
}

// Whether (s, t) keeps to the slab, when there is one (as clip_to_slab: t along n2).
fn in_slab(st: vec2<f32>) -> bool {
    return !slab_on() | ((st.y >= u.root.z - u.root.w) & (st.y <= u.root.z + u.root.w));
}

// Newton's steps from `start` (in the box [lo, hi]) towards a root of F in the plane: a
// sign change between .a and .b (F(.a) = .fa) if .found.
struct Seek {
    a: vec2<f32>,
    b: vec2<f32>,
    fa: f32,
    found: bool,
}

fn seek_from(tr: ptr<function, Tracer>, start: vec2<f32>, lo: vec4<f32>, hi: vec4<f32>) -> Seek {
    let reach = 0.5 * length(hi - lo);
    var a = start;
    var fa = ff_f_grad(in_plane(tr, a));
    // M is farther than the box reaches, by |F| / |grad F| in the plane (or F is undefined
    // there): no search (most boxes the pixels around M meet, which would each pay for it).
    if (!(abs(fa.f) <= reach * length(vec2<f32>(dot(fa.g, u.n1), dot(fa.g, u.n2))))) {
        return Seek(a, a, fa.f, false);
    }
    var b = a;
    var found = false;
    // The outward normal of the box's side the search stands on (0: none): a step that
    // would leave through it goes along it instead.
    var wall = vec2<f32>(0.0);
    // The normal of the valley's floor the search stands on (0: none): the steps go along
    // the floor, not across it again.
    var crease = vec2<f32>(0.0);
    // How far the next step goes, in Newton's steps.
    var gain = SEEK_REACH;
    var i = 0u;
    // (Tested at the end: see "The pixel's work".)
    loop {
        // (Whether this step goes along a floor found before.)
        let on_floor = any(crease != vec2<f32>(0.0));
        // F's gradient in the plane, along the valley's floor if on one, and along the side
        // if the step would leave through it.
        let g = vec2<f32>(dot(fa.g, u.n1), dot(fa.g, u.n2));
        let g_floor = g - dot(g, crease) * crease;
        let gw = select(g_floor, g_floor - dot(g_floor, wall) * wall, dot(g_floor, wall) * fa.f < 0.0);
        var step = (-gain * fa.f / dot(gw, gw)) * gw;
        let len = length(step);
        // (A flat or undefined F gives a step that is not finite: the search ends.)
        if (!(len < ff_inf())) {
            break;
        }
        step = select(step, step * (reach / len), len > reach);
        // A step that would leave the box stops at its side.
        let stay = within_box(tr, a, step, lo, hi);
        // (Short of the side by a thousandth: a point on it may round to outside.)
        b = a + select(stay.x, stay.x * 0.999, stay.x < 1.0) * step;
        if (stay.x < 1e-3) {
            // Stuck: at a second side (a corner), or already along the first.
            if (any(wall != vec2<f32>(0.0)) | all(stay.yz == vec2<f32>(0.0))) {
                break;
            }
            wall = stay.yz;
        } else {
            var fgb = ff_f_grad(in_plane(tr, b));
            if (!same_side(fa.f, fgb.f)) {
                found = true;
                break;
            }
            // A step across the floor of a valley of F (F falls towards 0 from a, rises
            // again at b) zigzags: so the point where the tangents to F at a and b meet (a
            // kink's place, or near a smooth floor) is tried too, and kept if it is nearer 0.
            let taken = b - a;
            let fb_step = fgb.f;
            let gb = vec2<f32>(dot(fgb.g, u.n1), dot(fgb.g, u.n2));
            let sa = dot(g, taken);
            let sb = dot(gb, taken);
            if ((sa * fa.f < 0.0) & (sb * fa.f > 0.0)) {
                let m = a + clamp((fgb.f - fa.f - sb) / (sa - sb), 0.05, 0.95) * taken;
                let fgm = ff_f_grad(in_plane(tr, m));
                i = i + 1u;
                if (!same_side(fa.f, fgm.f)) {
                    b = m;
                    found = true;
                    break;
                }
                if (abs(fgm.f) < abs(fgb.f)) {
                    // On the floor, whose normal is where the gradient turned from a to b.
                    let turn = gb - g;
                    let turned = length(turn);
                    crease = select(vec2<f32>(0.0), turn / turned, turned > 0.0);
                    b = m;
                    fgb = fgm;
                }
            }
            if (abs(fgb.f) < abs(fa.f)) {
                wall = select(wall, stay.yz, stay.x < 1.0);
                a = b;
                fa = fgb;
                gain = SEEK_REACH;
            } else if (on_floor) {
                // Along the floor took |F| up: the gradient's own step again.
                crease = vec2<f32>(0.0);
            } else {
                // Nothing nearer 0, even where the tangents meet: a shorter step, to where
                // the parabola through F(a), its slope and F(b) is nearest 0, and not along
                // that floor (the same step again would find the same).
                crease = vec2<f32>(0.0);
                let bend = fb_step - fa.f - sa;
                gain = gain * select(0.5, clamp(-sa / (2.0 * bend), 0.05, 0.95), bend * fa.f > 0.0) * length(taken) / len;
            }
        }
        i = i + 1u;
        if (i >= SEEK_EVALS) {
            break;
        }
    }
    return Seek(a, b, fa.f, found);
}

// Ray start k as bit k if the search tries it in the box [lo, hi]: it lies in the box, and
// beyond the first, within reach of an island between the rays (see between_rays).
fn start_bit(tr: ptr<function, Tracer>, k: u32, lo: vec4<f32>, hi: vec4<f32>) -> u32 {
    let near = nth_start(tr, k);
    let plausible = (near.z < ff_inf()) & ((k == 0u) | (near.z <= between_rays(near.xy)));
    return select(0u, 1u << k, plausible & in_box(in_plane(tr, near.xy), lo, hi));
}

fn seek_in_plane(tr: ptr<function, Tracer>, lo: vec4<f32>, hi: vec4<f32>) {
    // From the rays' closest samples that lie in the box, then from a point amid the plane's
    // part in the box, and (but in a certified frame) where F is undefined there (ln, sqrt
    // or a pole past the edge of its domain) from each corner of that part, a hundredth of
    // the way in: F's domain within it is cut off by its edge, and where that is a line, a
    // corner lies on the defined side.
    // One call of seek_from, in a loop over the starts (a compiler inlines each call, with
    // its three evaluations of F and its gradient).
    // (The ray starts it tries as bits, so that the loop runs once for each: llvmpipe ends
    // an invocation's loops after 65535 iterations in all, which a pixel with many boxes
    // nears.)
    let rays = start_bit(tr, 0u, lo, hi) | start_bit(tr, 1u, lo, hi) | start_bit(tr, 2u, lo, hi) | start_bit(tr, 3u, lo, hi);
    var s: Seek;
    var centre = vec2<f32>(0.0);
    var undefined = false;
    // 0 to SEEK_STARTS - 1: a ray start; SEEK_STARTS: the point amid the box; after it, the
    // corners.
    var k = select(SEEK_STARTS, firstTrailingBit(rays), rays != 0u);
    loop {
        // (A ray start's place in the box was tested by start_bit.)
        var start: vec2<f32>;
        var tried = true;
        if (k < SEEK_STARTS) {
            start = nth_start(tr, k).xy;
        } else if (k == SEEK_STARTS) {
            let amid = point_in_box(tr, lo, hi);
            if (amid.z == 0.0) {
                break;
            }
            centre = amid.xy;
            start = centre;
            tried = in_box(in_plane(tr, start), lo, hi);
        } else {
            if (!undefined) {
                break;
            }
            let corner = box_corner(tr, lo, hi, k - SEEK_STARTS - 1u);
            start = corner.xy + 0.01 * (centre - corner.xy);
            tried = (corner.z != 0.0) & in_box(in_plane(tr, start), lo, hi);
        }
        if (tried) {
            s = seek_from(tr, start, lo, hi);
            if (s.found) {
                break;
            }
            if (k == SEEK_STARTS) {
                // (F at a start where it is undefined is NaN, and the search stays there; a
                // compiler may take x != x to be false. A certified frame proves what the
                // corners would find and aims a ray at it: its loops, near llvmpipe's limit
                // already, do not try them.)
                undefined = (CERTIFY == 0u) & !(abs(s.fa) <= ff_inf());
            }
        }
        let later = rays & ~((2u << k) - 1u);
        k = select(k + 1u, select(SEEK_STARTS, firstTrailingBit(later), later != 0u), k < SEEK_STARTS);
        if (k > SEEK_STARTS + BOX_CORNERS) {
            break;
        }
    }
    if (!s.found) {
        return;
    }
    if ((CERTIFY == 1u) & !(*tr).bracketed & in_slab(s.a) & in_slab(s.b)) {
        // (The pixel's origin is its plane's: a slice seeks nothing. Outside a slab, a sign
        // change is not the pixel's to prove.)
        (*tr).bracket = vec4<f32>(s.a, s.b);
        (*tr).bracketed = true;
    }
    // The root on the segment from a to b, as march_ray finds a ray's.
    let ab = s.b - s.a;
    let m = s.a + bisect(in_plane(tr, s.a), ab.x * u.n1 + ab.y * u.n2, 0.0, 1.0, s.fa < 0.0) * ab;
    let t = length(m);
    // (In the box widened past rounding: a search along the box's side finds roots on it,
    // and the point worked out from m may round to either side.)
    let margin = ROOT_MARGIN * (u.domain_hi - u.domain_lo);
    let near = in_box(in_plane(tr, m), lo - margin, hi + margin);
    if ((t > 0.0) & (t < (*tr).hits.far) & near & in_slab(m)) {
        (*tr).k = plane_ray(m / t);
        insert_hit(tr, t);
    }
}
