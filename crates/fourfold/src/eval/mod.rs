//! Stage 3: evaluators of a compiled formula's tapes: point (f64), rigorous interval over a
//! box, and interval over 16 boxes at once, all keeping one contract ([`Evaluator`]); f32
//! as the GPU at 16 points at once (the CPU twin's); F's sign proved at 16 points at
//! once by ball arithmetic, where a tape is sums and products alone; and a bound on how far
//! the f32 values lie from F's exact ones over a box (`rounding`).
//!
//! The three evaluators at 16 at once run each instruction as a loop over the lanes, which
//! the compiler vectorizes; those loops (each module's `run`) are compiled for x86-64's
//! baseline, SSE2, and again for AVX2 (twice the lanes in a vector), and the processor's is
//! chosen at run time (the `multiversion` crate). AVX2 rounds each operation as SSE2 does
//! and no product is fused with a sum, so both give the same bits.

pub mod ball;
pub mod batch;
pub mod evaluator;
pub mod interval_eval;
pub mod lanes;
mod plan;
pub mod point;
pub mod rounding;
pub mod tape;

pub use crate::interval::Interval;
pub use ball::BallLanes;
pub use batch::{BatchEvaluator, LANES};
pub use evaluator::{Evaluator, Point4};
pub use interval_eval::{Box4, IntervalEvaluator};
pub use lanes::PointLanes;
pub use point::PointEvaluator;
pub use rounding::single_precision_error;
pub use tape::{Instr, Op, Tape};
