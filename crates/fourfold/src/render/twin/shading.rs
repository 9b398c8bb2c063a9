//! What the CPU twin shares with the shader beside the march: where a pixel's plane and
//! rays start, the colours (a hit's shading, viridis, the undecided marker, the slice's
//! mark, a channel's byte), the hashes that place rays, and vector arithmetic in f32 as the
//! GPU does it.

use crate::ops::powi;
use crate::render::view::{
    FLAG_BORDER, FLAG_HATCH, FLAG_HIDDEN, FLAG_LIGHTING, FLAG_MARK, FLAG_SILHOUETTE, FLAG_SLICE,
    Uniforms,
};

pub(super) type V4 = [f32; 4];

/// The colour of a hit at `p` seen along `d`, where ∇F is `g` (as the shader's `shade`):
/// the silhouette's, the border's or the slice's mark where one applies, else the surface's
/// lit (a slice's normal is ∇F within its hyperplane).
pub(super) fn shade(u: &Uniforms, p: V4, d: V4, g: V4) -> [f32; 3] {
    let mut g = g;
    if u.control.flags & FLAG_SLICE != 0 {
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
    let specular = highlight(dot(r, scale(d, -1.0)).max(0.0), u.shading.shininess);
    std::array::from_fn(|i| {
        surface[i] * (u.shading.ambient + u.shading.diffuse * diffuse)
            + u.shading.specular * specular
    })
}

/// `facing` to the power `shininess`: by products in f64 where the shininess is a whole
/// number (the default 24 among them: f32's power, but for a last bit now and then, in a
/// fraction of the time), else by f32's power.
fn highlight(facing: f32, shininess: f32) -> f32 {
    if shininess.fract() == 0.0 && (1.0..=64.0).contains(&shininess) {
        powi(f64::from(facing), shininess as i32) as f32
    } else {
        facing.powf(shininess)
    }
}

/// Undecided pixels' colour (as the shader's `UNDECIDED_COLOR`).
pub(super) const UNDECIDED_COLOR: [f32; 3] = [1.0, 0.0, 1.0];

/// The colour of the hits where a slice cuts (as the shader's `MARK_COLOR`).
pub(super) const MARK_COLOR: [f32; 3] = [1.0, 0.35, 0.1];

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
pub(super) fn base_color(u: &Uniforms, p: V4) -> [f32; 3] {
    if u.control.flags & FLAG_HIDDEN == 0 {
        return [u.surface[0], u.surface[1], u.surface[2]];
    }
    let centre: V4 = std::array::from_fn(|i| 0.5 * (u.domain_lo[i] + u.domain_hi[i]));
    let (lo, hi) = (u.hidden.lo, u.hidden.hi);
    viridis((dot(sub(p, centre), u.n2) - lo) / (hi - lo))
}

/// An undecided pixel with no hit: the marker colour, or its stripes over the background
/// (as the shader's `undecided_color`).
pub(super) fn undecided_color(u: &Uniforms, px: u32, py: u32) -> [f32; 3] {
    let stripe = ((px + py) / 3).is_multiple_of(2);
    if u.control.flags & FLAG_HATCH != 0 && !stripe {
        [u.background[0], u.background[1], u.background[2]]
    } else {
        UNDECIDED_COLOR
    }
}

/// The part of a ray's span within the slab, as the shader's `clip_to_slab`.
pub(super) fn clip_to_slab(u: &Uniforms, (t0, t1): (f32, f32), b: f32) -> (f32, f32) {
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

/// The pixel's offset of its stratified rays in a frame, as the shader's `start_pixel`: the
/// frame's turn (the radical inverse of the frame) added to the pixel's own offset, so that
/// successive frames' pencils interleave.
pub(super) fn stratified_offset(seed: u32, frame: u32, px: u32, py: u32) -> f32 {
    let base = pcg(px.wrapping_add(pcg(py.wrapping_add(pcg(seed)))));
    let turn = frame.reverse_bits() as f32 * 2f32.powi(-32);
    let x = rand01(base ^ 0x9e37_79b9) + turn;
    x - x.floor()
}

pub(super) fn dot(a: V4, b: V4) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]
}

pub(super) fn add(a: V4, b: V4) -> V4 {
    std::array::from_fn(|i| a[i] + b[i])
}

pub(super) fn sub(a: V4, b: V4) -> V4 {
    std::array::from_fn(|i| a[i] - b[i])
}

pub(super) fn scale(a: V4, s: f32) -> V4 {
    a.map(|v| v * s)
}

pub(super) fn pcg(v: u32) -> u32 {
    let state = v.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

pub(super) fn rand01(v: u32) -> f32 {
    (pcg(v) >> 8) as f32 / 16_777_216.0
}

/// A channel in [0, 1] as a byte, rounded to nearest, halves up: `(v · 255).round()`, but
/// with the half added in f64 (exact for an f32) and cut off, not a call to libm's `roundf`
/// (3% of a plain slice's frame).
pub(super) fn unorm8(v: f32) -> u8 {
    (f64::from(v.clamp(0.0, 1.0) * 255.0) + 0.5) as u8
}

/// The origin of the observer plane through the point (fx, fy) of the picture (in pixels
/// from its top left corner), and that of its rays: for a slice, the slice's line from
/// where it enters the sphere around the domain (as the shader).
pub(super) fn origins(u: &Uniforms, (fx, fy): (f32, f32)) -> (V4, V4) {
    let (w, hgt) = (u.size.width as f32, u.size.height as f32);
    let s = u.misc.pixel_size;
    let plane = add(
        u.center,
        add(
            scale(u.v1, s * (fx - 0.5 * w)),
            scale(u.v2, s * (0.5 * hgt - fy)),
        ),
    );
    if u.control.flags & FLAG_SLICE == 0 {
        return (plane, plane);
    }
    let line = sub(
        add(plane, scale(u.n2, u.root.section_offset)),
        scale(u.n1, slice_reach(u)),
    );
    (plane, line)
}

/// How far before the slice's place along n1 its rays start: the domain's half diagonal (the
/// sphere around the domain).
pub(super) fn slice_reach(u: &Uniforms) -> f32 {
    let extent = sub(u.domain_hi, u.domain_lo);
    0.5 * dot(extent, extent).sqrt()
}

/// dF/dt along `d` from ∇F, in f64 (as the evaluator's outputs, exact in f32, multiply).
pub(super) fn slope(g: V4, d: V4) -> f32 {
    (0..4)
        .map(|k| f64::from(g[k]) * f64::from(d[k]))
        .sum::<f64>() as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn rounded(v: f32) -> u8 {
        (v.clamp(0.0, 1.0) * 255.0).round() as u8
    }

    proptest! {
        /// A channel's byte is `(v · 255).round()`'s, for any value.
        #[test]
        fn a_channel_s_byte_is_its_value_rounded(v in -0.5f32..1.5) {
            prop_assert_eq!(unorm8(v), rounded(v));
        }
    }

    /// The same at and beside every halfway point, and beyond [0, 1] and NaN.
    #[test]
    fn a_channel_s_byte_rounds_halves_as_round_does() {
        for k in 0..=255u32 {
            let half = (k as f32 + 0.5) / 255.0;
            let mut v = half;
            for _ in 0..4 {
                v = f32::from_bits(v.to_bits() - 1);
            }
            for _ in 0..9 {
                assert_eq!(unorm8(v), rounded(v), "{v}");
                v = f32::from_bits(v.to_bits() + 1);
            }
        }
        for v in [f32::NAN, f32::INFINITY, -1.0, 0.0, -0.0, 1.0, 2.0] {
            assert_eq!(unorm8(v), rounded(v), "{v}");
        }
    }
}
