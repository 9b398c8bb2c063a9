//! Rules of the ray march that the shader states in WGSL and the CPU twin in Rust: how many
//! steps a box's span takes, and how far a ray's slope bound lets a step go.

/// `steps · 2^levels_up`, at most 2^16 (the shader's rule, see templates/raycast.wgsl).
pub fn march_steps(steps: u32, levels_up: u32) -> u32 {
    let up = levels_up.min(16);
    if steps <= (1 << 16) >> up {
        steps << up
    } else {
        1 << 16
    }
}

/// A bound on |∇F·d| (d a unit vector) from bounds on |∂F/∂x_k|, rounded up past f32's
/// rounding; +∞ if any bound is. The CPU reference's rule for a ray's slope; the shader
/// states it in WGSL (`trace_box`: slope · |d|, in f32, with the march's 0.999 margin).
pub fn slope_along(slope: [f32; 4], d: [f64; 4]) -> f32 {
    if slope.iter().any(|s| !s.is_finite()) {
        return f32::INFINITY;
    }
    let sum: f64 = (0..4).map(|k| f64::from(slope[k]) * d[k].abs()).sum();
    (sum * (1.0 + 1e-6)) as f32
}

/// The bit that marks a hit found between the pencil's rays by the search in the observer
/// plane; the low 24 bits hold its ray's angle there as a fraction of a turn (the shader's
/// `PLANE_ROOT`, see templates/raycast/seek.wgsl).
pub const PLANE_ROOT: u32 = 1 << 31;

/// The ray id of a hit found by the search along `dir` (a unit vector in n1, n2), in f32 as
/// the shader works it out.
pub fn plane_ray(dir: [f32; 2]) -> u32 {
    let turn = (dir[1].atan2(dir[0]) / std::f32::consts::TAU + 1.0).fract();
    PLANE_ROOT | ((turn * 16_777_216.0) as u32).min(0xff_ffff)
}

/// The direction, in (n1, n2), of a ray from `plane_ray`.
pub fn plane_ray_dir(ray: u32) -> [f32; 2] {
    let phi = std::f32::consts::TAU * (ray & 0xff_ffff) as f32 / 16_777_216.0;
    [phi.cos(), phi.sin()]
}
