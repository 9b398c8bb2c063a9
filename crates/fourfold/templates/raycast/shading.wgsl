// The colour of the hits where a slice cuts (flag 256).
const MARK_COLOR = vec3<f32>(1.0, 0.35, 0.1);

// The viridis colour map at t in [0, 1], linear between nine samples: dark blue to yellow,
// its lightness rising all the way (perceptually uniform, readable in grey).
fn viridis(t: f32) -> vec3<f32> {
    var stops = array<vec3<f32>, 9>(
        vec3<f32>(68.0, 1.0, 84.0), vec3<f32>(71.0, 45.0, 123.0), vec3<f32>(59.0, 82.0, 139.0),
        vec3<f32>(44.0, 114.0, 142.0), vec3<f32>(33.0, 145.0, 140.0), vec3<f32>(40.0, 174.0, 128.0),
        vec3<f32>(94.0, 201.0, 98.0), vec3<f32>(173.0, 220.0, 48.0), vec3<f32>(253.0, 231.0, 37.0),
    );
    let x = clamp(t, 0.0, 1.0) * 8.0;
    let i = min(u32(x), 7u);
    return mix(stops[i], stops[i + 1u], x - f32(i)) / 255.0;
}

// The colour a hit at p gets before lighting: the surface colour, or (flag 128) its place
// along n2 from the domain's centre, between hidden.x and hidden.y (the manifold's extent).
fn base_color(p: vec4<f32>) -> vec3<f32> {
    if ((u.control.z & 128u) == 0u) {
        return u.surface.rgb;
    }
    let centre = 0.5 * (u.domain_lo + u.domain_hi);
    return viridis((dot(p - centre, u.n2) - u.hidden.x) / (u.hidden.y - u.hidden.x));
}

fn shade(p: vec4<f32>, d: vec4<f32>) -> vec3<f32> {
    var g = ff_grad(p);
    if (slice_on()) {
        // The slice is a surface in the hyperplane: its normal is ∇F within it.
        g = g - dot(g, u.n2) * u.n2;
    }
    let glen = length(g);
    let flags = u.control.z;
    if (((flags & 2u) != 0u) & (glen > 0.0)) {
        let gu = g / glen;
        if ((abs(dot(gu, u.n1)) < u.misc.z) & (abs(dot(gu, u.n2)) < u.misc.z)) {
            return u.silhouette_color.rgb;
        }
    }
    if ((flags & 4u) != 0u) {
        let inside = min(p - u.domain_lo, u.domain_hi - p);
        if (min(min(inside.x, inside.y), min(inside.z, inside.w)) < u.misc.w) {
            return u.border_color.rgb;
        }
    }
    if ((flags & 256u) != 0u) {
        // Where the slice beside the projection cuts (root.z, within root.w along n2).
        let centre = 0.5 * (u.domain_lo + u.domain_hi);
        if (abs(dot(p - centre, u.n2) - u.root.z) < u.root.w) {
            return MARK_COLOR;
        }
    }
    let surface = base_color(p);
    if ((flags & 1u) == 0u) {
        return surface;
    }
    var nrm = vec4<f32>(0.0);
    if (glen > 0.0) {
        nrm = g / glen;
    }
    if (dot(nrm, d) > 0.0) {
        nrm = -nrm;
    }
    let l = u.light;
    let diffuse = max(dot(nrm, l), 0.0);
    let r = 2.0 * dot(nrm, l) * nrm - l;
    let specular = pow(max(dot(r, -d), 0.0), u.shading.w);
    return surface * (u.shading.x + u.shading.y * diffuse) + vec3<f32>(u.shading.z * specular);
}
