//! Stage 5: drawing. The camera (rotation, planes, pixel → R⁴), WGSL generation and naga
//! validation, the uniform block, the GPU ray caster and its CPU reference twin.

pub mod animation;
pub mod camera;
pub mod certify;
pub mod codegen;
pub mod cpu;
pub mod framing;
pub mod gpu;
pub mod march;
pub mod pipeline;
pub mod prepare;
pub mod probe;
pub mod tiles;
pub mod uniforms;

pub use camera::{Camera, Rotation4};
pub use codegen::{CodegenError, Shader};
pub use gpu::{Gpu, GpuError, Pass, RayCaster, Target, check_image_size};
pub use pipeline::MAX_PICTURE_SIDE;
pub use prepare::{PrepareSteps, Prepared};
pub use tiles::TileLists;
pub use uniforms::{FrameOptions, Uniforms};
