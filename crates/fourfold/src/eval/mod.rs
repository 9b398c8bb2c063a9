//! Stage 3: evaluators of a compiled formula's tapes: point (f64), rigorous interval over a
//! box, and interval over 16 boxes at once, all keeping one contract ([`Evaluator`]); f32
//! as the GPU at 16 points at once (the CPU twin's); and F's sign proved at 16 points at
//! once by ball arithmetic, where a tape is sums and products alone.

pub mod ball;
pub mod batch;
pub mod evaluator;
pub mod interval_eval;
pub mod lanes;
pub mod point;
pub mod tape;

pub use crate::interval::Interval;
pub use ball::BallLanes;
pub use batch::{BatchEvaluator, LANES};
pub use evaluator::{Evaluator, Point4};
pub use interval_eval::{Box4, IntervalEvaluator};
pub use lanes::PointLanes;
pub use point::PointEvaluator;
pub use tape::{Instr, Op, Tape};
