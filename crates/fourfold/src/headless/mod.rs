//! Drawing that waits for the GPU, for programs with a thread to spare (the command line,
//! the desktop viewer's background exports and gallery, the tests and benchmarks): a device
//! of one's own, pictures and animations waited for, files written. A web page cannot wait,
//! so this module is not built there (`lib.rs`); everything it waits for is in `render`,
//! which the page polls instead.

mod animation;
mod device;
mod output;
pub mod probe;
mod wait;

pub use animation::{Drawn, FrameDevice, draw};
pub use device::pipeline_cache_dir;
pub use output::{FrameWriter, Output};
pub use wait::{read_back, render_compiled, render_fitted, render_prepared, render_scene};
