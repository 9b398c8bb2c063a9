//! The CPU twin of the GPU: the method of `templates/raycast.wgsl`, step for step, in Rust
//! (f32 geometry like the GPU, F evaluated in f64 by the point evaluator), and the twin of
//! its certified pixels' search in rigorous f64 intervals. Same hierarchy, same uniforms,
//! same hash and sampling, so GPU and CPU pictures can be compared pixel for pixel.

mod abreast;
mod bundle;
mod certify;
mod evals;
mod forms;
mod frame;
mod march;
mod pixel;
mod root;
mod section;
mod seek;
mod shading;
mod tile;
mod traced;
mod walk;

pub use certify::{CERT_STACK, Certifier, Outcome};
pub use frame::render_rgba;
pub use shading::viridis;
