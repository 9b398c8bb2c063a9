//! Where a cell's vertex goes: the point nearest, in the least-squares sense, to the planes
//! tangent to the boundary where it crosses the cell's edges (dual contouring's quadratic
//! error function). Directions along which the planes say little (a flat piece, or the
//! line of a sharp edge) are left at the crossings' mean, so that a vertex stays on a
//! sharp edge or corner where one passes and near the crossings elsewhere.

/// Singular values below this share of the largest are dropped (as in Ju et al.'s dual
/// contouring).
const TRUNCATE: f64 = 0.1;

/// The vertex for crossings `points` with unit normals `normals` (a zero normal where the
/// gradient is unknown: that crossing only pulls the mean).
pub fn place(points: &[[f64; 3]], normals: &[[f64; 3]]) -> [f64; 3] {
    let n = points.len().max(1) as f64;
    let mean: [f64; 3] = std::array::from_fn(|a| points.iter().map(|p| p[a]).sum::<f64>() / n);
    // AᵀA and Aᵀb for the rows nₖ·(x − mean) = nₖ·(pₖ − mean).
    let mut ata = [[0.0; 3]; 3];
    let mut atb = [0.0; 3];
    for (p, nk) in points.iter().zip(normals) {
        let b: f64 = (0..3).map(|a| nk[a] * (p[a] - mean[a])).sum();
        for i in 0..3 {
            atb[i] += nk[i] * b;
            for j in 0..3 {
                ata[i][j] += nk[i] * nk[j];
            }
        }
    }
    let (values, vectors) = eigen(ata);
    let largest = values.iter().cloned().fold(0.0, f64::max);
    let mut x = mean;
    for k in 0..3 {
        if largest > 0.0 && values[k] > TRUNCATE * largest {
            let v = vectors[k];
            let along = (0..3).map(|a| v[a] * atb[a]).sum::<f64>() / values[k];
            for a in 0..3 {
                x[a] += along * v[a];
            }
        }
    }
    x
}

/// Eigenvalues and unit eigenvectors of a symmetric 3×3 matrix (Jacobi rotations).
fn eigen(mut m: [[f64; 3]; 3]) -> ([f64; 3], [[f64; 3]; 3]) {
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _ in 0..32 {
        let off = m[0][1].abs() + m[0][2].abs() + m[1][2].abs();
        if off < 1e-15 * (m[0][0].abs() + m[1][1].abs() + m[2][2].abs()) || off == 0.0 {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if m[p][q] == 0.0 {
                continue;
            }
            let theta = (m[q][q] - m[p][p]) / (2.0 * m[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let (c, s) = {
                let c = 1.0 / (t * t + 1.0).sqrt();
                (c, t * c)
            };
            // m ← Jᵀ m J, v ← v J, with J the rotation in the (p, q) plane.
            for k in 0..3 {
                let (mkp, mkq) = (m[k][p], m[k][q]);
                m[k][p] = c * mkp - s * mkq;
                m[k][q] = s * mkp + c * mkq;
            }
            for k in 0..3 {
                let (mpk, mqk) = (m[p][k], m[q][k]);
                m[p][k] = c * mpk - s * mqk;
                m[q][k] = s * mpk + c * mqk;
            }
            for row in &mut v {
                let (vp, vq) = (row[p], row[q]);
                row[p] = c * vp - s * vq;
                row[q] = s * vp + c * vq;
            }
        }
    }
    let values = [m[0][0], m[1][1], m[2][2]];
    let vectors = std::array::from_fn(|k| [v[0][k], v[1][k], v[2][k]]);
    (values, vectors)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn three_planes_meet_at_their_corner_and_one_plane_keeps_the_mean_along_it() {
        // The corner of the planes x = 0.3, y = 0.6, z = 0.2, seen from crossings near it.
        let points = [
            [0.3, 0.0, 0.0],
            [0.3, 1.0, 1.0],
            [0.0, 0.6, 0.0],
            [1.0, 0.6, 1.0],
            [0.0, 0.0, 0.2],
            [1.0, 1.0, 0.2],
        ];
        let normals = [
            [1.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, 1.0],
        ];
        let x = place(&points, &normals);
        for (a, want) in [0.3, 0.6, 0.2].iter().enumerate() {
            assert!((x[a] - want).abs() < 1e-12, "{x:?}");
        }
        let flat = place(&points[..2], &normals[..2]);
        assert!(
            (flat[0] - 0.3).abs() < 1e-12 && (flat[1] - 0.5).abs() < 1e-12,
            "{flat:?}"
        );
    }

    #[test]
    fn jacobi_finds_a_rotated_matrix_s_eigenvalues() {
        let m = [[2.0, 1.0, 0.0], [1.0, 2.0, 0.0], [0.0, 0.0, 5.0]];
        let (mut values, _) = eigen(m);
        values.sort_by(f64::total_cmp);
        for (got, want) in values.iter().zip([1.0, 3.0, 5.0]) {
            assert!((got - want).abs() < 1e-12, "{values:?}");
        }
    }
}
