//! The desktop side of the viewer: a native window, builds on a thread of their own, files
//! at paths typed in, and what needs a thread and a GPU device of its own beside the
//! window's (the gallery, PNG and animation exports).

mod animation;
mod build;
mod files;
mod gallery;
mod ui;
mod window;

pub use build::{
    Background, BuildWork, CERTIFIED_PIXELS, CRITICAL_BOX_BUDGET, CriticalWork, pause,
};
pub use ui::{EMBEDS, State, end_frame, file_actions, page_address, sections, top_bar};
pub use window::run;
