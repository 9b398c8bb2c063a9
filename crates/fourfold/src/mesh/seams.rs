//! Two sheets of the boundary within one cell's reach: where a face's corners alternate and
//! both cells beside it join the face's two segments into one piece, the two cells'
//! vertices would be joined by two mesh edges at once (an edge of four triangles, not a
//! manifold). Each segment then gets a vertex of its own on the face, and the polygons of
//! the face's four grid edges go through it, so that the two sheets share no edge.

use std::collections::HashMap;

use crate::eval::PointEvaluator;

use super::contour::{Contour, Edge, polish};
use super::octree::Grid;
use super::solid::Solid;

/// Splits every doubled edge of `contour`'s polygons (see the module's note).
pub fn split_double_edges(contour: &mut Contour, solid: &Solid, grid: &Grid, tolerance: f64) {
    let mut uses: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
    for (k, polygon) in contour.polygons.iter().enumerate() {
        let v = &polygon.vertices;
        for i in 0..v.len() {
            let (a, b) = (v[i], v[(i + 1) % v.len()]);
            uses.entry((a.min(b), a.max(b))).or_default().push(k);
        }
    }
    let mut doubled: Vec<((u32, u32), Vec<usize>)> =
        uses.into_iter().filter(|(_, k)| k.len() == 4).collect();
    doubled.sort_unstable();
    let mut eval = PointEvaluator::new();
    for ((a, b), polygons) in doubled {
        let edges: Vec<Edge> = polygons.iter().map(|&k| contour.polygons[k].edge).collect();
        // The segments cut off the face's inside corners: two sides of the face lie on one
        // segment when they meet at an inside corner.
        let inside = &contour.inside;
        let Some(partner) = (1..4).find(|&j| meet_inside(edges[0], edges[j], inside)) else {
            continue;
        };
        let rest: Vec<usize> = (1..4).filter(|&j| j != partner).collect();
        if !meet_inside(edges[rest[0]], edges[rest[1]], inside) {
            continue;
        }
        for (p, q) in [(0, partner), (rest[0], rest[1])] {
            let (kp, kq) = (polygons[p], polygons[q]);
            let (ep, eq) = (contour.polygons[kp].edge, contour.polygons[kq].edge);
            let (cell, face) = shared_face(
                contour.vertex_cells[a as usize],
                contour.vertex_cells[b as usize],
            );
            let crossing = |e: &Edge| contour.crossings.get(e).point;
            let mid: [f64; 3] =
                std::array::from_fn(|k| 0.5 * (crossing(&ep)[k] + crossing(&eq)[k]));
            let (lo, hi) = (grid.corner(cell), grid.corner(cell.map(|x| x + 1)));
            let plane = grid.corner(cell.map(|x| x + 1))[face];
            let on_face = |x: [f64; 3]| -> [f64; 3] {
                std::array::from_fn(|k| {
                    if k == face {
                        plane
                    } else {
                        x[k].clamp(lo[k], hi[k])
                    }
                })
            };
            let vertex = polish(solid, &mut eval, on_face(mid), tolerance, on_face);
            let s = contour.vertices.len() as u32;
            contour.vertices.push(vertex);
            contour.vertex_cells.push(cell);
            for k in [kp, kq] {
                insert_between(&mut contour.polygons[k].vertices, a, b, s);
            }
        }
    }
}

/// Whether grid edges `e` and `f` share a corner that is inside the solid.
fn meet_inside(e: Edge, f: Edge, inside: &HashMap<[i32; 3], bool>) -> bool {
    let ends = |(c, axis): Edge| {
        let mut upper = c;
        upper[axis] += 1;
        [c, upper]
    };
    ends(e)
        .iter()
        .any(|p| ends(f).contains(p) && inside.get(p).copied().unwrap_or(false))
}

/// The lower of two face-adjacent cells, and the axis across their shared face (whose
/// plane is the lower cell's upper side along it).
fn shared_face(a: [i32; 3], b: [i32; 3]) -> ([i32; 3], usize) {
    let axis = (0..3).find(|&k| a[k] != b[k]).unwrap_or(0);
    (if a[axis] < b[axis] { a } else { b }, axis)
}

/// Puts `s` between the consecutive vertices `a` and `b` of a polygon (either way round).
fn insert_between(polygon: &mut Vec<u32>, a: u32, b: u32, s: u32) {
    let n = polygon.len();
    if let Some(i) = (0..n).find(|&i| {
        let (p, q) = (polygon[i], polygon[(i + 1) % n]);
        (p, q) == (a, b) || (p, q) == (b, a)
    }) {
        polygon.insert(i + 1, s);
    }
}
