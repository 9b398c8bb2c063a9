//! A GPU device of one's own, opened without a window: the first adapter wgpu finds, with
//! the limits the ray caster can use.

use std::path::PathBuf;

use crate::render::gpu::{Gpu, GpuError, STORAGE_BUFFERS};

impl Gpu {
    /// Opens the first adapter wgpu finds (any backend, or those named in WGPU_BACKEND),
    /// headless, keeping compiled pipelines in [`pipeline_cache_dir`].
    pub fn new() -> Result<Self, GpuError> {
        Self::with_cache_dir(pipeline_cache_dir())
    }

    /// As [`Gpu::new`], keeping compiled pipelines in `cache` (None: nowhere).
    pub fn with_cache_dir(cache: Option<PathBuf>) -> Result<Self, GpuError> {
        let from_env = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        // Without WGPU_BACKEND, the primary backends (Vulkan, Metal, DX12) first: their
        // adapters take the ray caster's storage buffers, and setting up OpenGL as well
        // (probing EGL) cost 10-20 ms of a 40-55 ms opening on lavapipe. OpenGL only where
        // none of them has an adapter.
        let first = if std::env::var_os("WGPU_BACKEND").is_none() {
            let primary = wgpu::InstanceDescriptor {
                backends: from_env.backends & wgpu::Backends::PRIMARY,
                ..wgpu::InstanceDescriptor::new_without_display_handle_from_env()
            };
            request_adapter(primary).ok()
        } else {
            None
        };
        let (_instance, adapter) = match first {
            Some(found) => found,
            None => request_adapter(from_env)?,
        };
        let info = adapter.get_info();
        let limits = adapter.limits();
        if limits.max_storage_buffers_per_shader_stage < STORAGE_BUFFERS {
            return Err(GpuError::Device(format!(
                "{} reads at most {} storage buffers in a shader, and the ray caster needs {}; \
                 use a Vulkan, Metal or DX12 adapter (WGPU_BACKEND=vulkan, or on Linux without \
                 a GPU: apt-get install -y mesa-vulkan-drivers), or render with --cpu",
                info.name, limits.max_storage_buffers_per_shader_stage, STORAGE_BUFFERS
            )));
        }
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("fourfold"),
            // Where the adapter has them: GPU timestamps around a frame's pass
            // (`RayCaster::render_rgba_timed`), and pipeline caches kept between runs.
            required_features: adapter.features()
                & (wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::PIPELINE_CACHE),
            // The adapter's own limits where fourfold can use more than the defaults: tile
            // lists and trees in storage buffers, and the largest picture (`render --size`).
            required_limits: wgpu::Limits {
                max_storage_buffer_binding_size: limits.max_storage_buffer_binding_size,
                max_buffer_size: limits.max_buffer_size,
                max_texture_dimension_2d: limits.max_texture_dimension_2d,
                max_storage_buffers_per_shader_stage: STORAGE_BUFFERS,
                ..wgpu::Limits::downlevel_defaults()
            },
            ..Default::default()
        }))
        .map_err(|e| GpuError::Device(e.to_string()))?;
        Ok(Self::from_parts(device, queue, &info).with_pipeline_cache(cache, &info))
    }
}

/// An instance of `backends` and its first adapter, preferring a high-performance one.
fn request_adapter(
    desc: wgpu::InstanceDescriptor,
) -> Result<(wgpu::Instance, wgpu::Adapter), GpuError> {
    let instance = wgpu::Instance::new(desc);
    let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
        power_preference: wgpu::PowerPreference::HighPerformance,
        ..Default::default()
    }))
    .map_err(|e| GpuError::NoAdapter(e.to_string()))?;
    Ok((instance, adapter))
}

/// Where compiled pipelines are kept between runs: `FOURFOLD_CACHE_DIR` if set (empty or
/// `off`: nowhere), else `fourfold/pipelines` in the user's cache directory
/// (`~/.cache` on Linux).
pub fn pipeline_cache_dir() -> Option<PathBuf> {
    match std::env::var_os("FOURFOLD_CACHE_DIR") {
        Some(dir) if dir.is_empty() || dir == "off" => None,
        Some(dir) => Some(PathBuf::from(dir)),
        None => dirs::cache_dir().map(|d| d.join("fourfold").join("pipelines")),
    }
}
