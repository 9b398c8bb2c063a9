//! Progressive drawing: the viewer never asks the GPU for more than about one UI frame's
//! worth of rays at a time, so the window stays responsive even on a software GPU.
//!
//! A picture is drawn in stages: a coarse preview (every `div`-th pixel, few rays, sized from
//! the measured ray throughput so that it fits in one frame), a half-resolution pass, the
//! full picture with the scene's rays, and then further full passes with new ray offsets that
//! are averaged into it (the picture converges; nothing flickers). Each stage is drawn in
//! square tiles, as many per UI frame as fit in the time budget. Any change (view, settings,
//! new tree) starts again from the preview, while the last picture stays on screen.

mod binning;
mod cpu_preview;
mod paint;
mod stages;
mod state;
mod textures;

pub use binning::Binner;
pub use cpu_preview::CpuPreviews;
pub use paint::{Done, Paint};
pub use stages::{ACCUMULATED_PASSES, ViewKey};
pub use state::{Progressive, Subject};
pub use textures::StageTexture;
