//! Meshes of slices: the cut of M by the view's hyperplane at c along n2, as triangles in
//! the slice's own frame (x, y, z along the view's v1, v2, n1, so lengths and volumes are
//! R⁴'s), for printing and for other programs (docs/mesh.md).
//!
//! The mesh bounds the solid where F < 0 inside the domain: its triangles are wound
//! counter-clockwise seen from outside, so their normals point towards F > 0. Where M leaves
//! the domain the cut is capped by the domain's faces (a closed solid), or left open.
//! Built on [`octree`] (interval pruning, as the 16-tree) and [`contour`] (dual contouring
//! with a vertex per piece of boundary in a cell, placed by the tangent planes, so flat faces
//! and sharp edges stay flat and sharp).

pub mod contour;
pub mod cube;
pub mod file;
pub mod frame;
mod glb;
pub mod octree;
mod qef;
mod seams;
pub mod solid;

use crate::formula::CompiledFormula;
use crate::scene::Scene;
use crate::scene::limits::{DEFAULT_MESH_LEVEL, MESH_CELL_BUDGET, MESH_LEVELS};

pub use file::MeshFormat;
pub use frame::SliceFrame;
pub use octree::Grid;

/// How to mesh a slice.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshSettings {
    /// Where the hyperplane cuts, along n2 from the domain's centre.
    pub offset: f64,
    /// Levels of the octree: the finest cells are the slice's extent / 2^level.
    pub max_level: u32,
    /// How far (|F|/|∇F|, in the frame's units) a vertex may lie from the boundary before it
    /// is moved onto it; None: a hundredth of a finest cell.
    pub tolerance: Option<f64>,
    /// Close the solid with the domain's faces where M leaves the domain.
    pub caps: bool,
}

impl MeshSettings {
    pub fn new(offset: f64) -> Self {
        Self {
            offset,
            max_level: DEFAULT_MESH_LEVEL,
            tolerance: None,
            caps: true,
        }
    }
}

/// A slice's mesh and what building it found.
#[derive(Debug, Clone)]
pub struct SliceMesh {
    pub vertices: Vec<[f64; 3]>,
    /// Counter-clockwise seen from outside the solid.
    pub triangles: Vec<[u32; 3]>,
    /// The finest cell each vertex lies in (see [`Grid`]).
    pub vertex_cells: Vec<[i32; 3]>,
    pub grid: Grid,
    pub stats: MeshStats,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshStats {
    /// Cells the octree looked at, and the finest ones it kept.
    pub visited: usize,
    pub leaves: usize,
    /// The tolerance used, and the largest |S|/|∇S| over the vertices (S: F, or the
    /// domain's face on a cap).
    pub tolerance: f64,
    pub max_residual: f64,
    /// Vertices farther than the tolerance (where M bends, meets a cap or stops being
    /// defined within their cell, Newton steps inside it cannot reach it: a finer level
    /// brings them closer).
    pub over_tolerance: usize,
}

/// Why a slice has no mesh.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeshError {
    #[error(
        "the slice at {offset} misses the domain: along this view's n2 the domain reaches \
         only ±{reach:.6} from its centre"
    )]
    Misses { offset: f64, reach: f64 },
    #[error(
        "the slice at {offset} does not cut M inside the domain (F is positive or undefined \
         everywhere on it): no mesh to write"
    )]
    Empty { offset: f64 },
    #[error(
        "the slice needs more than {budget} cells at level {level} of {max_level}: F has \
         surface nearly everywhere; lower the level (--max-level) or narrow the domain"
    )]
    Budget {
        level: u32,
        max_level: u32,
        budget: usize,
    },
    #[error("the mesh's level must be within {lo}..={hi}, not {level}")]
    Level { level: u32, lo: u32, hi: u32 },
    #[error("the tolerance must be a positive number, not {0}")]
    Tolerance(f64),
}

/// What a mesh file says it is (its comment, or its header's): the slice of `formula` at
/// `offset` along n2 of `scene`'s view, in the slice's frame.
pub fn describe_slice(formula: &CompiledFormula, scene: &Scene, offset: f64) -> String {
    format!(
        "fourfold: the slice at {offset} along n2 of F = {}\nangles {:?}, in the slice's frame \
         (v1, v2, n1)",
        formula.f_text(),
        scene.view.angles
    )
}

/// The mesh of `formula`'s slice in `scene`'s view and domain.
pub fn mesh_slice(
    formula: &CompiledFormula,
    scene: &Scene,
    settings: &MeshSettings,
) -> Result<SliceMesh, MeshError> {
    if !MESH_LEVELS.contains(&settings.max_level) {
        return Err(MeshError::Level {
            level: settings.max_level,
            lo: *MESH_LEVELS.start(),
            hi: *MESH_LEVELS.end(),
        });
    }
    if let Some(t) = settings.tolerance.filter(|t| !(*t > 0.0 && t.is_finite())) {
        return Err(MeshError::Tolerance(t));
    }
    let offset = settings.offset;
    let frame = SliceFrame::new(&scene.domain, &scene.view, offset);
    let extent = frame.extent().ok_or(MeshError::Misses {
        offset,
        reach: frame.reach(),
    })?;
    let params = scene.param_values(&formula.param_names());
    let grid = Grid::around(extent, settings.max_level);
    let leaves = octree::descend(
        formula,
        &params,
        &frame,
        &grid,
        settings.max_level,
        MESH_CELL_BUDGET,
    )
    .map_err(
        |octree::DescentError::Budget { level, budget }| MeshError::Budget {
            level,
            max_level: settings.max_level,
            budget,
        },
    )?;
    let solid = solid::Solid {
        formula,
        params: &params,
        frame: &frame,
    };
    let tolerance = settings.tolerance.unwrap_or(0.01 * grid.side);
    let mut contour = contour::contour(&solid, &grid, &leaves.cells, tolerance);
    seams::split_double_edges(&mut contour, &solid, &grid, tolerance);
    let (vertices, triangles, vertex_cells) = triangulate(contour, settings.caps);
    if triangles.is_empty() {
        return Err(MeshError::Empty { offset });
    }
    let mut eval = crate::eval::PointEvaluator::new();
    let residuals: Vec<f64> = vertices
        .iter()
        .map(|v| solid.sample(&mut eval, *v).distance())
        .collect();
    let stats = MeshStats {
        visited: leaves.visited,
        leaves: leaves.cells.len(),
        tolerance,
        max_residual: residuals.iter().cloned().fold(0.0, f64::max),
        over_tolerance: residuals.iter().filter(|r| **r > tolerance).count(),
    };
    Ok(SliceMesh {
        vertices,
        triangles,
        vertex_cells,
        grid,
        stats,
    })
}

/// Vertices, triangles and each vertex's cell.
type Triangles = (Vec<[f64; 3]>, Vec<[u32; 3]>, Vec<[i32; 3]>);

/// Splits each quad in two along the diagonal whose triangles face most like the boundary
/// where the quad's edge crosses it, and a polygon with a seam's vertex into a fan from it;
/// drops the caps' polygons if asked, and the vertices only they used.
fn triangulate(contour: contour::Contour, caps: bool) -> Triangles {
    let v = &contour.vertices;
    let first_seam = contour.first_seam;
    let facing = |t: [u32; 3], n: [f64; 3]| {
        let [a, b, c] = t.map(|i| v[i as usize]);
        let normal = cross(sub(b, a), sub(c, a));
        let m = contour::unit(normal);
        if m == [0.0; 3] { -2.0 } else { dot(m, n) }
    };
    let mut triangles = Vec::with_capacity(2 * contour.polygons.len());
    for polygon in &contour.polygons {
        if polygon.on_cap && !caps {
            continue;
        }
        let (q, n) = (&polygon.vertices, polygon.normal);
        if let [a, b, c, d] = q[..] {
            let splits = [[[a, b, c], [a, c, d]], [[a, b, d], [b, c, d]]];
            let score = |s: &[[u32; 3]; 2]| facing(s[0], n).min(facing(s[1], n));
            let best = if score(&splits[0]) >= score(&splits[1]) {
                splits[0]
            } else {
                splits[1]
            };
            triangles.extend(best);
        } else {
            // A side split by a seam's vertex: a fan from it.
            let k = q
                .iter()
                .position(|&i| i as usize >= first_seam)
                .unwrap_or(0);
            let m = q.len();
            triangles.extend((1..m - 1).map(|j| [q[k], q[(k + j) % m], q[(k + j + 1) % m]]));
        }
    }
    // Keep only the vertices the triangles use, in their order.
    let mut index = vec![u32::MAX; v.len()];
    let (mut vertices, mut vertex_cells) = (Vec::new(), Vec::new());
    for t in &mut triangles {
        for i in t.iter_mut() {
            let old = *i as usize;
            if index[old] == u32::MAX {
                index[old] = vertices.len() as u32;
                vertices.push(v[old]);
                vertex_cells.push(contour.vertex_cells[old]);
            }
            *i = index[old];
        }
    }
    (vertices, triangles, vertex_cells)
}

impl SliceMesh {
    /// The volume the triangles enclose (positive when they are wound outward).
    pub fn volume(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| self.vertices[i as usize]);
                dot(a, cross(b, c)) / 6.0
            })
            .sum()
    }

    /// The smallest box holding the vertices: its low and high corners.
    pub fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        self.vertices.iter().fold(
            ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]),
            |(lo, hi), v| {
                (
                    std::array::from_fn(|a| lo[a].min(v[a])),
                    std::array::from_fn(|a| hi[a].max(v[a])),
                )
            },
        )
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| a[i] - b[i])
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|i| a[i] * b[i]).sum()
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
