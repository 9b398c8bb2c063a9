//! The live viewer (eframe + wgpu), on the desktop and in the browser: type a formula, see the
//! manifold, rotate it in 4D. `session` holds what is drawn (`job` builds it in the
//! background), `progressive` how it reaches the screen without blocking the window,
//! `pacing` how much of each UI frame it may take, `history` undo and redo, and `app` the
//! widgets. What the desktop and the page do differently is `platform`'s. The picture is
//! made by the library's ray caster, the same as `fourfold render`'s.

pub mod animation;
pub mod app;
mod blit;
pub mod critical;
mod export;
pub mod gallery;
pub mod history;
pub mod job;
pub mod notice;
pub mod outcome;
pub mod pacing;
pub mod platform;
pub mod progressive;
pub mod session;
pub mod settings;

pub use app::FourfoldApp;
pub use session::Session;
