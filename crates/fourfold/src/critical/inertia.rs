//! The Morse index at a proved critical point, proved too. The index of the height on M is
//! read from the inertia of the Hessian of F restricted to the tangent space, which is that
//! of the bordered matrix [[0, nᵀ], [n, H]] less one positive and one negative eigenvalue.
//! Inertia is kept by any congruence (Sylvester's law): C = Qᵀ B Q with Q the eigenvectors
//! of B's midpoint is nearly diagonal, and where each of C's Gershgorin discs leaves out 0,
//! the discs' signs count B's positive and negative eigenvalues for every B in the box.

use crate::interval::Interval;

use super::linalg::{self, N};
use super::system::midpoints;

/// (negative, positive) eigenvalues of every symmetric matrix in the leading n×n block of
/// the interval matrix `b`; None where a disc holds 0 (singular, or not tight enough).
pub fn inertia(b: &[[Interval; N]; N], n: usize) -> Option<(usize, usize)> {
    let q = linalg::eigenvectors(&midpoints(b), n);
    // C = Qᵀ B Q, in interval arithmetic with Q's entries exact.
    let mut bq = [[Interval::ZERO; N]; N];
    for i in 0..n {
        for j in 0..n {
            bq[i][j] = (0..n).fold(Interval::ZERO, |acc, k| {
                acc.add(b[i][k].mul(Interval::point(q[k][j])))
            });
        }
    }
    let (mut negative, mut positive) = (0, 0);
    for i in 0..n {
        let row: Vec<Interval> = (0..n)
            .map(|j| {
                (0..n).fold(Interval::ZERO, |acc, k| {
                    acc.add(Interval::point(q[k][i]).mul(bq[k][j]))
                })
            })
            .collect();
        let radius = (0..n)
            .filter(|&j| j != i)
            .fold(Interval::ZERO, |acc, j| acc.add(row[j].abs()))
            .hi();
        let centre = row[i];
        if centre.lo() - radius > 0.0 && (centre.lo() - radius).is_finite() {
            positive += 1;
        } else if centre.hi() + radius < 0.0 && (centre.hi() + radius).is_finite() {
            negative += 1;
        } else {
            return None;
        }
    }
    Some((negative, positive))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn matrix(rows: &[&[f64]]) -> [[Interval; N]; N] {
        let mut m = [[Interval::ZERO; N]; N];
        for (i, row) in rows.iter().enumerate() {
            for (j, v) in row.iter().enumerate() {
                m[i][j] = Interval::new(v - 1e-9, v + 1e-9);
            }
        }
        m
    }

    #[test]
    fn counts_the_signs_of_a_bordered_hessian() {
        // H = diag(2, −1, 3) bordered by n = (0, 0, 1): on n⊥, diag(2, −1): one of each,
        // so the bordered matrix has two negative and two positive eigenvalues.
        let b = matrix(&[
            &[0.0, 0.0, 0.0, 1.0],
            &[0.0, 2.0, 0.0, 0.0],
            &[0.0, 0.0, -1.0, 0.0],
            &[1.0, 0.0, 0.0, 3.0],
        ]);
        assert_eq!(inertia(&b, 4), Some((2, 2)));
    }

    #[test]
    fn refuses_a_singular_matrix() {
        let b = matrix(&[&[0.0, 1.0, 0.0], &[1.0, 0.0, 0.0], &[0.0, 0.0, 0.0]]);
        assert_eq!(inertia(&b, 3), None);
    }
}
