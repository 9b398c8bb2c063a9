//! The viewer's platform edge: what the desktop and the web page do differently. Each side
//! gives the same names (a test of the core checks that no other file of the viewer names a
//! target):
//!
//! - `CERTIFIED_PIXELS`: whether the viewer draws certified pixels;
//! - `WAITS_FOR_GPU`: whether the window's thread may wait for the GPU's work (a page
//!   cannot: its picture's runs are paced by the queue's word that the last is done);
//! - `CRITICAL_BOX_BUDGET` and `CriticalWork`: how long the slice slider's critical values
//!   may search, and where (a thread, or slices of the window's frames);
//! - `BuildWork`: where a build runs (a thread, or slices of the window's frames), and
//!   `warm_up`, `pause`; `pipelines_beside`: a variant's pipelines built on a thread (or
//!   none: a page's frame makes what it lacks); `INTERPRETS`: whether a new formula's first
//!   frames draw with the interpreting shader while its own compiles;
//! - `Thumbnails`: how the gallery's pictures are made (a thread and a device of their own,
//!   or slices of the window's frames on its device);
//! - `State`: the platform's own part of the app, with `file_actions`,
//!   `sections` (panels only one side has), `end_frame`, `busy` and `embedded` (the
//!   page's picture alone, for an iframe);
//! - the exports of `file_actions`: a picture of the scene, the slice's mesh (a file
//!   written off the window's thread, or a download), and in `sections` the animation
//!   export (drawn on a thread of its own into a file, or over the window's frames into a
//!   GIF download);
//! - `page_address`: the web page's address, for share links.

#[cfg(not(target_arch = "wasm32"))]
mod native;
#[cfg(not(target_arch = "wasm32"))]
pub use native::*;

#[cfg(target_arch = "wasm32")]
mod web;
#[cfg(target_arch = "wasm32")]
pub use web::*;
