//! The slice's interval octree: the 3D analogue of the 16-tree. A cube around the slice of
//! the domain is split in eight, level by level, keeping only the cells where the solid's
//! boundary may pass: the enclosure of F over the cell (by the same interval evaluator as
//! the 16-tree) or of the domain's `outside` holds 0. A cell where the solid's function
//! (max(F, outside)) is proved > 0, or proved < 0 with F defined on the whole cell, holds
//! none of the boundary and is dropped with all its children.

use rayon::prelude::*;

use crate::eval::IntervalEvaluator;
use crate::formula::CompiledFormula;
use crate::interval::Interval;

use super::frame::{Box3, SliceFrame};

/// The grid of the finest level: cell (i, j, k) spans `origin + side·(i, j, k)` to
/// `origin + side·(i+1, j+1, k+1)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    pub origin: [f64; 3],
    pub side: f64,
    /// Cells along each axis: 2^level.
    pub cells: i32,
}

impl Grid {
    /// A cube split `level` times that holds the box of half-extents `extent` around the
    /// frame's origin with room to spare. It is moved off centre by a small odd fraction of
    /// a cell, so that the grid's planes do not fall on the planes of symmetry where formulas
    /// put their corners and sharp edges.
    pub fn around(extent: [f64; 3], level: u32) -> Self {
        let cells = 1i32 << level;
        let reach = extent.iter().cloned().fold(f64::MIN_POSITIVE, f64::max);
        // The shift below is at most a quarter of a cell: the cube's half side leaves room
        // for it and 1% more.
        let half = 1.01 * reach / (1.0 - 0.25 / f64::from(cells));
        let side = 2.0 * half / f64::from(cells);
        let shift = 0.123_456_7 * side;
        Self {
            origin: [-half + shift, -half + 0.7 * shift, -half + 0.4 * shift],
            side,
            cells,
        }
    }

    /// Corner (i, j, k) of the grid, in the frame.
    pub fn corner(&self, c: [i32; 3]) -> [f64; 3] {
        std::array::from_fn(|a| self.origin[a] + self.side * f64::from(c[a]))
    }

    /// The box of the cell at `c` at `level` (a cell there spans 2^(finest − level) cells of
    /// the finest level).
    fn cell_box(&self, c: [i32; 3], span: i32) -> Box3 {
        let lo = self.corner(c);
        let hi = self.corner(c.map(|x| x + span));
        std::array::from_fn(|a| Interval::new(lo[a], hi[a]))
    }
}

/// What the descent keeps: the finest cells the boundary may cross, and how many cells it
/// looked at.
pub struct Leaves {
    pub cells: Vec<[i32; 3]>,
    pub visited: usize,
}

/// Why the descent stopped.
#[derive(Debug, Clone, PartialEq)]
pub enum DescentError {
    /// More than `budget` cells at some level: the formula fills the slice with surface.
    Budget { level: u32, budget: usize },
}

/// The finest-level cells of `grid` that the solid's boundary may cross, found level by
/// level from the root; at most `budget` cells a level.
pub fn descend(
    formula: &CompiledFormula,
    params: &[f64],
    frame: &SliceFrame,
    grid: &Grid,
    level: u32,
    budget: usize,
) -> Result<Leaves, DescentError> {
    let mut cells = vec![[0i32; 3]];
    let mut visited = 1;
    for depth in 0..=level {
        let span = 1i32 << (level - depth);
        let kept: Vec<[i32; 3]> = cells
            .par_iter()
            .map_init(IntervalEvaluator::new, |eval, &c| {
                may_cross(eval, formula, params, frame, &grid.cell_box(c, span)).then_some(c)
            })
            .flatten()
            .collect();
        if depth == level {
            return Ok(Leaves {
                cells: kept,
                visited,
            });
        }
        let half = span / 2;
        cells = kept
            .iter()
            .flat_map(|c| {
                (0..8).map(move |k| {
                    [
                        c[0] + (k & 1) * half,
                        c[1] + (k >> 1 & 1) * half,
                        c[2] + (k >> 2 & 1) * half,
                    ]
                })
            })
            .collect();
        visited += cells.len();
        if cells.len() > budget {
            return Err(DescentError::Budget {
                level: depth + 1,
                budget,
            });
        }
    }
    unreachable!("the last level returns")
}

/// Whether the boundary of the solid max(F, outside) ≤ 0 may cross the cell `b`.
fn may_cross(
    eval: &mut IntervalEvaluator,
    formula: &CompiledFormula,
    params: &[f64],
    frame: &SliceFrame,
    b: &Box3,
) -> bool {
    let b4 = frame.enclose(b);
    let outside = frame.outside_over(&b4);
    if outside.lo() > 0.0 {
        return false;
    }
    let f = eval.eval(&formula.tape_f, &b4, params);
    if f.is_empty() || f.lo() > 0.0 {
        // Undefined, or positive, wherever F is defined: outside the solid.
        return false;
    }
    let inside = f.hi() < 0.0 && outside.hi() < 0.0;
    !(inside && eval.continuous_on_last_box(&formula.tape_f))
}
