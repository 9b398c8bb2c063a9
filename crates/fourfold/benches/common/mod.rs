//! What the benchmarks share: the device they draw on and their settings from the
//! environment.
#![allow(dead_code)]

use fourfold::render::Gpu;

/// The first adapter wgpu finds; a benchmark without one says why and stops.
pub fn gpu_or_exit() -> Gpu {
    Gpu::new().unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(1);
    })
}

/// The number in the environment variable `name`, else `default`.
pub fn env_u32(name: &str, default: u32) -> u32 {
    std::env::var(name)
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

/// The levels in `FOURFOLD_BENCH_LEVELS` (as "6,8"), else `default`.
pub fn bench_levels(default: &str) -> Vec<u32> {
    std::env::var("FOURFOLD_BENCH_LEVELS")
        .unwrap_or_else(|_| default.into())
        .split(',')
        .map(|l| {
            l.trim()
                .parse()
                .expect("FOURFOLD_BENCH_LEVELS: levels like 6,8")
        })
        .collect()
}
