//! The proved critical values of the slice sweep: the places c along the view's n2 where
//! the slice of M (within the domain) can change its topology. They are the critical values
//! of the height h(p) = ⟨p − o, n2⟩ (o the domain's centre) on M, and on M's cut by each
//! part of the domain's boundary (faces, where faces meet, edges). Boxes of R⁴ are split
//! until each is proved to hold no critical point or exactly one ([`system`]: Krawczyk's
//! operator on F = 0, ∇F = λ n2), whose Morse index is proved from the restricted
//! Hessian's inertia ([`inertia`]); what stays undecided at the finest boxes is reported as
//! such (docs/critical.md).

mod inertia;
mod linalg;
mod search;
pub mod sweep;
mod system;

use std::sync::atomic::{AtomicUsize, Ordering};

use rayon::prelude::*;
use serde::Serialize;

use crate::eval::Box4;
use crate::formula::CompiledFormula;
use crate::interval::Interval;
use crate::render::view::Rotation4;
use crate::scene::Scene;
use crate::scene::limits::{CRITICAL_BOX_BUDGET, CRITICAL_LEVELS, DEFAULT_CRITICAL_LEVEL};

use system::{Stratum, System};

/// How hard to look.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CriticalSettings {
    /// The finest boxes are the domain / 2^level along each axis.
    pub max_level: u32,
    /// The most boxes looked at, over all strata; what is pending then is undecided.
    pub box_budget: usize,
    /// Also the critical points on M's cut by the domain's boundary: its faces, where two
    /// faces meet, and its edges.
    pub boundary: bool,
}

impl Default for CriticalSettings {
    fn default() -> Self {
        Self {
            max_level: DEFAULT_CRITICAL_LEVEL,
            box_budget: CRITICAL_BOX_BUDGET,
            boundary: true,
        }
    }
}

/// What is known about a reported place.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Status {
    /// Exactly one critical point in the enclosure, non-degenerate.
    Proved,
    /// F is smooth there, but down to the finest boxes the critical points could not be
    /// isolated: a degenerate or non-isolated critical point (a cylinder's line, a circle
    /// of tops), or critical points closer together than a finest box.
    Degenerate,
    /// F is not smooth on some of these boxes (a kink, the edge of where it is defined), or
    /// the budget ran out before they were decided.
    Undecided,
}

impl Status {
    pub fn name(self) -> &'static str {
        match self {
            Status::Proved => "proved",
            Status::Degenerate => "degenerate",
            Status::Undecided => "undecided",
        }
    }
}

/// Where in the domain a critical point lies.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Place {
    Interior,
    /// On the domain's boundary, where each `Some` coordinate (x, y, z, w) is at that
    /// bound: one on a face, two where two faces meet, three on an edge.
    Boundary {
        fixed: [Option<f64>; 4],
    },
}

impl Place {
    /// "inside", or the boundary's equations, as "x=2, y=-2".
    pub fn describe(&self) -> String {
        match self {
            Place::Interior => "inside".into(),
            Place::Boundary { fixed } => fixed
                .iter()
                .zip(["x", "y", "z", "w"])
                .filter_map(|(v, name)| v.map(|v| format!("{name}={v}")))
                .collect::<Vec<_>>()
                .join(", "),
        }
    }
}

/// `{"kind": "interior"}`, or `{"kind": "boundary", "on": "x=2, y=-2"}`.
impl Serialize for Place {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let boundary = matches!(self, Place::Boundary { .. });
        let mut s = serializer.serialize_struct("Place", 1 + usize::from(boundary))?;
        s.serialize_field("kind", if boundary { "boundary" } else { "interior" })?;
        if boundary {
            s.serialize_field("on", &self.describe())?;
        }
        s.end()
    }
}

/// One critical point, or one cluster of undecided boxes.
#[derive(Debug, Clone, PartialEq)]
pub struct CriticalPoint {
    /// An enclosure of the critical value c (the slice's place along n2).
    pub value: Interval,
    /// An enclosure of the point (for a cluster, of all its boxes).
    pub enclosure: Box4,
    /// The height's Morse index there (on the boundary: of the height on M's cut by that
    /// part of it), where proved.
    pub index: Option<u8>,
    pub status: Status,
    pub place: Place,
    /// How many finest boxes a degenerate or undecided cluster holds (1 for a point).
    pub boxes: usize,
}

impl CriticalPoint {
    /// The enclosure's centre.
    pub fn point(&self) -> [f64; 4] {
        self.enclosure.map(Interval::midpoint)
    }

    /// What happens to the slice as c passes this value upwards, in words.
    pub fn meaning(&self) -> &'static str {
        match (self.status, self.place, self.index) {
            (Status::Proved, Place::Interior, Some(0)) => "a component is born",
            (Status::Proved, Place::Interior, Some(1)) => "two pieces join, or a tunnel opens",
            (Status::Proved, Place::Interior, Some(2)) => "a tunnel closes, or a piece splits",
            (Status::Proved, Place::Interior, Some(3)) => "a component vanishes",
            (Status::Proved, Place::Boundary { .. }, Some(_)) => {
                "the cut changes where M meets the domain's boundary"
            }
            (Status::Proved, _, _) => "a critical point whose index is not proved",
            (Status::Degenerate, Place::Interior, _) => {
                "a degenerate or non-isolated critical point"
            }
            (Status::Degenerate, Place::Boundary { .. }, _) => {
                "M meets the domain's boundary degenerately (or the slice lies along it)"
            }
            (Status::Undecided, _, _) => "undecided: the slice may change here",
        }
    }
}

/// Every place where the slice's topology can change, in increasing order of their
/// enclosures' middles.
#[derive(Debug, Clone, PartialEq)]
pub struct CriticalReport {
    pub points: Vec<CriticalPoint>,
    /// Boxes looked at, in all strata.
    pub visited: usize,
    /// Finest boxes left degenerate or undecided.
    pub degenerate_boxes: usize,
    pub undecided_boxes: usize,
    /// Whether the box budget ran out (the rest is reported undecided).
    pub budget_spent: bool,
    /// The slices within ±reach of the domain's centre meet the domain.
    pub reach: f64,
}

impl CriticalReport {
    /// The nearest value wholly above `c` (by its enclosure's lower end), if any.
    pub fn next_after(&self, c: f64) -> Option<&CriticalPoint> {
        self.points
            .iter()
            .filter(|p| p.value.lo() > c)
            .min_by(|a, b| a.value.lo().total_cmp(&b.value.lo()))
    }

    /// The nearest value wholly below `c` (by its enclosure's upper end), if any.
    pub fn next_before(&self, c: f64) -> Option<&CriticalPoint> {
        self.points
            .iter()
            .filter(|p| p.value.hi() < c)
            .max_by(|a, b| a.value.hi().total_cmp(&b.value.hi()))
    }
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CriticalError {
    #[error("the search's level must be within {lo}..={hi}, not {level}")]
    Level { level: u32, lo: u32, hi: u32 },
}

/// The critical values of the slice sweep for `formula` in `scene`'s view and domain.
pub fn critical_values(
    formula: &CompiledFormula,
    scene: &Scene,
    settings: &CriticalSettings,
) -> Result<CriticalReport, CriticalError> {
    if !CRITICAL_LEVELS.contains(&settings.max_level) {
        return Err(CriticalError::Level {
            level: settings.max_level,
            lo: *CRITICAL_LEVELS.start(),
            hi: *CRITICAL_LEVELS.end(),
        });
    }
    let params = scene.param_values(&formula.param_names());
    let normal = Rotation4::from_angles(scene.view.angles).row(3);
    let domain = scene.domain.to_box();
    let centre = scene.domain.center();
    let scale = 0.5f64.powi(settings.max_level as i32);
    let finest = domain.map(|r| r.width() * scale);
    let mut strata = vec![Stratum::interior()];
    if settings.boundary {
        strata.extend(boundary_strata(&domain));
    }
    let budget = AtomicUsize::new(settings.box_budget);
    let mut report = CriticalReport {
        points: Vec::new(),
        visited: 0,
        degenerate_boxes: 0,
        undecided_boxes: 0,
        budget_spent: false,
        reach: (0..4)
            .map(|i| normal[i].abs() * 0.5 * domain[i].width())
            .sum(),
    };
    for stratum in strata {
        // A face across which n2 has no component is a level set of the height at the end
        // of the slice's range. (Where faces meet or on an edge such a level set can lie
        // anywhere: there no box is excluded by the gradient, λ is not bounded, and the
        // boxes where F may vanish are reported, at that height.)
        if stratum.free.len() == 3 && stratum.free.iter().all(|&i| normal[i].abs() < 1e-9) {
            continue;
        }
        let place = match stratum.free.len() {
            4 => Place::Interior,
            _ => Place::Boundary {
                fixed: stratum.fixed,
            },
        };
        let mut start = domain;
        for (axis, v) in stratum.fixed.iter().enumerate() {
            if let Some(v) = v {
                start[axis] = Interval::point(*v);
            }
        }
        let system = System::new(formula, &params, normal, stratum);
        let outcome = search_stratum(&system, start, finest, &budget);
        report.visited += outcome.visited;
        let height = |b: &Box4| {
            (0..4).fold(Interval::ZERO, |acc, i| {
                acc.add(
                    b[i].sub(Interval::point(centre[i]))
                        .mul(Interval::point(normal[i])),
                )
            })
        };
        for p in &outcome.proved {
            let enclosure = system.space_box(&p.tight);
            // Grown boxes reach past the domain: keep only points that may lie in it.
            let meets = (0..4).all(|i| {
                enclosure[i].hi() >= domain[i].lo() && enclosure[i].lo() <= domain[i].hi()
            });
            if meets {
                report.points.push(CriticalPoint {
                    value: height(&enclosure),
                    enclosure,
                    index: p.index,
                    status: Status::Proved,
                    place,
                    boxes: 1,
                });
            }
        }
        for cluster in search::clusters(&outcome.leftovers) {
            let boxes: Vec<&search::Leftover> =
                cluster.iter().map(|&i| &outcome.leftovers[i]).collect();
            let enclosure = boxes
                .iter()
                .map(|l| l.space)
                .reduce(|a, b| std::array::from_fn(|i| a[i].hull(b[i])))
                .expect("a cluster has a box");
            let value = boxes
                .iter()
                .map(|l| height(&l.space))
                .reduce(Interval::hull)
                .expect("a cluster has a box");
            let status = if boxes.iter().all(|l| l.smooth) {
                report.degenerate_boxes += boxes.len();
                Status::Degenerate
            } else {
                report.undecided_boxes += boxes.len();
                Status::Undecided
            };
            report.points.push(CriticalPoint {
                value,
                enclosure,
                index: None,
                status,
                place,
                boxes: boxes.len(),
            });
        }
    }
    report.budget_spent = budget.load(Ordering::Relaxed) == 0;
    report.points.sort_by(|a, b| {
        let mid = |p: &CriticalPoint| p.value.midpoint();
        mid(a).total_cmp(&mid(b))
    });
    Ok(report)
}

/// The parts of the domain's boundary, faces first, then where two faces meet, then the
/// edges (the corners matter only at the ends of the slice's range, where the slice
/// first and last meets the domain).
fn boundary_strata(domain: &Box4) -> Vec<Stratum> {
    let mut strata = Vec::new();
    for count in 1..=3 {
        for mask in (1u32..16).filter(|m| m.count_ones() == count) {
            let axes: Vec<usize> = (0..4).filter(|&a| mask >> a & 1 == 1).collect();
            for sides in 0..1u32 << count {
                let mut fixed = [None; 4];
                for (k, &a) in axes.iter().enumerate() {
                    let r = domain[a];
                    fixed[a] = Some(if sides >> k & 1 == 1 { r.hi() } else { r.lo() });
                }
                strata.push(Stratum::boundary(fixed));
            }
        }
    }
    strata
}

/// The search over one stratum from `start`: split once along every free axis, the parts
/// searched in parallel; then the smooth clusters of boxes left over are searched deeper,
/// a level at a time (a point beside one proved from a neighbour, or where the enclosures
/// were too loose at the finest size, is often decided there), while the boxes left keep
/// decreasing: a curve or surface of critical points doubles or quadruples them at each
/// level, and is left as it is.
fn search_stratum(
    system: &System,
    start: Box4,
    finest: [f64; 4],
    budget: &AtomicUsize,
) -> search::Outcome {
    let run = |parts: Vec<Box4>, finest: [f64; 4], known: &[search::Proved]| {
        let outcomes = parts
            .into_par_iter()
            .map(|part| search::search(&mut system.clone(), part, finest, budget, known))
            .collect();
        search::merge(outcomes, system)
    };
    let mut outcome = run(split_once(start, &system.stratum.free), finest, &[]);
    let mut kept = Vec::new();
    let leftovers = std::mem::take(&mut outcome.leftovers);
    for cluster in search::clusters(&leftovers) {
        let mut boxes: Vec<search::Leftover> =
            cluster.iter().map(|&i| leftovers[i].clone()).collect();
        let smooth = boxes.iter().all(|l| l.smooth);
        let mut finer = finest;
        for _ in 0..DEEPER_LEVELS {
            if !smooth || boxes.is_empty() || boxes.len() > DEEPER_CLUSTER {
                break;
            }
            finer = finer.map(|f| f / 2.0);
            let spaces = boxes.iter().map(|l| l.space).collect();
            let again = run(spaces, finer, &outcome.proved);
            outcome.visited += again.visited;
            let shrank = again.leftovers.len() < boxes.len();
            boxes = again.leftovers;
            let dim = system.dim();
            for p in again.proved {
                if !outcome.proved.iter().any(|q| search::same(q, &p, dim)) {
                    outcome.proved.push(p);
                }
            }
            if !shrank {
                break;
            }
        }
        kept.extend(boxes);
    }
    outcome.leftovers = kept;
    outcome
}

/// How many levels below the finest a cluster may be searched, and the most boxes it may
/// have to be (a larger one is a surface of critical points, and would take long).
const DEEPER_LEVELS: usize = 4;
const DEEPER_CLUSTER: usize = 2048;

/// The 2^k boxes of `b` halved along each of the k `free` axes.
fn split_once(b: Box4, free: &[usize]) -> Vec<Box4> {
    free.iter().fold(vec![b], |boxes, &axis| {
        boxes
            .into_iter()
            .flat_map(|b| {
                let mid = b[axis].midpoint();
                let (mut low, mut high) = (b, b);
                low[axis] = Interval::new(b[axis].lo(), mid);
                high[axis] = Interval::new(mid, b[axis].hi());
                [low, high]
            })
            .collect()
    })
}
