//! Turning the view by dragging: a rotation in the view's own planes, expressed as new
//! values of the six angles.

use super::camera::{Rotation4, plane_rotation};

/// The six angles of `A' = R·A`, where R turns row `i` of A towards row `j` by `delta`
/// (rows 0, 1 span the projection plane, 2, 3 the observer plane): rotating the view in its
/// own planes, as a mouse drag does. The angles are found by damped Gauss–Newton from the
/// current ones, so they change continuously with the drag.
pub fn rotate_view(angles: [f64; 6], i: usize, j: usize, delta: f64) -> [f64; 6] {
    let target = plane_rotation(i, j, delta) * Rotation4::from_angles(angles).0;
    let residual = |t: &[f64; 6]| -> [f64; 16] {
        let m = Rotation4::from_angles(*t).0 - target;
        m.to_cols_array()
    };
    let mut t = angles;
    for _ in 0..8 {
        let r0 = residual(&t);
        let norm: f64 = r0.iter().map(|v| v * v).sum();
        if norm < 1e-24 {
            break;
        }
        // Jacobian by central differences (6 columns of 16).
        let h = 1e-6;
        let mut jac = [[0.0; 16]; 6];
        for (k, col) in jac.iter_mut().enumerate() {
            let (mut a, mut b) = (t, t);
            a[k] += h;
            b[k] -= h;
            let (ra, rb) = (residual(&a), residual(&b));
            for r in 0..16 {
                col[r] = (ra[r] - rb[r]) / (2.0 * h);
            }
        }
        // (JᵀJ + λI) step = −Jᵀr, solved by Gaussian elimination with partial pivoting.
        let mut m = [[0.0; 7]; 6];
        for a in 0..6 {
            for b in 0..6 {
                m[a][b] = (0..16).map(|r| jac[a][r] * jac[b][r]).sum();
            }
            m[a][a] += 1e-9;
            m[a][6] = -(0..16).map(|r| jac[a][r] * r0[r]).sum::<f64>();
        }
        for c in 0..6 {
            let p = (c..6)
                .max_by(|&x, &y| m[x][c].abs().total_cmp(&m[y][c].abs()))
                .unwrap_or(c);
            m.swap(c, p);
            if m[c][c].abs() < 1e-15 {
                continue;
            }
            for r in 0..6 {
                if r != c {
                    let f = m[r][c] / m[c][c];
                    for k in c..7 {
                        m[r][k] -= f * m[c][k];
                    }
                }
            }
        }
        for k in 0..6 {
            if m[k][k].abs() >= 1e-15 {
                t[k] += m[k][6] / m[k][k];
            }
        }
    }
    // Keep the angles in (−π, π].
    t.map(|a| {
        let w = (a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
        if w.is_finite() { w } else { 0.0 }
    })
}
