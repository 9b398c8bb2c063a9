//! A rigorous interval type: every operation returns an interval that contains the exact
//! result of the operation on every pair of real numbers in its operands (and, for library
//! functions, every value the platform's `f64` function returns there).
//!
//! * Arithmetic rounds outward: each bound of `+ - * /` and `sqrt` (correctly rounded by IEEE
//!   754) is moved one ulp out.
//! * Library functions (`exp`, `sin`, ...) are not correctly rounded; their bounds are moved
//!   out by [`LIB_ULPS`] ulps, above the documented error of glibc, musl and the Rust `libm`.
//! * Domain rules follow IEEE 1788's set-based flavour: `sqrt`, `ln`, `asin`, `acos` and real
//!   `pow` use only the part of the argument inside their domain; an argument wholly outside
//!   gives the empty interval. Division by an interval containing 0 gives a half-line or the
//!   whole line; division by exactly [0, 0] is empty.
//! * Even powers and `x²` are never negative; `sin`/`cos` find their extrema by quadrant.

mod arith;
mod functions;
pub mod rounding;
pub(crate) mod trig;
mod value;

pub use rounding::LIB_ULPS;
pub use value::Interval;
