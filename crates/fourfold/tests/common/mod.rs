//! Helpers shared by the integration tests.
#![allow(dead_code)]

use fourfold::CompiledFormula;
use fourfold::eval::PointEvaluator;
use std::sync::atomic::AtomicBool;

use fourfold::render::Prepared;
use fourfold::scene::{EXAMPLES, Scene};
use fourfold::tree::{BuildSettings, Tree16};

/// A small deterministic generator (xorshift64*), so failures reproduce.
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
}

/// Every example scene, parsed.
pub fn example_scenes() -> Vec<(&'static str, Scene)> {
    EXAMPLES
        .iter()
        .map(|(name, text)| {
            (
                *name,
                Scene::parse(text, name).expect("example scenes parse"),
            )
        })
        .collect()
}

/// The example scenes named in `names`, in the examples' order.
pub fn example_scenes_named(names: &[&str]) -> Vec<(&'static str, Scene)> {
    example_scenes()
        .into_iter()
        .filter(|(n, _)| names.contains(n))
        .collect()
}

/// F at a point with the given parameter values.
pub fn eval_f(formula: &CompiledFormula, p: [f64; 4], params: &[f64]) -> f64 {
    PointEvaluator::new().eval(&formula.tape_f, p, params)
}

/// The compiled formula, its parameter values and its tree, for `scene` with `settings`
/// (the preparation the CLI and the viewer make).
pub fn build(scene: &Scene, settings: BuildSettings) -> (CompiledFormula, Vec<f64>, Tree16) {
    let f = CompiledFormula::compile(&scene.formula).unwrap();
    let prepared = Prepared::build(&f, scene, settings, &AtomicBool::new(false), None).unwrap();
    (f, prepared.params, prepared.tree)
}

/// The pixels of an RGBA8 texture (made with COPY_SRC), rows top to bottom.
pub fn read_texture(gpu: &fourfold::render::Gpu, texture: &wgpu::Texture) -> Vec<u8> {
    let (w, h) = (texture.width(), texture.height());
    let row = w * 4;
    let padded =
        row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: u64::from(padded * h),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    encoder.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(padded),
                rows_per_image: Some(h),
            },
        },
        texture.size(),
    );
    gpu.queue.submit([encoder.finish()]);
    buffer
        .slice(..)
        .map_async(wgpu::MapMode::Read, |r| r.unwrap());
    gpu.device
        .poll(wgpu::PollType::wait_indefinitely())
        .unwrap();
    let data = buffer.slice(..).get_mapped_range().unwrap();
    (0..h as usize)
        .flat_map(|y| data[y * padded as usize..][..row as usize].to_vec())
        .collect()
}

/// Shares of pixels whose colours agree within `tolerance` per channel, and of pixels that
/// agree on showing M (not the background).
pub fn agreement(a: &[u8], b: &[u8], background: [u8; 3], tolerance: u8) -> (f64, f64) {
    let n = (a.len() / 4) as f64;
    let close = a
        .chunks(4)
        .zip(b.chunks(4))
        .filter(|(p, q)| p.iter().zip(*q).all(|(x, y)| x.abs_diff(*y) <= tolerance))
        .count() as f64;
    let cover = coverage(a, background)
        .iter()
        .zip(coverage(b, background))
        .filter(|(p, q)| **p == *q)
        .count() as f64;
    (close / n, cover / n)
}

/// Pixels that are not background.
pub fn coverage(rgba: &[u8], background: [u8; 3]) -> Vec<bool> {
    rgba.chunks(4).map(|p| p[..3] != background).collect()
}
