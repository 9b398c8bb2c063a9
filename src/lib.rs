//! fourfold: type an implicit function F(x, y, z, w) and see the 3-manifold F = 0 in R⁴.
//!
//! The pipeline runs one way, and the modules follow it:
//! [`syntax`] (text → syntax tree) → [`expr`] (graph, ∇F) → [`eval`] (point and interval
//! evaluators) → [`formula`] (the compiled bundle) → [`tree`] (16-tree and sphere hierarchy)
//! → [`render`] (camera, WGSL code generation, GPU and CPU ray casters). [`scene`] holds
//! everything needed to reproduce a picture. The CLI (`src/main.rs`, [`cli`]) and the viewer
//! ([`viewer`]) are thin layers on top.

pub mod eval;
pub mod expr;
pub mod formula;
pub mod gpu_layout;
pub mod render;
pub mod syntax;
pub mod tree;
pub mod viewer;

pub use formula::CompiledFormula;
/// The command line (not in the web page, which has no terminal).
#[cfg(not(target_arch = "wasm32"))]
pub mod cli;
pub mod scene;
