//! The equations whose solutions are the critical points of the height
//! h(p) = ⟨p − o, n⟩ on M within one stratum of the domain: its interior (x, y, z, w free)
//! or a part of its boundary (a face, where two faces meet, an edge: one, two or three
//! coordinates fixed at their bounds). With S the free coordinates and λ a
//! multiplier, G(p, λ) = (F(p), ∂_S F(p) − λ n_S): |S| + 1 equations in as many unknowns,
//! with Jacobian [[∂_S F, 0], [H_SS, −n_S]]. Krawczyk's operator on it proves a box holds
//! exactly one solution, or none.

use crate::eval::{Box4, IntervalEvaluator};
use crate::formula::{CompiledFormula, HESSIAN_PAIRS};
use crate::interval::Interval;

use super::linalg::{self, Mat, N};

/// Unknowns of a system: the free coordinates in order, then λ (the first `dim` used).
pub type Unknowns = [Interval; N];

/// Where on the domain the critical points are sought.
#[derive(Debug, Clone, PartialEq)]
pub struct Stratum {
    /// The free coordinates, in increasing order.
    pub free: Vec<usize>,
    /// The value of each fixed coordinate; None where free.
    pub fixed: [Option<f64>; 4],
}

impl Stratum {
    pub fn interior() -> Self {
        Self {
            free: vec![0, 1, 2, 3],
            fixed: [None; 4],
        }
    }

    /// The part of the boundary where each `Some` coordinate has that value.
    pub fn boundary(fixed: [Option<f64>; 4]) -> Self {
        Self {
            free: (0..4).filter(|&i| fixed[i].is_none()).collect(),
            fixed,
        }
    }

    /// The number of unknowns (and equations).
    pub fn dim(&self) -> usize {
        self.free.len() + 1
    }
}

/// F, ∇F and the Hessian over a box, and whether F is twice continuously differentiable
/// there as far as the enclosures tell (only then do they bound slopes).
struct Jet {
    f: Interval,
    gradient: [Interval; 4],
    hessian: [[Interval; 4]; 4],
    smooth: bool,
}

/// What is known of F over a box that may hold a critical point: the range of λ, whether
/// F is twice continuously differentiable there, and whether it is Lipschitz (continuous,
/// with bounded slopes) there.
#[derive(Debug, Clone, Copy)]
pub struct Screened {
    pub lambda: Interval,
    pub smooth: bool,
    pub lipschitz: bool,
}

/// G and its Jacobian over some unknowns, and whether F is smooth there.
struct Linear {
    g: [Interval; N],
    j: [[Interval; N]; N],
    smooth: bool,
}

/// What Krawczyk's operator proves about a box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Proof {
    /// Exactly one solution in the box, and the Jacobian is regular on it; it lies in K(X),
    /// given.
    Unique(Unknowns),
    /// No solution in the box.
    None,
    /// Every solution in the box lies in this smaller one.
    Narrowed(Unknowns),
    /// Nothing learned.
    Unknown,
}

#[derive(Clone)]
pub struct System<'a> {
    formula: &'a CompiledFormula,
    params: &'a [f64],
    normal: [f64; 4],
    pub stratum: Stratum,
    evaluator: IntervalEvaluator,
    out: [Interval; 15],
}

impl<'a> System<'a> {
    pub fn new(
        formula: &'a CompiledFormula,
        params: &'a [f64],
        normal: [f64; 4],
        stratum: Stratum,
    ) -> Self {
        Self {
            formula,
            params,
            normal,
            stratum,
            evaluator: IntervalEvaluator::new(),
            out: [Interval::EMPTY; 15],
        }
    }

    pub fn dim(&self) -> usize {
        self.stratum.dim()
    }

    /// The box of R⁴ of some unknowns (their coordinates, and the fixed ones).
    pub fn space_box(&self, x: &Unknowns) -> Box4 {
        let mut free = self.stratum.free.iter().zip(x);
        std::array::from_fn(|axis| match self.stratum.fixed[axis] {
            Some(v) => Interval::point(v),
            None => *free.next().expect("a free axis").1,
        })
    }

    fn jet(&mut self, b: &Box4) -> Jet {
        let tape = &self.formula.tape_second;
        self.evaluator
            .eval_into(tape, b, self.params, &mut self.out);
        let smooth = self.evaluator.continuous_on_last_box(tape);
        let mut hessian = [[Interval::EMPTY; 4]; 4];
        for (k, &(i, j)) in HESSIAN_PAIRS.iter().enumerate() {
            let (i, j) = (usize::from(i), usize::from(j));
            hessian[i][j] = self.out[5 + k];
            hessian[j][i] = self.out[5 + k];
        }
        Jet {
            f: self.out[0],
            gradient: std::array::from_fn(|i| self.out[1 + i]),
            hessian,
            smooth,
        }
    }

    /// Whether the box of R⁴ may hold a critical point: F may vanish on it, and ∇_S F may be
    /// parallel to n_S (each 2×2 minor n_j ∂_i F − n_i ∂_j F may vanish); if so, what is
    /// known of F there.
    ///
    /// The minors exclude a box only where F is Lipschitz on it: continuous, with bounded
    /// enclosures of ∇F (a kink of |x|, min or max is, the edge of sqrt's domain or a jump
    /// is not). Then Clarke's generalized gradient lies in those enclosures, and where none
    /// of it is parallel to n2 the pair (F, h) is a Lipschitz submersion (Clarke's inverse
    /// function theorem): no change of the cut's topology in the box.
    pub fn screen(&mut self, b: &Box4) -> Option<Screened> {
        let jet = self.jet(b);
        if !jet.f.contains_zero() {
            return None;
        }
        let lipschitz = jet.smooth || self.lipschitz(b, &jet);
        if lipschitz {
            let free = &self.stratum.free;
            let n = |i: usize| Interval::point(self.normal[i]);
            for (a, &i) in free.iter().enumerate() {
                for &j in &free[a + 1..] {
                    let minor = n(j).mul(jet.gradient[i]).sub(n(i).mul(jet.gradient[j]));
                    if !minor.contains_zero() {
                        return None;
                    }
                }
            }
        }
        Some(Screened {
            lambda: self.multiplier(&jet),
            smooth: jet.smooth,
            lipschitz,
        })
    }

    /// Whether F is continuous on the box with bounded enclosures of its partials (`jet`'s,
    /// over the same box).
    fn lipschitz(&mut self, b: &Box4, jet: &Jet) -> bool {
        let bounded = jet
            .gradient
            .iter()
            .all(|g| !g.is_empty() && g.lo().is_finite() && g.hi().is_finite());
        bounded && {
            let tape = &self.formula.tape_f;
            self.evaluator.eval(tape, b, self.params);
            self.evaluator.continuous_on_last_box(tape)
        }
    }

    /// λ = ⟨∂_S F, n_S⟩ / |n_S|² over the box: where ∂_S F = λ n_S, λ lies in it.
    fn multiplier(&self, jet: &Jet) -> Interval {
        let (mut dot, mut norm) = (Interval::ZERO, Interval::ZERO);
        for &i in &self.stratum.free {
            let n = Interval::point(self.normal[i]);
            dot = dot.add(jet.gradient[i].mul(n));
            norm = norm.add(n.square());
        }
        dot.div(norm)
    }

    /// G and its Jacobian over the unknowns `x`, and whether F is smooth there.
    fn linearise(&mut self, x: &Unknowns) -> Linear {
        let b = self.space_box(x);
        let jet = self.jet(&b);
        let free = &self.stratum.free;
        let last = self.dim() - 1;
        let lambda = x[last];
        let mut g = [Interval::ZERO; N];
        let mut j = [[Interval::ZERO; N]; N];
        g[0] = jet.f;
        for (c, &i) in free.iter().enumerate() {
            j[0][c] = jet.gradient[i];
        }
        for (r, &i) in free.iter().enumerate() {
            let n = Interval::point(self.normal[i]);
            g[r + 1] = jet.gradient[i].sub(lambda.mul(n));
            for (c, &k) in free.iter().enumerate() {
                j[r + 1][c] = jet.hessian[i][k];
            }
            j[r + 1][last] = n.neg();
        }
        Linear {
            g,
            j,
            smooth: jet.smooth,
        }
    }

    /// Newton's method in floating point from `start`: an approximate solution, or None
    /// where it does not settle within a few steps.
    pub fn newton(&mut self, start: [f64; N]) -> Option<[f64; N]> {
        let dim = self.dim();
        let mut x = start;
        for _ in 0..8 {
            let point: Unknowns = std::array::from_fn(|i| Interval::point(x[i]));
            let Linear { g, j, .. } = self.linearise(&point);
            let inv = linalg::inverse(&midpoints(&j), dim)?;
            let g = g.map(Interval::midpoint);
            let mut size = 0.0f64;
            for i in 0..dim {
                let step: f64 = (0..dim).map(|k| inv[i][k] * g[k]).sum();
                x[i] -= step;
                size = size.max(step.abs() / (1.0 + x[i].abs()));
            }
            if !x.iter().all(|v| v.is_finite()) {
                return None;
            }
            if size < 1e-14 {
                return Some(x);
            }
        }
        None
    }

    /// Krawczyk's operator K(X) = m − Y G(m) + (I − Y J(X)) (X − m), with m in X and Y the
    /// inverse of J's midpoint: every solution in X lies in K(X); if K(X) lies in X's
    /// interior, X holds exactly one. Needs F smooth on X.
    pub fn krawczyk(&mut self, x: &Unknowns, m: &[f64; N]) -> Proof {
        let dim = self.dim();
        let Linear { j, smooth, .. } = self.linearise(x);
        if !smooth {
            return Proof::Unknown;
        }
        let Some(y) = linalg::inverse(&midpoints(&j), dim) else {
            return Proof::Unknown;
        };
        let at_m: Unknowns = std::array::from_fn(|i| Interval::point(m[i]));
        let Linear {
            g,
            smooth: smooth_at_m,
            ..
        } = self.linearise(&at_m);
        if !smooth_at_m || g.iter().take(dim).any(|v| v.is_empty()) {
            return Proof::Unknown;
        }
        let mut k = *x;
        let mut inside = true;
        let mut narrowed = *x;
        for i in 0..dim {
            let mut v = Interval::point(m[i]);
            for (l, gl) in g.iter().enumerate().take(dim) {
                v = v.sub(Interval::point(y[i][l]).mul(*gl));
            }
            for c in 0..dim {
                // (I − Y J)_ic, with Y's entries exact and J's rows intervals.
                let mut e = Interval::point(if i == c { 1.0 } else { 0.0 });
                for (l, row) in j.iter().enumerate().take(dim) {
                    e = e.sub(Interval::point(y[i][l]).mul(row[c]));
                }
                v = v.add(e.mul(x[c].sub(Interval::point(m[c]))));
            }
            k[i] = v;
            if v.is_empty() {
                return Proof::Unknown;
            }
            inside &= v.lo() > x[i].lo() && v.hi() < x[i].hi();
            narrowed[i] = x[i].intersect(v.lo(), v.hi());
            if narrowed[i].is_empty() {
                return Proof::None;
            }
        }
        if inside {
            Proof::Unique(k)
        } else if (0..dim).any(|i| narrowed[i].width() < 0.9 * x[i].width()) {
            Proof::Narrowed(narrowed)
        } else {
            Proof::Unknown
        }
    }

    /// The Hessian block H_SS over a box of R⁴, bordered by n_S: the matrix whose inertia
    /// gives that of H restricted to the stratum's tangent space at a critical point.
    pub fn bordered_hessian(&mut self, b: &Box4) -> [[Interval; N]; N] {
        let jet = self.jet(b);
        let free = &self.stratum.free;
        let mut m = [[Interval::ZERO; N]; N];
        for (r, &i) in free.iter().enumerate() {
            m[0][r + 1] = Interval::point(self.normal[i]);
            m[r + 1][0] = Interval::point(self.normal[i]);
            for (c, &k) in free.iter().enumerate() {
                m[r + 1][c + 1] = jet.hessian[i][k];
            }
        }
        m
    }
}

pub fn midpoints(m: &[[Interval; N]; N]) -> Mat {
    m.map(|row| row.map(Interval::midpoint))
}
