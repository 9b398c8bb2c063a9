// The settings the pixel's code reads most, handed from vs_main to the fragment shaders as
// flat (per triangle) values: llvmpipe reads a flat input for a group of pixels in one
// load, where it reads a storage buffer's word lane by lane (see `u`). start_pixel puts
// them in its copy of the settings.
struct Flat {
    @builtin(position) pos: vec4<f32>,
    @location(0) @interpolate(flat) v1: vec4<f32>,
    @location(1) @interpolate(flat) v2: vec4<f32>,
    @location(2) @interpolate(flat) n1: vec4<f32>,
    @location(3) @interpolate(flat) n2: vec4<f32>,
    @location(4) @interpolate(flat) center: vec4<f32>,
    @location(5) @interpolate(flat) half0: vec4<f32>,
    @location(6) @interpolate(flat) misc: vec4<f32>,
    @location(7) @interpolate(flat) root: vec4<f32>,
    @location(8) @interpolate(flat) size: vec4<u32>,
    @location(9) @interpolate(flat) control: vec4<u32>,
}

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> Flat {
    let x = f32((i << 1u) & 2u) * 2.0 - 1.0;
    let y = f32(i & 2u) * 2.0 - 1.0;
    var o: Flat;
    o.pos = vec4<f32>(x, y, 0.0, 1.0);
    o.v1 = settings.v1;
    o.v2 = settings.v2;
    o.n1 = settings.n1;
    o.n2 = settings.n2;
    o.center = settings.center;
    o.half0 = settings.half0;
    o.misc = settings.misc;
    o.root = settings.root;
    o.size = settings.size;
    o.control = settings.control;
    return o;
}

// What a pixel's entry point returns where it finds no root (a SIMD rasterizer would run
// its loops once for a group of such pixels, with every lane masked).
@fragment
fn fs_background() -> @location(0) vec4<f32> {
    return vec4<f32>(settings.background.rgb, 1.0);
}

// The pixels' entry points, one per source of boxes (MODE) and per kind of pixel, plain
// (here) or certified (CERTIFY, docs/method.md §5.9: its verdict too, in certify.wgsl,
// which a shader that draws plain pixels only leaves out), so that a pipeline's compile
// meets no other mode's code and a plain one no certified search: a driver inlines every
// call before it drops the branches a pipeline constant rules out (docs/benchmarks.md,
// "An edit through the viewer's session").
@fragment
fn fs_tiles(fl: Flat) -> @location(0) vec4<f32> {
    var tr = start_pixel(fl);
    cast_tiles(&tr, vec2<u32>(fl.pos.xy));
    return plain_color(tr, fl);
}

@fragment
fn fs_walk(fl: Flat) -> @location(0) vec4<f32> {
    var tr = start_pixel(fl);
    cast_walk(&tr);
    return plain_color(tr, fl);
}

@fragment
fn fs_brute_force(fl: Flat) -> @location(0) vec4<f32> {
    var tr = start_pixel(fl);
    cast_brute_force(&tr);
    return plain_color(tr, fl);
}

fn plain_color(tr: Tracer, fl: Flat) -> vec4<f32> {
    return pixel_color(tr, vec2<u32>(fl.pos.xy), CERT_EMPTY);
}

// The pixel's tracer, before its rays: the settings in `u`, copied from binding 0, but for
// those vs_main hands over.
fn start_pixel(fl: Flat) -> Tracer {
    u = settings;
    let pos = fl.pos;
    u.v1 = fl.v1;
    u.v2 = fl.v2;
    u.n1 = fl.n1;
    u.n2 = fl.n2;
    u.center = fl.center;
    u.half0 = fl.half0;
    u.misc = fl.misc;
    u.root = fl.root;
    u.size = fl.size;
    u.control = fl.control;
    let w = f32(u.size.x);
    let h = f32(u.size.y);
    let s = u.misc.x;
    var tr: Tracer;
    tr.shift = vec2<f32>(s * (pos.x - 0.5 * w), s * (0.5 * h - pos.y));
    tr.o = u.center + tr.shift.x * u.v1 + tr.shift.y * u.v2;
    tr.plane = tr.o;
    if (slice_on()) {
        // The slice's line, from where it enters the sphere around the domain.
        let reach = 0.5 * length(u.domain_hi - u.domain_lo);
        tr.o = tr.o + u.root.z * u.n2 - reach * u.n1;
    }
    let px = vec2<u32>(pos.xy);
    tr.pixel_seed = pcg(px.x + pcg(px.y + pcg(u.control.w + 7919u * u.counts.y)));
    // Successive frames' stratified pencils interleave: frame f turns the pixel's offset by
    // the radical inverse of f, so 2^m frames of n rays are 2^m n evenly spaced rays.
    let base_seed = pcg(px.x + pcg(px.y + pcg(u.control.w)));
    let turn = ldexp(f32(reverseBits(u.counts.y)), -32);
    tr.offset = fract(rand01(base_seed ^ 0x9e3779b9u) + turn);
    tr.k_max = max(min(u.size.w, SLOTS), 1u);
    let inf = ff_inf();
    tr.hits.t = array<f32, 16>(inf, inf, inf, inf, inf, inf, inf, inf, inf, inf, inf, inf, inf, inf, inf, inf);
    tr.hits.far = inf;
    tr.closest = vec3<f32>(0.0, 0.0, inf);
    tr.start0 = vec3<f32>(0.0, 0.0, inf);
    tr.start1 = tr.start0;
    tr.start2 = tr.start0;
    tr.start3 = tr.start0;
    return tr;
}

// Where a pixel's candidate boxes come from: the brute-force baseline (MODE 0), its tile's
// list (1) or a walk of the hierarchy (2); none without rays (u.size.z).
// (llvmpipe stops all loops of an invocation after 65535 iterations in all: see below.)

// The domain as one box.
fn cast_brute_force(tr: ptr<function, Tracer>) {
    if (u.size.z == 0u) {
        return;
    }
    let c = 0.5 * (u.domain_lo + u.domain_hi);
    let half = 0.5 * (u.domain_hi - u.domain_lo);
    let rel = c - (*tr).o;
    var none: PlaneCurvature;
    none.ab = vec4<f32>(-ff_inf(), ff_inf(), -ff_inf(), ff_inf());
    none.c = vec2<f32>(-ff_inf(), ff_inf());
    trace_box(tr, u.domain_lo, u.domain_hi, angles(vec2<f32>(dot(rel, u.n1), dot(rel, u.n2)), length(half)), u.counts.w, vec4<f32>(ff_inf()), none);
}

// The list is nearest first: past the first box that cannot hold a hit nearer than the K
// kept, none can. A pixel whose rays found nothing goes over it again, searching each box
// between the rays (seek_in_plane; all of them, so that the hits kept do not depend on the
// boxes' order; a slice's one ray has no plane to search).
fn cast_tiles(tr: ptr<function, Tracer>, px: vec2<u32>) {
    if (u.size.z == 0u) {
        return;
    }
    let tile = px / max(u.tiling.x, 1u);
    let t = tile.x + tile.y * u.tiling.y;
    // (Tested at the end: see "The pixel's work".)
    let end = tiles[t + 1u];
    let rounds = select(2u, 1u, slice_on());
    for (var round = 0u; round < rounds; round = round + 1u) {
        let seeking = round == 1u;
        var c = tiles[t];
        if ((c < end) & ((*tr).hits.count == 0u)) {
            loop {
                let near = visit_box(tr, tiles[u.tiling.w + c], seeking);
                c = c + 1u;
                if (!near | (c >= end)) {
                    break;
                }
            }
        }
    }
}

// Depth first: a node that passes is entered (its subtree follows it), one that fails, or
// a box marched whole, is skipped past. (Twice, as the lists.)
fn cast_walk(tr: ptr<function, Tracer>) {
    if (u.size.z == 0u) {
        return;
    }
    let rounds = select(2u, 1u, slice_on());
    for (var round = 0u; round < rounds; round = round + 1u) {
        let seeking = round == 1u;
        var i = 0u;
        loop {
            if (i >= u.counts.x) {
                break;
            }
            let node = nodes[i];
            let v = visit(tr, i, seeking);
            let boxed = (node.info & MARCHED) != 0u;
            i = select(node.skip, i + 1u, v.x & v.y & !boxed);
        }
        if ((*tr).hits.count > 0u) {
            break;
        }
    }
}

// A pixel's certified verdict (certify.wgsl), in its colour's alpha (see pixel_color).
const CERT_EMPTY: u32 = 0u;
const CERT_HIT: u32 = 1u;
const CERT_UNDECIDED: u32 = 2u;
// The ray index of a hit found along the ray aimed through a certified root.
const AIMED: u32 = 0xffffffffu;
// Undecided pixels: filled with this colour, or hatched with it (flag 1024).
const UNDECIDED_COLOR = vec3<f32>(1.0, 0.0, 1.0);

// What an undecided pixel with no hit shows: the marker colour, or (flag 1024) stripes of
// it over the background.
fn undecided_color(px: vec2<u32>) -> vec3<f32> {
    let stripe = ((px.x + px.y) / 3u) % 2u == 0u;
    let hatch = (u.control.z & 1024u) != 0u;
    return select(UNDECIDED_COLOR, u.background.rgb, hatch & !stripe);
}

// The pixel's colour from its hits, with its certified verdict (CERT_EMPTY where not
// certified) in alpha: 255 - 2 verdict - cut, cut flagging loops the driver cut short.
fn pixel_color(tr: Tracer, px: vec2<u32>, verdict: u32) -> vec4<f32> {
    // Did the driver cut this invocation's loops short? A loop that must run 3 times runs
    // once when the iteration cap is spent; the pixel is then marked with alpha 254/255 so
    // that the caller can tell the user (the picture may miss parts of M).
    // (The bound reads the settings so that no compiler unrolls the loop away.)
    let rounds = 3u + (u.control.x >> 31u);
    var probe = 0u;
    loop {
        probe = probe + 1u;
        if (probe >= rounds) {
            break;
        }
    }
    let alpha = f32(255u - 2u * verdict - select(1u, 0u, probe >= rounds)) / 255.0;
    let count = tr.hits.count;
    if ((count == 0u) & ((u.control.z & 4096u) != 0u)) {
        // A pass blended into a certified picture keeps what it proved here (FLAG_KEEP_MISSES).
        discard;
    }
    if (count == 0u) {
        let empty = select(u.background.rgb, undecided_color(px), verdict == CERT_UNDECIDED);
        return vec4<f32>(empty, alpha);
    }
    // Blend the hits farthest first (count >= 1; tested at the end: see "The pixel's work").
    let n = u.size.z;
    var color = vec3<f32>(0.0);
    var j = 0u;
    loop {
        let idx = count - 1u - j;
        let hit = hit_at(tr.hits, idx);
        var dir = select(ray_dir2(hit.y, n, tr.pixel_seed, tr.offset), vec2<f32>(1.0, 0.0), slice_on());
        dir = select(dir, plane_ray_dir(hit.y), (hit.y & PLANE_ROOT) != 0u);
        dir = select(dir, tr.aim, hit.y == AIMED);
        let d = dir.x * u.n1 + dir.y * u.n2;
        let c = shade(tr.o + bitcast<f32>(hit.x) * d, d);
        if (j == 0u) {
            color = c;
        } else {
            color = color * (1.0 - u.misc.y) + c * u.misc.y;
        }
        j = j + 1u;
        if (j >= count) {
            break;
        }
    }
    return vec4<f32>(clamp(color, vec3<f32>(0.0), vec3<f32>(1.0)), alpha);
}
