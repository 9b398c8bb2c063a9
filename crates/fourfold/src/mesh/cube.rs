//! A cube's corners, edges and faces, and how the boundary splits into pieces inside one
//! cell of the grid. Corner k has bits (x, y, z) = (k & 1, k >> 1 & 1, k >> 2 & 1). Edge
//! 4a + j runs along axis a from the corner whose other two bits (axes a+1 and a+2, mod 3)
//! are j's two bits.
//!
//! A cell may hold several pieces of the boundary (the marching-cubes patches): each piece
//! gets its own vertex, so that the mesh stays a manifold where one cell holds two sheets.
//! Where a face's corners alternate (its two inside corners diagonal), the pieces through it
//! are the ones that cut off each inside corner: a rule that reads only the face's own
//! corners, so the two cells sharing a face agree on it.

/// The two corners of edge `e`, lower first.
pub fn edge_corners(e: usize) -> (usize, usize) {
    let a = e / 4;
    let (b, c) = ((a + 1) % 3, (a + 2) % 3);
    let lo = ((e & 1) << b) | ((e >> 1 & 1) << c);
    (lo, lo | 1 << a)
}

/// The edge along `axis` whose lower corner is `corner`.
pub fn edge_at(axis: usize, corner: usize) -> usize {
    let (b, c) = ((axis + 1) % 3, (axis + 2) % 3);
    4 * axis + (corner >> b & 1) + 2 * (corner >> c & 1)
}

/// The four corners of each face in cyclic order.
fn faces() -> [[usize; 4]; 6] {
    std::array::from_fn(|f| {
        let (a, side) = (f / 2, f % 2);
        let (b, c) = ((a + 1) % 3, (a + 2) % 3);
        [(0, 0), (1, 0), (1, 1), (0, 1)].map(|(i, j)| side << a | i << b | j << c)
    })
}

/// The edge between two corners that differ in one bit.
fn edge_between(p: usize, q: usize) -> usize {
    let axis = (p ^ q).trailing_zeros() as usize;
    edge_at(axis, p.min(q))
}

/// For a cell whose corner k is inside when bit k of `inside` is set: the piece of the
/// boundary each edge belongs to (None where the edge's ends agree), and how many pieces.
pub fn pieces(inside: u8) -> ([Option<u8>; 12], u8) {
    let is_in = |k: usize| inside >> k & 1 == 1;
    let crossed = |e: usize| {
        let (p, q) = edge_corners(e);
        is_in(p) != is_in(q)
    };
    // Union-find over the twelve edges, joined where a face's segment links two crossings.
    let mut parent: [usize; 12] = std::array::from_fn(|e| e);
    fn root(parent: &mut [usize; 12], mut e: usize) -> usize {
        while parent[e] != e {
            parent[e] = parent[parent[e]];
            e = parent[e];
        }
        e
    }
    for corners in faces() {
        let sides: [usize; 4] =
            std::array::from_fn(|i| edge_between(corners[i], corners[(i + 1) % 4]));
        let cut: Vec<usize> = (0..4).filter(|&i| crossed(sides[i])).collect();
        let pairs: Vec<(usize, usize)> = match cut.len() {
            2 => vec![(sides[cut[0]], sides[cut[1]])],
            4 => {
                // Each inside corner is cut off by the segment joining its two sides: side
                // i runs from corner i to corner i + 1, so corner i lies between sides
                // i − 1 and i.
                let first = if is_in(corners[0]) { 0 } else { 1 };
                vec![
                    (sides[(first + 3) % 4], sides[first]),
                    (sides[first + 1], sides[first + 2]),
                ]
            }
            _ => vec![],
        };
        for (p, q) in pairs {
            let (rp, rq) = (root(&mut parent, p), root(&mut parent, q));
            parent[rp] = rq;
        }
    }
    let mut piece = [None; 12];
    let mut count = 0u8;
    let mut label = [u8::MAX; 12];
    for e in 0..12 {
        if crossed(e) {
            let r = root(&mut parent, e);
            if label[r] == u8::MAX {
                label[r] = count;
                count += 1;
            }
            piece[e] = Some(label[r]);
        }
    }
    (piece, count)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edges_and_corners_agree() {
        for e in 0..12 {
            let (p, q) = edge_corners(e);
            assert_eq!(edge_at(e / 4, p), e);
            assert_eq!((p ^ q).count_ones(), 1);
            assert_eq!(edge_between(q, p), e);
        }
    }

    #[test]
    fn one_inside_corner_is_one_piece_of_three_edges_and_two_diagonal_corners_two() {
        let (piece, count) = pieces(0b0000_0001);
        assert_eq!((count, piece.iter().flatten().count()), (1, 3));
        // Corners 0 and 3 are diagonal on the face z = 0: two pieces, each of three edges.
        let (piece, count) = pieces(0b0000_1001);
        assert_eq!(count, 2);
        let sizes: Vec<usize> = (0..count)
            .map(|c| piece.iter().filter(|p| **p == Some(c)).count())
            .collect();
        assert_eq!(sizes, [3, 3]);
        // Every crossing belongs to a piece with at least three edges (a closed polygon).
        for inside in 0..=255u8 {
            let (piece, count) = pieces(inside);
            for c in 0..count {
                assert!(
                    piece.iter().filter(|p| **p == Some(c)).count() >= 3,
                    "{inside:08b}"
                );
            }
            assert_eq!(pieces(!inside).1 > 0, count > 0);
        }
    }
}
