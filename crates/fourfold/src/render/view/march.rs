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
