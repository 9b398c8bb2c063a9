//! Scene files: a TOML document holding everything needed to reproduce a picture (formula,
//! parameter values, domain, the six angles, tree and render settings). Every field but the
//! formula has a default. Bad values are reported with the line they are on, the flag that
//! set them or the link key that spelled them, checked by one set of rules against one set
//! of ranges ([`limits`]).

mod bounds;
mod check;
mod examples;
mod file;
mod keys;
pub mod limits;
pub mod link;
mod settings;

pub use bounds::{LinkBounds, PAGE_LINK_BOUNDS};
pub use check::{Invalid, Problem};
pub use examples::EXAMPLES;
pub use file::SceneError;
pub use keys::{Speaker, flag_of, keyword_of, link_key};
pub use limits::{DEFAULT_CERT_BUDGET, MAX_PICTURE_SIDE};
pub use link::LinkProblem;
pub use settings::{
    AxisRange, Color, ColorBy, Domain, Highlight, Lighting, RenderSettings, Sampling, Scene,
    TreeSettings, Undecided, View,
};
