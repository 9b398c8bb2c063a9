//! Stage 3: evaluators of a compiled formula: point (f64) and rigorous interval.

pub mod batch;
pub mod interval;
pub mod interval_eval;
pub mod point;
pub mod tape;
mod trig;

pub use batch::{BatchEvaluator, LANES};
pub use interval::Interval;
pub use interval_eval::{Box4, IntervalEvaluator};
pub use point::PointEvaluator;
pub use tape::{Instr, Op, Tape};
