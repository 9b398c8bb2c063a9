//! The search over one stratum: boxes are split until each is proved to hold no critical
//! point, proved to hold exactly one (Krawczyk, tried on the box grown by a tenth around a
//! Newton point, so that a point on a split plane is inside some box), or reaches the
//! finest size. The boxes left at the finest size are grouped into touching clusters and
//! reported, never dropped.

use std::sync::atomic::{AtomicUsize, Ordering};

use crate::eval::Box4;
use crate::interval::Interval;

use super::inertia::inertia;
use super::linalg::N;
use super::system::{Proof, Screened, System, Unknowns};

/// A critical point proved unique in `region`, enclosed by `tight`.
#[derive(Debug, Clone)]
pub struct Proved {
    pub region: Unknowns,
    pub tight: Unknowns,
    /// The Morse index, where the restricted Hessian's inertia is proved too.
    pub index: Option<u8>,
}

/// A box the search could not decide at the finest size (or when the budget ran out).
#[derive(Debug, Clone)]
pub struct Leftover {
    pub space: Box4,
    /// F is twice continuously differentiable on it.
    pub smooth: bool,
}

#[derive(Debug, Default)]
pub struct Outcome {
    pub proved: Vec<Proved>,
    pub leftovers: Vec<Leftover>,
    pub visited: usize,
}

/// Searches `start` (a box of the stratum, fixed coordinates as points). `finest[axis]`:
/// boxes narrower than it on every free axis are not split. `budget` counts the boxes
/// looked at across strata; what is pending when it runs out is left over. `known`: points
/// already proved (the boxes in their regions need no more search).
pub fn search(
    system: &mut System,
    start: Box4,
    finest: [f64; 4],
    budget: &AtomicUsize,
    known: &[Proved],
) -> Outcome {
    let mut outcome = Outcome {
        proved: known.to_vec(),
        ..Outcome::default()
    };
    let mut stack = vec![start];
    'boxes: while let Some(b) = stack.pop() {
        let spent = budget
            .fetch_update(Ordering::Relaxed, Ordering::Relaxed, |left| {
                left.checked_sub(1)
            })
            .is_err();
        if spent {
            outcome.leftovers.push(Leftover {
                space: b,
                smooth: false,
            });
            continue;
        }
        outcome.visited += 1;
        let Some(mut known) = system.screen(&b) else {
            continue;
        };
        let mut b = b;
        // A box Krawczyk narrows is tried again as it is now, a few times.
        for _ in 0..4 {
            let lambda = known.lambda;
            if !(known.smooth && lambda.lo().is_finite() && lambda.hi().is_finite()) {
                break;
            }
            match decide(system, &b, lambda, finest, &mut outcome.proved) {
                Decision::Done => continue 'boxes,
                Decision::Narrowed(narrower) => {
                    b = narrower;
                    let Some(screened) = system.screen(&b) else {
                        continue 'boxes;
                    };
                    known = screened;
                }
                Decision::Open => break,
            }
        }
        // Where F is not even Lipschitz (the edge of sqrt's domain, a jump) no split can
        // decide a box: it is left three levels coarser, where it costs 8^k times fewer
        // boxes along a k-dimensional set.
        let smallest = if known.lipschitz {
            finest
        } else {
            finest.map(|f| 8.0 * f)
        };
        let free = &system.stratum.free;
        let widest = free
            .iter()
            .copied()
            .filter(|&a| b[a].width() > smallest[a])
            .max_by(|&a, &c| (b[a].width() / smallest[a]).total_cmp(&(b[c].width() / smallest[c])));
        match widest {
            Some(axis) => {
                let [low, high] = halves(b, axis);
                stack.push(high);
                stack.push(low);
            }
            None => outcome.leftovers.push(Leftover {
                space: b,
                smooth: known.smooth,
            }),
        }
    }
    outcome
}

/// `b` halved across `axis`: the lower half, then the upper.
pub fn halves(b: Box4, axis: usize) -> [Box4; 2] {
    let mid = b[axis].midpoint();
    let (mut low, mut high) = (b, b);
    low[axis] = Interval::new(b[axis].lo(), mid);
    high[axis] = Interval::new(mid, b[axis].hi());
    [low, high]
}

enum Decision {
    /// No critical point is left undiscovered in the box.
    Done,
    /// Any critical point in the box lies in this smaller one.
    Narrowed(Box4),
    Open,
}

fn decide(
    system: &mut System,
    b: &Box4,
    lambda: Interval,
    finest: [f64; 4],
    proved: &mut Vec<Proved>,
) -> Decision {
    let dim = system.dim();
    let unknowns = unknowns_of(system, b, lambda);
    let centre: [f64; N] = std::array::from_fn(|i| unknowns[i].midpoint());
    if proved.iter().any(|p| within(&unknowns, &p.region, dim - 1)) {
        // The box lies where a point already found is the only one.
        return Decision::Done;
    }
    if let Some(m) = system.newton(centre) {
        // The box centred on the Newton point that holds this one with a margin of a tenth
        // of it (or of a finest box where Krawczyk narrowed it more): Krawczyk's operator
        // contracts best about its centre, and so a point on a split plane or just outside
        // is found too.
        let mut grown = unknowns;
        let mut near = true;
        for (i, &axis) in system.stratum.free.iter().enumerate() {
            let v = grown[i];
            let d = 0.1 * v.width().max(finest[axis]);
            let r = (m[i] - v.lo()).abs().max((v.hi() - m[i]).abs()) + d;
            near &= r <= 2.0 * v.width() + d;
            grown[i] = Interval::new(m[i] - r, m[i] + r);
        }
        if near {
            let grown_space = system.space_box(&grown);
            // λ over the grown box, from ∇F there (no critical point there if screened out).
            let Some(Screened { lambda, .. }) = system.screen(&grown_space) else {
                return Decision::Done;
            };
            // λ's range, widened too: where ∇F is nearly constant it is a few ulps wide,
            // and K(X) could never fall strictly inside it.
            let mut region = grown;
            let lambda = lambda.hull(Interval::point(m[dim - 1]));
            let d = 0.1 * lambda.width() + 1e-9 * (1.0 + m[dim - 1].abs());
            region[dim - 1] = Interval::new(lambda.lo() - d, lambda.hi() + d);
            match system.krawczyk(&region, &m) {
                Proof::Unique(k) => {
                    record(system, region, k, proved);
                    return Decision::Done;
                }
                Proof::None => return Decision::Done,
                _ => {}
            }
        }
    }
    match system.krawczyk(&unknowns, &centre) {
        Proof::None => Decision::Done,
        Proof::Unique(k) => {
            record(system, unknowns, k, proved);
            Decision::Done
        }
        Proof::Narrowed(k) => Decision::Narrowed(system.space_box(&k)),
        Proof::Unknown => Decision::Open,
    }
}

/// The unknowns of a box of R⁴ with λ's range over it.
fn unknowns_of(system: &System, b: &Box4, lambda: Interval) -> Unknowns {
    let mut u = [Interval::ZERO; N];
    for (i, &axis) in system.stratum.free.iter().enumerate() {
        u[i] = b[axis];
    }
    u[system.dim() - 1] = lambda;
    u
}

/// Adds the point proved unique in `region` (with K(region) = `k`) unless it is one already
/// found.
fn record(system: &mut System, region: Unknowns, k: Unknowns, proved: &mut Vec<Proved>) {
    let dim = system.dim();
    let tight = tighten(system, &region, k);
    let point = Proved {
        region,
        tight,
        index: None,
    };
    if !proved.iter().any(|p| same(p, &point, dim)) {
        let index = morse_index(system, &point.tight);
        proved.push(Proved { index, ..point });
    }
}

/// Whether two proved points are one: one's enclosure lies in the other's region of
/// uniqueness.
pub fn same(a: &Proved, b: &Proved, dim: usize) -> bool {
    within(&a.tight, &b.region, dim) || within(&b.tight, &a.region, dim)
}

/// The outcomes of searches over parts of one stratum as one: each point once, and the
/// boxes left over only where no proved point's region of uniqueness holds them.
pub fn merge(outcomes: Vec<Outcome>, system: &System) -> Outcome {
    let dim = system.dim();
    let mut merged = Outcome::default();
    for outcome in outcomes {
        merged.visited += outcome.visited;
        for p in outcome.proved {
            if !merged.proved.iter().any(|q| same(q, &p, dim)) {
                merged.proved.push(p);
            }
        }
        merged.leftovers.extend(outcome.leftovers);
    }
    let free = &system.stratum.free;
    merged.leftovers.retain(|l| {
        !merged.proved.iter().any(|p| {
            free.iter().enumerate().all(|(i, &axis)| {
                p.region[i].lo() <= l.space[axis].lo() && l.space[axis].hi() <= p.region[i].hi()
            })
        })
    });
    merged
}

/// A narrow enclosure of the point proved unique in `region`, whose K(region) is `k`: a
/// small box about the Newton point that Krawczyk's operator proves to hold a solution
/// holds the one; else K applied again and again, while it shrinks the box (each K(X) ∩ X
/// still holds the point).
fn tighten(system: &mut System, region: &Unknowns, mut x: Unknowns) -> Unknowns {
    let dim = system.dim();
    let mid: [f64; N] = std::array::from_fn(|i| x[i].midpoint());
    if let Some(m) = system
        .newton(mid)
        .filter(|m| (0..dim).all(|i| x[i].contains(m[i])))
    {
        for radius in [1e-12, 1e-10, 1e-8, 1e-6] {
            let mut small = x;
            for i in 0..dim {
                let r = radius * (1.0 + m[i].abs());
                small[i] = Interval::new(m[i] - r, m[i] + r);
            }
            if !within(&small, region, dim) {
                break;
            }
            if let Proof::Unique(k) = system.krawczyk(&small, &m) {
                return k;
            }
        }
    }
    for _ in 0..60 {
        let before = widest(&x, dim);
        let m: [f64; N] = std::array::from_fn(|i| x[i].midpoint());
        match system.krawczyk(&x, &m) {
            Proof::Unique(k) | Proof::Narrowed(k) => x = intersect(&x, &k, dim),
            _ => break,
        }
        if widest(&x, dim) > 0.9 * before {
            break;
        }
    }
    x
}

/// Whether the first `count` unknowns of `a` lie in those of `b`.
fn within(a: &Unknowns, b: &Unknowns, count: usize) -> bool {
    (0..count).all(|i| b[i].lo() <= a[i].lo() && a[i].hi() <= b[i].hi())
}

fn intersect(a: &Unknowns, b: &Unknowns, dim: usize) -> Unknowns {
    let mut c = *a;
    for i in 0..dim {
        let v = a[i].intersect(b[i].lo(), b[i].hi());
        if !v.is_empty() {
            c[i] = v;
        }
    }
    c
}

fn widest(x: &Unknowns, dim: usize) -> f64 {
    x.iter().take(dim).map(|v| v.width()).fold(0.0, f64::max)
}

/// The index of the height at the point in `tight`: with ∇F = λ n there, the height's
/// Hessian on M is −H/λ on the tangent space, so its negative eigenvalues are H's positive
/// ones where λ > 0 and H's negative ones where λ < 0.
fn morse_index(system: &mut System, tight: &Unknowns) -> Option<u8> {
    let dim = system.dim();
    let bordered = system.bordered_hessian(&system.space_box(tight));
    let (negative, positive) = inertia(&bordered, dim)?;
    let lambda = tight[dim - 1];
    let count = if lambda.lo() > 0.0 {
        positive.checked_sub(1)?
    } else if lambda.hi() < 0.0 {
        negative.checked_sub(1)?
    } else {
        return None;
    };
    u8::try_from(count).ok()
}

/// Groups boxes that touch (closed boxes sharing a point) into clusters.
pub fn clusters(leftovers: &[Leftover]) -> Vec<Vec<usize>> {
    let mut order: Vec<usize> = (0..leftovers.len()).collect();
    order.sort_by(|&a, &b| {
        leftovers[a].space[0]
            .lo()
            .total_cmp(&leftovers[b].space[0].lo())
    });
    let mut parent: Vec<usize> = (0..leftovers.len()).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for (k, &a) in order.iter().enumerate() {
        for &b in &order[k + 1..] {
            if leftovers[b].space[0].lo() > leftovers[a].space[0].hi() {
                break;
            }
            let touch = (0..4).all(|i| {
                let (p, q) = (leftovers[a].space[i], leftovers[b].space[i]);
                p.lo() <= q.hi() && q.lo() <= p.hi()
            });
            if touch {
                let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
                parent[ra] = rb;
            }
        }
    }
    let mut groups: std::collections::BTreeMap<usize, Vec<usize>> = Default::default();
    for i in 0..leftovers.len() {
        let r = root(&mut parent, i);
        groups.entry(r).or_default().push(i);
    }
    groups.into_values().collect()
}
