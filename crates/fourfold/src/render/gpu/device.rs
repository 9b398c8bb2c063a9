//! The device the ray caster draws on, and what it may draw: the storage buffers its
//! shader reads, its colour format, and the largest picture it can read back.

use std::path::PathBuf;
use std::sync::Arc;

use super::cache::CacheDir;
use crate::render::view::tiles::MAX_ENTRIES;

/// Storage buffers the ray caster's shaders read (bindings 0-6; the interpreting shader's
/// program is binding 7). WebGPU's default limit is 8.
pub const STORAGE_BUFFERS: u32 = 8;

/// The colour format the ray caster writes.
pub const TARGET_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    #[error(
        "no GPU adapter found ({0}). On Linux without a GPU, install Mesa's software Vulkan \
         driver: apt-get install -y mesa-vulkan-drivers (or render with --cpu)"
    )]
    NoAdapter(String),
    #[error("the GPU device could not be created: {0}")]
    Device(String),
    #[error("the GPU rejected the shader or pipeline: {0}")]
    Pipeline(String),
    #[error(
        "the tree has {nodes} nodes (a {bytes}-byte buffer), over this GPU's storage-buffer limit of {limit} bytes; lower max_level or node_budget"
    )]
    TooLarge {
        nodes: usize,
        bytes: u64,
        limit: u64,
    },
    #[error("the interpreting shader cannot draw this formula: {0}")]
    Interpret(#[from] crate::render::shader::InterpretError),
    #[error("reading the picture back from the GPU failed: {0}")]
    Readback(String),
    #[error(
        "a {width}x{height} image is over this GPU's limit ({reason}); use a smaller --size, \
         at most {max_side}x{max_side} here, or render with --cpu"
    )]
    ImageTooLarge {
        width: u32,
        height: u32,
        max_side: u32,
        reason: String,
    },
}

/// Whether this device can draw and read back a `width`×`height` picture: its sides within
/// the largest texture side, and its read-back buffer (rows padded to 256 bytes) within the
/// largest buffer.
pub fn check_image_size(width: u32, height: u32, limits: &wgpu::Limits) -> Result<(), GpuError> {
    let max_side = limits.max_texture_dimension_2d;
    let row = (u64::from(width) * 4).div_ceil(u64::from(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT))
        * u64::from(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
    let bytes = row * u64::from(height);
    let reason = if width > max_side || height > max_side {
        format!("its largest texture side is {max_side} pixels")
    } else if bytes > limits.max_buffer_size {
        format!(
            "reading it back takes {bytes} bytes, over its largest buffer of {} bytes",
            limits.max_buffer_size
        )
    } else {
        return Ok(());
    };
    // The largest square within both limits.
    let by_buffer = ((limits.max_buffer_size / 4) as f64).sqrt() as u32 / 64 * 64;
    Err(GpuError::ImageTooLarge {
        width,
        height,
        max_side: max_side.min(by_buffer.max(1)),
        reason,
    })
}

/// The adapter as pictures and status lines name it: its name, backend and kind (a browser
/// tells a page no name: "WebGPU" stands for it).
pub fn describe_adapter(info: &wgpu::AdapterInfo) -> String {
    let name = if info.name.is_empty() {
        "WebGPU"
    } else {
        &info.name
    };
    format!("{name} ({:?}, {:?})", info.backend, info.device_type)
}

/// A device and queue, with a description of the adapter. Cloning shares them.
#[derive(Clone)]
pub struct Gpu {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub adapter: String,
    /// The adapter is a CPU's (llvmpipe, SwiftShader): it compiles a shader in a tenth of
    /// the time a GPU's driver takes, and draws many times slower.
    pub software: bool,
    /// Where ray casters keep their compiled pipelines between runs (None: nowhere; the
    /// device has the `PIPELINE_CACHE` feature wherever this is set).
    pub pipeline_cache: Option<Arc<CacheDir>>,
}

impl Gpu {
    /// How many words tile lists (offsets and entries) may hold on this device: MAX_ENTRIES,
    /// or less where the device's storage-buffer limit is lower.
    pub fn tile_entry_budget(&self) -> usize {
        let words = self.device.limits().max_storage_buffer_binding_size / 4;
        usize::try_from(words).map_or(MAX_ENTRIES, |w| w.min(MAX_ENTRIES))
    }

    /// Whether frames can be timed on the GPU (`RayCaster::render_rgba_timed`).
    pub fn has_timestamps(&self) -> bool {
        self.device
            .features()
            .contains(wgpu::Features::TIMESTAMP_QUERY)
    }

    /// From a device someone else made (the viewer's) on the adapter `info` describes,
    /// keeping no pipeline cache.
    pub fn from_parts(device: wgpu::Device, queue: wgpu::Queue, info: &wgpu::AdapterInfo) -> Self {
        Self {
            device,
            queue,
            adapter: describe_adapter(info),
            software: info.device_type == wgpu::DeviceType::Cpu,
            pipeline_cache: None,
        }
    }

    /// Keeps compiled pipelines in `dir` (None: nowhere), where the device can (its adapter
    /// is `info`, and it has the `PIPELINE_CACHE` feature).
    pub fn with_pipeline_cache(mut self, dir: Option<PathBuf>, info: &wgpu::AdapterInfo) -> Self {
        let able = self
            .device
            .features()
            .contains(wgpu::Features::PIPELINE_CACHE);
        self.pipeline_cache = dir
            .filter(|_| able)
            .and_then(|d| CacheDir::new(d, info))
            .map(Arc::new);
        self
    }
}
