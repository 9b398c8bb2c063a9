//! The GPU side of drawing, on wgpu: the device, the ray caster's pipelines and buffers, and
//! frames read back without waiting. Nothing here blocks on the GPU, so it all runs in a
//! web page too; the `headless` module adds the waiting a native program may do.

mod buffers;
mod cache;
mod caster;
mod device;
mod handover;
mod pipelines;
mod readback;

pub use cache::{CacheDir, CacheUse};
pub use caster::RayCaster;
pub use device::{
    Gpu, GpuError, STORAGE_BUFFERS, TARGET_FORMAT, check_image_size, describe_adapter,
};
pub use pipelines::{Fullscreen, Mode, Pass, Target, Variant, fullscreen_pipeline};
pub use readback::{Mapping, PendingRgba, TimedRgba, start_texture_read};
