//! The web page's side of the viewer: builds in slices of the window's frames (a page has
//! one thread), the share link kept in the address bar, files as uploads and downloads.
//! The page's entry (`web/`) starts the viewer in its canvas.

mod animation;
mod build;
mod files;
mod thumbnails;
mod ui;

pub use build::{
    Background, BuildWork, CPU_PREVIEWS, CRITICAL_BOX_BUDGET, CriticalWork, INTERPRETS,
    WAITS_FOR_GPU, pause, pipelines_beside, warm_up,
};
pub use thumbnails::Thumbnails;
pub use ui::{
    EMBEDS, State, end_frame, file_actions, open_link, page_address, sections, split_embed,
};
