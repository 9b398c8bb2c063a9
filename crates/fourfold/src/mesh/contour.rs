//! Dual contouring of the solid over the octree's finest cells: a vertex for each piece of
//! the boundary in a cell (placed by the crossings' tangent planes, inside the cell), and
//! for each grid edge the boundary crosses, a quad joining the vertices of the four cells
//! around it, wound so that its normal points out of the solid (towards F > 0).

use std::collections::HashMap;

use rayon::prelude::*;

use crate::eval::PointEvaluator;

use super::cube::{edge_at, edge_corners, pieces};
use super::octree::Grid;
use super::qef;
use super::solid::{Sample, Solid};

/// A grid edge: its lower corner and its axis.
pub type Edge = ([i32; 3], usize);

/// The boundary's crossing of one grid edge.
#[derive(Debug, Clone, Copy)]
pub struct Crossing {
    pub point: [f64; 3],
    pub sample: Sample,
    /// Whether the edge's lower corner is the inside one.
    lower_inside: bool,
}

/// The crossed edges in order, with their crossings.
pub struct Crossings {
    edges: Vec<Edge>,
    found: Vec<Crossing>,
}

impl Crossings {
    pub fn get(&self, edge: &Edge) -> &Crossing {
        let i = self
            .edges
            .binary_search(edge)
            .expect("every crossed edge was found");
        &self.found[i]
    }

    fn iter(&self) -> impl Iterator<Item = (&Edge, &Crossing)> {
        self.edges.iter().zip(&self.found)
    }
}

/// A cell's pieces of boundary: the piece of each edge, and the first of its vertices.
#[derive(Debug, Clone, Copy)]
struct Cell {
    piece: [Option<u8>; 12],
    pieces: u8,
    first_vertex: u32,
}

/// One grid edge's polygon: a quad, or more where [`seams`] split one of its sides.
#[derive(Debug, Clone)]
pub struct Polygon {
    /// Counter-clockwise seen from outside the solid.
    pub vertices: Vec<u32>,
    /// Part of a cap (the domain's face, not F, crosses the edge).
    pub on_cap: bool,
    /// The boundary's unit normal where it crosses the edge.
    pub normal: [f64; 3],
    pub edge: Edge,
}

/// The contoured boundary, before any cap is dropped.
pub struct Contour {
    pub vertices: Vec<[f64; 3]>,
    /// The cell each vertex lies in (for a vertex on a face, one of its two cells).
    pub vertex_cells: Vec<[i32; 3]>,
    pub polygons: Vec<Polygon>,
    /// Vertices from this one on were added on faces by `seams`.
    pub first_seam: usize,
    /// Whether each grid corner met is inside the solid.
    pub inside: HashMap<[i32; 3], bool>,
    pub crossings: Crossings,
}

/// Contours the boundary through `seeds` (the octree's leaves), adding any cell a crossing
/// needs that the octree dropped, so the mesh has no hole whatever the enclosures said.
pub fn contour(solid: &Solid, grid: &Grid, seeds: &[[i32; 3]], tolerance: f64) -> Contour {
    let mut inside = corner_signs(solid, grid, seeds);
    let (cells, order) = close_cells(solid, grid, seeds, &mut inside);
    let crossings = crossings(solid, grid, &cells, &order, &inside);
    let (vertices, vertex_cells) =
        place_vertices(solid, grid, &cells, &order, &crossings, tolerance);
    let mut polygons = Vec::with_capacity(crossings.edges.len());
    for (&(corner, axis), crossing) in crossings.iter() {
        let ring = around((corner, axis)).map(|(cell, local)| {
            cells
                .get(&cell)
                .and_then(|k| k.piece[local].map(|p| k.first_vertex + u32::from(p)))
        });
        let [Some(v0), Some(v1), Some(v2), Some(v3)] = ring else {
            continue; // a cell beyond the grid: only where M reaches the grid's own faces.
        };
        polygons.push(Polygon {
            vertices: if crossing.lower_inside {
                vec![v0, v1, v2, v3]
            } else {
                vec![v3, v2, v1, v0]
            },
            on_cap: crossing.sample.on_cap,
            normal: unit(crossing.sample.gradient),
            edge: (corner, axis),
        });
    }
    Contour {
        first_seam: vertices.len(),
        vertices,
        vertex_cells,
        polygons,
        inside,
        crossings,
    }
}

/// The four cells around a grid edge, counter-clockwise seen from its axis's + end, each
/// with the edge's number in that cell.
fn around((corner, axis): Edge) -> [([i32; 3], usize); 4] {
    let (b, c) = ((axis + 1) % 3, (axis + 2) % 3);
    [(0, 0), (1, 0), (1, 1), (0, 1)].map(|(db, dc)| {
        let mut cell = corner;
        cell[b] -= db;
        cell[c] -= dc;
        (cell, edge_at(axis, (db as usize) << b | (dc as usize) << c))
    })
}

/// Whether each corner of the seed cells is inside the solid.
fn corner_signs(solid: &Solid, grid: &Grid, seeds: &[[i32; 3]]) -> HashMap<[i32; 3], bool> {
    let mut corners: Vec<[i32; 3]> = seeds
        .iter()
        .flat_map(|c| (0..8).map(move |k| corner_of(*c, k)))
        .collect();
    corners.sort_unstable();
    corners.dedup();
    corners
        .par_iter()
        .map_init(PointEvaluator::new, |eval, &c| {
            (c, solid.inside(eval, grid.corner(c)))
        })
        .collect()
}

/// The cells that hold boundary: the seeds, and their neighbours across crossed edges until
/// none is missing. Returns them with their pieces, and their coordinates in order.
fn close_cells(
    solid: &Solid,
    grid: &Grid,
    seeds: &[[i32; 3]],
    inside: &mut HashMap<[i32; 3], bool>,
) -> (HashMap<[i32; 3], Cell>, Vec<[i32; 3]>) {
    let mut eval = PointEvaluator::new();
    let mut cells: HashMap<[i32; 3], Cell> = HashMap::with_capacity(seeds.len());
    let mut queue: Vec<[i32; 3]> = seeds.to_vec();
    let in_grid = |c: [i32; 3]| c.iter().all(|&x| (0..grid.cells).contains(&x));
    while let Some(cell) = queue.pop() {
        if cells.contains_key(&cell) || !in_grid(cell) {
            continue;
        }
        let mut mask = 0u8;
        for k in 0..8 {
            let corner = corner_of(cell, k);
            let is_in = *inside
                .entry(corner)
                .or_insert_with(|| solid.inside(&mut eval, grid.corner(corner)));
            mask |= u8::from(is_in) << k;
        }
        let (piece, count) = pieces(mask);
        cells.insert(
            cell,
            Cell {
                piece,
                pieces: count,
                first_vertex: 0,
            },
        );
        for e in (0..12).filter(|&e| piece[e].is_some()) {
            let edge = (corner_of(cell, edge_corners(e).0), e / 4);
            for (next, _) in around(edge) {
                if !cells.contains_key(&next) {
                    queue.push(next);
                }
            }
        }
    }
    cells.retain(|_, cell| cell.pieces > 0);
    let mut order: Vec<[i32; 3]> = cells.keys().copied().collect();
    order.sort_unstable();
    let mut next = 0u32;
    for c in &order {
        let cell = cells.get_mut(c).expect("listed");
        cell.first_vertex = next;
        next += u32::from(cell.pieces);
    }
    (cells, order)
}

/// Each crossed grid edge's crossing, in the order of the cells (so a mesh comes out the
/// same every time).
fn crossings(
    solid: &Solid,
    grid: &Grid,
    cells: &HashMap<[i32; 3], Cell>,
    order: &[[i32; 3]],
    inside: &HashMap<[i32; 3], bool>,
) -> Crossings {
    let mut edges: Vec<Edge> = order
        .iter()
        .flat_map(|c| {
            let cell = cells[c];
            (0..12)
                .filter(move |&e| cell.piece[e].is_some())
                .map(move |e| (corner_of(*c, edge_corners(e).0), e / 4))
        })
        .collect();
    edges.sort_unstable();
    edges.dedup();
    let found: Vec<Crossing> = edges
        .par_iter()
        .map_init(PointEvaluator::new, |eval, &(corner, axis)| {
            let a = grid.corner(corner);
            let mut upper = corner;
            upper[axis] += 1;
            let b = grid.corner(upper);
            let lower_inside = inside[&corner];
            let point = if lower_inside {
                solid.crossing(eval, a, b)
            } else {
                solid.crossing(eval, b, a)
            };
            Crossing {
                point,
                sample: solid.sample(eval, point),
                lower_inside,
            }
        })
        .collect();
    Crossings { edges, found }
}

/// One vertex per piece of each cell: the tangent planes' point, kept inside the cell, then
/// moved onto the boundary (Newton steps along the gradient, still inside the cell) where it
/// is farther from it than `tolerance`.
fn place_vertices(
    solid: &Solid,
    grid: &Grid,
    cells: &HashMap<[i32; 3], Cell>,
    order: &[[i32; 3]],
    crossings: &Crossings,
    tolerance: f64,
) -> (Vec<[f64; 3]>, Vec<[i32; 3]>) {
    let placed: Vec<Vec<([f64; 3], [i32; 3])>> = order
        .par_iter()
        .map_init(PointEvaluator::new, |eval, c| {
            let cell = cells[c];
            let lo = grid.corner(*c);
            let hi = grid.corner(c.map(|x| x + 1));
            // A hair inside the cell, so that neighbouring cells' vertices never coincide.
            let margin = 1e-6 * grid.side;
            let clamp = |x: [f64; 3]| -> [f64; 3] {
                std::array::from_fn(|a| x[a].clamp(lo[a] + margin, hi[a] - margin))
            };
            (0..cell.pieces)
                .map(|p| {
                    let (points, normals): (Vec<[f64; 3]>, Vec<[f64; 3]>) = (0..12)
                        .filter(|&e| cell.piece[e] == Some(p))
                        .map(|e| {
                            let x = crossings.get(&(corner_of(*c, edge_corners(e).0), e / 4));
                            (x.point, unit(x.sample.gradient))
                        })
                        .unzip();
                    let v = clamp(qef::place(&points, &normals));
                    (polish(solid, eval, v, tolerance, clamp), *c)
                })
                .collect()
        })
        .collect();
    placed.into_iter().flatten().unzip()
}

/// `v` moved onto the boundary by Newton steps along the gradient, each kept where `clamp`
/// puts it, until it is within `tolerance` of it (at most eight steps).
pub(super) fn polish(
    solid: &Solid,
    eval: &mut PointEvaluator,
    mut v: [f64; 3],
    tolerance: f64,
    clamp: impl Fn([f64; 3]) -> [f64; 3],
) -> [f64; 3] {
    for _ in 0..8 {
        let s = solid.sample(eval, v);
        if s.distance() <= tolerance || !s.value.is_finite() {
            break;
        }
        let g2: f64 = s.gradient.iter().map(|x| x * x).sum();
        v = clamp(std::array::from_fn(|a| v[a] - s.value * s.gradient[a] / g2));
    }
    v
}

/// Corner k of cell `c` (bit a of k: the cell's upper side along axis a).
pub(super) fn corner_of(c: [i32; 3], k: usize) -> [i32; 3] {
    std::array::from_fn(|a| c[a] + (k >> a & 1) as i32)
}

/// `v` scaled to length 1 (zero where it has none).
pub fn unit(v: [f64; 3]) -> [f64; 3] {
    let n = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    if n > 0.0 && n.is_finite() {
        v.map(|x| x / n)
    } else {
        [0.0; 3]
    }
}
