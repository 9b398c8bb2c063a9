//! fourfold: type an implicit function F(x, y, z, w) and see the 3-manifold F = 0 in R⁴.
//!
//! Beneath it all: [`interval`], the rigorous interval type every stage computes with, and
//! [`ops`], the table of the language's operations every stage reads.
//! The pipeline runs one way, and the modules follow it:
//! [`syntax`] (text → syntax tree) → [`expr`] (graph, ∇F) → [`eval`] (point and interval
//! evaluators) → [`formula`] (the compiled bundle) → [`tree`] (16-tree and sphere hierarchy)
//! → [`scene`] (everything that reproduces a picture) → [`render`] (camera, WGSL code
//! generation, GPU and CPU ray casters, the picture API). [`platform`] holds the few things
//! a web page does differently; `headless` (native targets only) the drawing that waits for
//! the GPU. The front ends (the viewer, the command line, the web page) are crates of their
//! own over this one: docs/architecture.md maps it all.

pub mod critical;
pub mod eval;
pub mod expr;
pub mod formula;
pub mod gpu_layout;
pub mod interval;
pub mod mesh;
pub mod ops;
pub mod platform;
pub mod render;
pub mod scene;
pub mod syntax;
pub mod tree;

/// Drawing that waits for the GPU (a web page cannot).
#[cfg(not(target_arch = "wasm32"))]
pub mod headless;

pub use formula::CompiledFormula;
