//! Dense linear algebra for the critical-point systems, in f64: at most 5×5 (four
//! coordinates and a multiplier), so two plain routines rather than a general crate that
//! would add to the page's size. Matrices are used through their leading n×n block.

/// The largest system: four coordinates and the multiplier λ.
pub const N: usize = 5;

pub type Mat = [[f64; N]; N];

/// The inverse of the leading n×n block of `a` (Gauss–Jordan with partial pivoting); None
/// where it is singular to working precision or not finite.
pub fn inverse(a: &Mat, n: usize) -> Option<Mat> {
    let mut m = *a;
    let mut inv = identity();
    let scale = (0..n)
        .flat_map(|i| (0..n).map(move |j| (i, j)))
        .map(|(i, j)| a[i][j].abs())
        .fold(0.0, f64::max);
    if !(scale > 0.0 && scale.is_finite()) {
        return None;
    }
    for col in 0..n {
        let pivot = (col..n).max_by(|&r, &s| m[r][col].abs().total_cmp(&m[s][col].abs()))?;
        if !(m[pivot][col].abs() > 1e-13 * scale) {
            return None;
        }
        m.swap(col, pivot);
        inv.swap(col, pivot);
        let p = m[col][col];
        for j in 0..n {
            m[col][j] /= p;
            inv[col][j] /= p;
        }
        for r in (0..n).filter(|&r| r != col) {
            let k = m[r][col];
            if k != 0.0 {
                for j in 0..n {
                    m[r][j] -= k * m[col][j];
                    inv[r][j] -= k * inv[col][j];
                }
            }
        }
    }
    inv.iter().flatten().all(|v| v.is_finite()).then_some(inv)
}

/// The eigenvectors (as columns) of the leading n×n block of the symmetric `a`, by cyclic
/// Jacobi rotations: accurate for such small matrices, and always orthogonal.
pub fn eigenvectors(a: &Mat, n: usize) -> Mat {
    let mut m = *a;
    let mut v = identity();
    for _sweep in 0..50 {
        let off: f64 = (0..n)
            .flat_map(|i| (0..n).filter(move |&j| j != i).map(move |j| (i, j)))
            .map(|(i, j)| m[i][j] * m[i][j])
            .sum();
        if !(off > 1e-300) {
            break;
        }
        for p in 0..n {
            for q in p + 1..n {
                if m[p][q] == 0.0 {
                    continue;
                }
                let theta = (m[q][q] - m[p][p]) / (2.0 * m[p][q]);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for k in 0..n {
                    let (mkp, mkq) = (m[k][p], m[k][q]);
                    m[k][p] = c * mkp - s * mkq;
                    m[k][q] = s * mkp + c * mkq;
                }
                for k in 0..n {
                    let (mpk, mqk) = (m[p][k], m[q][k]);
                    m[p][k] = c * mpk - s * mqk;
                    m[q][k] = s * mpk + c * mqk;
                }
                for row in v.iter_mut().take(n) {
                    let (vkp, vkq) = (row[p], row[q]);
                    row[p] = c * vkp - s * vkq;
                    row[q] = s * vkp + c * vkq;
                }
            }
        }
    }
    v
}

fn identity() -> Mat {
    std::array::from_fn(|i| std::array::from_fn(|j| if i == j { 1.0 } else { 0.0 }))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn product(a: &Mat, b: &Mat, n: usize) -> Mat {
        let mut c = [[0.0; N]; N];
        for i in 0..n {
            for j in 0..n {
                c[i][j] = (0..n).map(|k| a[i][k] * b[k][j]).sum();
            }
        }
        c
    }

    #[test]
    fn inverse_undoes_the_matrix_and_refuses_a_singular_one() {
        let mut a = [[0.0; N]; N];
        let rows = [[0.0, 1.0, 2.0], [3.0, -1.0, 0.5], [1.0, 1.0, 1.0]];
        for (i, row) in rows.iter().enumerate() {
            a[i][..3].copy_from_slice(row);
        }
        let inv = inverse(&a, 3).expect("regular");
        let id = product(&a, &inv, 3);
        for (i, row) in id.iter().take(3).enumerate() {
            for (j, v) in row.iter().take(3).enumerate() {
                assert!((v - f64::from(u8::from(i == j))).abs() < 1e-12);
            }
        }
        a[2] = [3.0, 0.0, 2.5, 0.0, 0.0]; // row 0 + row 1
        assert!(inverse(&a, 3).is_none());
    }

    #[test]
    fn eigenvectors_diagonalise_a_symmetric_matrix() {
        let mut a = [[0.0; N]; N];
        let rows = [
            [0.0, 0.3, 0.0, 1.0],
            [0.3, 2.0, -1.0, 0.0],
            [0.0, -1.0, 1.0, 0.2],
            [1.0, 0.0, 0.2, -3.0],
        ];
        for (i, row) in rows.iter().enumerate() {
            a[i][..4].copy_from_slice(row);
        }
        let v = eigenvectors(&a, 4);
        let vt: Mat = std::array::from_fn(|i| std::array::from_fn(|j| v[j][i]));
        let d = product(&vt, &product(&a, &v, 4), 4);
        for (i, row) in d.iter().take(4).enumerate() {
            for (j, x) in row.iter().take(4).enumerate() {
                if i != j {
                    assert!(x.abs() < 1e-12, "{d:?}");
                }
            }
        }
    }
}
