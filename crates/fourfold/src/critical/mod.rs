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
mod steps;
pub mod sweep;
mod system;

use serde::Serialize;
use web_time::Duration;

use crate::eval::Box4;
use crate::formula::CompiledFormula;
use crate::interval::Interval;
use crate::scene::Scene;
use crate::scene::limits::{CRITICAL_BOX_BUDGET, DEFAULT_CRITICAL_LEVEL};

pub use steps::CriticalSteps;

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

    /// The points as JSON (what `fourfold critical --json` prints and the Python package
    /// reads): each value's enclosure `[lo, hi]`, point, index (or null), status, place,
    /// boxes and meaning.
    pub fn to_json(&self) -> serde_json::Value {
        self.points
            .iter()
            .map(|p| {
                serde_json::json!({
                    "value": [p.value.lo(), p.value.hi()],
                    "point": p.point(),
                    "index": p.index,
                    "status": p.status,
                    "place": p.place,
                    "boxes": p.boxes,
                    "meaning": p.meaning(),
                })
            })
            .collect()
    }
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CriticalError {
    #[error("the search's level must be within {lo}..={hi}, not {level}")]
    Level { level: u32, lo: u32, hi: u32 },
}

/// The critical values of the slice sweep for `formula` in `scene`'s view and domain,
/// searched to the end at once (on every thread).
pub fn critical_values(
    formula: &CompiledFormula,
    scene: &Scene,
    settings: &CriticalSettings,
) -> Result<CriticalReport, CriticalError> {
    let mut steps = CriticalSteps::new(formula, scene, settings)?;
    loop {
        if let Some(report) = steps.step(Duration::MAX) {
            return Ok(report);
        }
    }
}
