//! Stage 5: drawing. One view's camera and settings ([`view`]), the shader
//! ([`shader`]), the GPU ray caster ([`gpu`]) and its CPU twin ([`twin`]), the verdicts of
//! certified pixels ([`verdict`]), and over them the picture API ([`picture`]) every front
//! end draws with; [`prepare`] makes the tree a picture is drawn from, [`animation`] says
//! what moves from frame to frame, [`frames`] starts an animation's frames and [`gif`]
//! writes them.

pub mod animation;
pub mod apng;
pub mod frames;
pub mod gif;
pub mod gpu;
pub mod picture;
pub mod prepare;
pub mod program;
pub mod shader;
pub mod twin;
pub mod verdict;
pub mod view;

pub use frames::AnimationFrames;
pub use gpu::{Gpu, GpuError, Pass, RayCaster, Target, check_image_size};
pub use picture::{
    CPU_SLICE_PIXELS_PER_THREAD, Device, Painter, PendingPicture, Picture, RenderError, Source,
    StageTimes, cpu_slice_pixels, sooner_on_cpu,
};
pub use prepare::{PrepareSteps, Prepared, view_region};
pub use program::{Program, ProgramError};
pub use shader::{CodegenError, Shader};
pub use view::{Camera, FrameOptions, Rotation4, TileLists, Uniforms};
