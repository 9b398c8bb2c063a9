//! The desktop side of the viewer: a native window, builds on a thread of their own, files
//! at paths typed in, and what needs a thread and a GPU device of its own beside the
//! window's (the gallery's pictures, PNG and animation exports).

mod animation;
mod build;
mod files;
mod threads;
mod thumbnails;
mod ui;
mod window;

pub use build::{
    Background, BuildWork, CPU_PREVIEWS, CRITICAL_BOX_BUDGET, CriticalWork, INTERPRETS,
    WAITS_FOR_GPU, pause, pipelines_beside, warm_up,
};
pub use thumbnails::Thumbnails;
pub use ui::{EMBEDS, State, end_frame, file_actions, page_address, sections};
pub use window::run;
