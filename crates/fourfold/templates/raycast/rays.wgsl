fn pcg(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

fn rand01(v: u32) -> f32 {
    return f32(pcg(v) >> 8u) / 16777216.0;
}

// Whether the rays are the chapter's random ones (else stratified): see SAMPLING.
fn random_rays() -> bool {
    if (SAMPLING == 2u) {
        return (u.control.z & 8u) != 0u;
    }
    return SAMPLING == 1u;
}

// Whether rays keep to a slab (root.z, root.w: its middle and half width along n2).
fn slab_on() -> bool {
    if (SECTION == 3u) {
        return (u.control.z & 32u) != 0u;
    }
    return SECTION == 1u;
}

// Whether each pixel casts one ray along n1, at root.z along n2: a slice (docs/method.md §5.8).
fn slice_on() -> bool {
    if (SECTION == 3u) {
        return (u.control.z & 64u) != 0u;
    }
    return SECTION == 2u;
}

// The part of a ray's span [t0, t1] within the slab: the ray o + t d, d = a n1 + b n2, is at
// t b along n2 from the domain's centre (o lies in the plane through it spanned by v1, v2).
fn clip_to_slab(span: vec2<f32>, b: f32) -> vec2<f32> {
    let lo = u.root.z - u.root.w;
    let hi = u.root.z + u.root.w;
    if (abs(b) < 1e-30) {
        return select(vec2<f32>(1.0, 0.0), span, (lo <= 0.0) & (0.0 <= hi));
    }
    let ta = lo / b;
    let tb = hi / b;
    return vec2<f32>(max(span.x, min(ta, tb)), min(span.y, max(ta, tb)));
}

// Direction k of n in the observer plane, as (n1, n2) coefficients (docs/method.md §5.2).
fn ray_dir2(k: u32, n: u32, pixel_seed: u32, offset: f32) -> vec2<f32> {
    if (random_rays()) {
        let a = vec2<f32>(2.0 * rand01(pixel_seed + 2u * k) - 1.0, 2.0 * rand01(pixel_seed + 2u * k + 1u) - 1.0);
        let len = length(a);
        if (len < 1e-6) {
            return vec2<f32>(1.0, 0.0);
        }
        return a / len;
    }
    let phi = TAU * (f32(k) + offset) / f32(n);
    return vec2<f32>(cos(phi), sin(phi));
}

// The K nearest hits (docs/method.md §5.5), sorted, in a fixed array read only at constant indices
// (so that a compiler can keep it in registers): empty slots hold +inf.
struct Hits {
    t: array<f32, MAX_HITS>,
    ray: array<u32, MAX_HITS>,
    count: u32,
    far: f32, // the K-th nearest t once K are kept, else +inf: nothing beyond it matters
}

// Keeps the K smallest t, sorted (docs/method.md §5.5). Written out without loops or varying
// indices: on a SIMD rasterizer every branch runs for every pixel, and an index that varies
// sends an array to memory. Slot i takes the new hit if it lies between slots i - 1 and i
// (after hits at the same t, as a stable insertion does), the hit of slot i - 1 if the new
// one lies before that, and keeps its own otherwise: no slot depends on another's result.
fn insert_hit(tr: ptr<function, Tracer>, t: f32) {
    let k_max = (*tr).k_max;
    let ray = (*tr).k;
    let old_t = (*tr).hits.t;
    let old_r = (*tr).hits.ray;
    (*tr).hits.t[0] = min(old_t[0], t);
    (*tr).hits.ray[0] = select(old_r[0], ray, t < old_t[0]);
    (*tr).hits.t[1] = min(old_t[1], max(t, old_t[0]));
    (*tr).hits.ray[1] = select(old_r[1], select(old_r[0], ray, t >= old_t[0]), t < old_t[1]);
    (*tr).hits.t[2] = min(old_t[2], max(t, old_t[1]));
    (*tr).hits.ray[2] = select(old_r[2], select(old_r[1], ray, t >= old_t[1]), t < old_t[2]);
    (*tr).hits.t[3] = min(old_t[3], max(t, old_t[2]));
    (*tr).hits.ray[3] = select(old_r[3], select(old_r[2], ray, t >= old_t[2]), t < old_t[3]);
    if (SLOTS > 4u) {
        (*tr).hits.t[4] = min(old_t[4], max(t, old_t[3]));
        (*tr).hits.ray[4] = select(old_r[4], select(old_r[3], ray, t >= old_t[3]), t < old_t[4]);
        (*tr).hits.t[5] = min(old_t[5], max(t, old_t[4]));
        (*tr).hits.ray[5] = select(old_r[5], select(old_r[4], ray, t >= old_t[4]), t < old_t[5]);
        (*tr).hits.t[6] = min(old_t[6], max(t, old_t[5]));
        (*tr).hits.ray[6] = select(old_r[6], select(old_r[5], ray, t >= old_t[5]), t < old_t[6]);
        (*tr).hits.t[7] = min(old_t[7], max(t, old_t[6]));
        (*tr).hits.ray[7] = select(old_r[7], select(old_r[6], ray, t >= old_t[6]), t < old_t[7]);
    }
    if (SLOTS > 8u) {
        (*tr).hits.t[8] = min(old_t[8], max(t, old_t[7]));
        (*tr).hits.ray[8] = select(old_r[8], select(old_r[7], ray, t >= old_t[7]), t < old_t[8]);
        (*tr).hits.t[9] = min(old_t[9], max(t, old_t[8]));
        (*tr).hits.ray[9] = select(old_r[9], select(old_r[8], ray, t >= old_t[8]), t < old_t[9]);
        (*tr).hits.t[10] = min(old_t[10], max(t, old_t[9]));
        (*tr).hits.ray[10] = select(old_r[10], select(old_r[9], ray, t >= old_t[9]), t < old_t[10]);
        (*tr).hits.t[11] = min(old_t[11], max(t, old_t[10]));
        (*tr).hits.ray[11] = select(old_r[11], select(old_r[10], ray, t >= old_t[10]), t < old_t[11]);
        (*tr).hits.t[12] = min(old_t[12], max(t, old_t[11]));
        (*tr).hits.ray[12] = select(old_r[12], select(old_r[11], ray, t >= old_t[11]), t < old_t[12]);
        (*tr).hits.t[13] = min(old_t[13], max(t, old_t[12]));
        (*tr).hits.ray[13] = select(old_r[13], select(old_r[12], ray, t >= old_t[12]), t < old_t[13]);
        (*tr).hits.t[14] = min(old_t[14], max(t, old_t[13]));
        (*tr).hits.ray[14] = select(old_r[14], select(old_r[13], ray, t >= old_t[13]), t < old_t[14]);
        (*tr).hits.t[15] = min(old_t[15], max(t, old_t[14]));
        (*tr).hits.ray[15] = select(old_r[15], select(old_r[14], ray, t >= old_t[14]), t < old_t[15]);
    }
    (*tr).hits.count = min((*tr).hits.count + 1u, k_max);
    if ((*tr).hits.count == k_max) {
        (*tr).hits.far = bitcast<f32>(hit_at((*tr).hits, k_max - 1u).x);
    }
}

// Slot i of the hits: (t's bits, ray). A chain of selects: an index that varies would send
// the arrays to memory, where a SIMD rasterizer reads them lane by lane.
fn hit_at(h: Hits, i: u32) -> vec2<u32> {
    var v = vec2<u32>(bitcast<u32>(h.t[0]), h.ray[0]);
    v = select(v, vec2<u32>(bitcast<u32>(h.t[1]), h.ray[1]), i == 1u);
    v = select(v, vec2<u32>(bitcast<u32>(h.t[2]), h.ray[2]), i == 2u);
    v = select(v, vec2<u32>(bitcast<u32>(h.t[3]), h.ray[3]), i == 3u);
    if (SLOTS > 4u) {
        v = select(v, vec2<u32>(bitcast<u32>(h.t[4]), h.ray[4]), i == 4u);
        v = select(v, vec2<u32>(bitcast<u32>(h.t[5]), h.ray[5]), i == 5u);
        v = select(v, vec2<u32>(bitcast<u32>(h.t[6]), h.ray[6]), i == 6u);
        v = select(v, vec2<u32>(bitcast<u32>(h.t[7]), h.ray[7]), i == 7u);
    }
    if (SLOTS > 8u) {
        v = select(v, vec2<u32>(bitcast<u32>(h.t[8]), h.ray[8]), i == 8u);
        v = select(v, vec2<u32>(bitcast<u32>(h.t[9]), h.ray[9]), i == 9u);
        v = select(v, vec2<u32>(bitcast<u32>(h.t[10]), h.ray[10]), i == 10u);
        v = select(v, vec2<u32>(bitcast<u32>(h.t[11]), h.ray[11]), i == 11u);
        v = select(v, vec2<u32>(bitcast<u32>(h.t[12]), h.ray[12]), i == 12u);
        v = select(v, vec2<u32>(bitcast<u32>(h.t[13]), h.ray[13]), i == 13u);
        v = select(v, vec2<u32>(bitcast<u32>(h.t[14]), h.ray[14]), i == 14u);
        v = select(v, vec2<u32>(bitcast<u32>(h.t[15]), h.ray[15]), i == 15u);
    }
    return v;
}

// The span of the ray o + t d, t >= 0, inside the box [lo, hi] (4D slab test).
fn clip_to_box(o: vec4<f32>, d: vec4<f32>, lo: vec4<f32>, hi: vec4<f32>) -> vec2<f32> {
    let safe = select(d, vec4<f32>(1e-30), abs(d) < vec4<f32>(1e-30));
    let inv = 1.0 / safe;
    let ta = (lo - o) * inv;
    let tb = (hi - o) * inv;
    let tmin = min(ta, tb);
    let tmax = max(ta, tb);
    let t0 = max(max(max(tmin.x, tmin.y), max(tmin.z, tmin.w)), 0.0);
    let t1 = min(min(tmax.x, tmax.y), min(tmax.z, tmax.w));
    return vec2<f32>(t0, t1);
}
