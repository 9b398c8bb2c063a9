//! The one check of a scene's values, shared by the scene file and the command line: each
//! problem names the key it is about, and each reader says it in its own words (the file
//! points at the key's line, the command line names the flag that set it).

use super::keys::{Speaker, flag_of, keyword_of, link_key};
use super::limits::{
    CERT_BUDGET, DOMAIN_BOUND, HITS, NODE_BUDGET, PARAM_BOUND, RAYS, STEPS, TOLERANCE, TREE_LEVELS,
    UNIT, ZOOM,
};
use super::settings::Scene;

/// A scene value that is not allowed.
#[derive(Debug, Clone, PartialEq)]
pub struct Invalid {
    /// The key's path in the scene file, as `render.rays` or `params.R`.
    pub key: String,
    pub problem: Problem,
}

/// What is wrong with the value of [`Invalid::key`].
#[derive(Debug, Clone, PartialEq)]
pub enum Problem {
    /// The value is out of its range; `allowed` says what it takes ("between 1 and 1024").
    Range { value: String, allowed: String },
    /// A level above another key's level that it may not exceed.
    Above {
        value: u32,
        limit_key: &'static str,
        limit: u32,
    },
    /// Anything else, said whole.
    Other(String),
}

impl Invalid {
    fn range(key: &str, value: impl ToString, allowed: impl Into<String>) -> Self {
        Self {
            key: key.to_string(),
            problem: Problem::Range {
                value: value.to_string(),
                allowed: allowed.into(),
            },
        }
    }

    fn other(key: &str, message: impl Into<String>) -> Self {
        Self {
            key: key.to_string(),
            problem: Problem::Other(message.into()),
        }
    }

    /// The message, naming keys as the scene file writes them or as the flags that set them.
    pub fn message(&self, speaker: Speaker) -> String {
        let name = |key: &str| match speaker {
            Speaker::File => key.rsplit('.').next().unwrap_or(key).to_string(),
            Speaker::Flag => flag_of(key),
            Speaker::Link => link_key(key),
            Speaker::Keyword => keyword_of(key),
        };
        let key = name(&self.key);
        let sep = match speaker {
            Speaker::File => " = ",
            Speaker::Flag => " ",
            Speaker::Link | Speaker::Keyword => "=",
        };
        match &self.problem {
            Problem::Range { value, allowed } => format!("{key}{sep}{value}: {allowed}"),
            Problem::Above {
                value,
                limit_key,
                limit,
            } => format!(
                "{key} {value} is above {} {limit}: lower the first or raise the second",
                name(limit_key)
            ),
            Problem::Other(message) => match speaker {
                Speaker::File | Speaker::Link => message.clone(),
                Speaker::Flag | Speaker::Keyword => format!("{key}: {message}"),
            },
        }
    }
}

/// The ranges of the counted settings.
const COUNTS: [(&str, std::ops::RangeInclusive<u32>); 5] = [
    ("render.rays", RAYS),
    ("render.hits", HITS),
    ("render.steps", STEPS),
    ("render.bisection_iters", STEPS),
    ("render.cert_budget", CERT_BUDGET),
];

impl Scene {
    /// Every check of the scene's values, in the order of the file's keys; the first
    /// problem found.
    pub fn check(&self) -> Result<(), Invalid> {
        for (name, value) in &self.params {
            if !value.is_finite() {
                return Err(Invalid::other(
                    &format!("params.{name}"),
                    format!("parameter {name} must be a finite number"),
                ));
            }
            if value.abs() > PARAM_BOUND {
                return Err(Invalid::other(
                    &format!("params.{name}"),
                    format!(
                        "parameter {name} = {value:e} is beyond ±{PARAM_BOUND:.1e}, the largest \
                         number F is computed with (32-bit floats, as on the GPU): rescale the \
                         formula so that it needs a smaller value"
                    ),
                ));
            }
        }
        for (axis, name) in self.domain.axes().iter().zip(["x", "y", "z", "w"]) {
            if axis.lo.abs().max(axis.hi.abs()) > DOMAIN_BOUND {
                return Err(Invalid::range(
                    &format!("domain.{name}"),
                    format!("[{}, {}]", axis.lo, axis.hi),
                    format!("bounds within ±{DOMAIN_BOUND:e} (the GPU draws in 32-bit floats)"),
                ));
            }
        }
        self.check_view()?;
        self.check_tree()?;
        self.check_render()
    }

    fn check_view(&self) -> Result<(), Invalid> {
        if self.view.angles.iter().any(|a| !a.is_finite()) {
            return Err(Invalid::other(
                "view.angles",
                "angles must be finite numbers",
            ));
        }
        positive("view.zoom", self.view.zoom)?;
        within("view.zoom", self.view.zoom, &ZOOM)?;
        if self.view.pan.iter().any(|p| !p.is_finite()) {
            return Err(Invalid::other("view.pan", "pan must be two finite numbers"));
        }
        if let Some(c) = self.view.slice {
            if !c.is_finite() {
                return Err(Invalid::range("view.slice", c, "a finite number"));
            }
            if self.view.slab.is_some() {
                return Err(Invalid::other(
                    "view.slice",
                    "a view is a slice or a slab, not both: remove one of slice and slab",
                ));
            }
        }
        if let Some([c, h]) = self.view.slab
            && !(c.is_finite() && h.is_finite() && h >= 0.0)
        {
            return Err(Invalid::range(
                "view.slab",
                format!("[{c}, {h}]"),
                "[c, h]: a finite middle c and a half width h ≥ 0",
            ));
        }
        Ok(())
    }

    fn check_tree(&self) -> Result<(), Invalid> {
        let t = &self.tree;
        let deepest = *TREE_LEVELS.end();
        for (key, level) in [
            ("tree.max_level", t.max_level),
            ("tree.min_level", t.min_level),
        ] {
            if !TREE_LEVELS.contains(&level) {
                return Err(Invalid::range(
                    key,
                    level,
                    format!(
                        "the deepest level is {deepest} (each level multiplies the boxes by up to 16)"
                    ),
                ));
            }
        }
        if t.min_level > t.max_level {
            return Err(Invalid {
                key: "tree.min_level".into(),
                problem: Problem::Above {
                    value: t.min_level,
                    limit_key: "tree.max_level",
                    limit: t.max_level,
                },
            });
        }
        if t.node_budget < *NODE_BUDGET.start() {
            return Err(Invalid::range(
                "tree.node_budget",
                t.node_budget,
                format!("at least {}", NODE_BUDGET.start()),
            ));
        }
        if t.node_budget > *NODE_BUDGET.end() {
            return Err(Invalid::range(
                "tree.node_budget",
                t.node_budget,
                format!(
                    "at most {} (more nodes than a machine's memory holds)",
                    NODE_BUDGET.end()
                ),
            ));
        }
        Ok(())
    }

    fn check_render(&self) -> Result<(), Invalid> {
        let r = &self.render;
        let counts = [r.rays, r.hits, r.steps, r.bisection_iters, r.cert_budget];
        for ((key, range), value) in COUNTS.into_iter().zip(counts) {
            if !range.contains(&value) {
                let (lo, hi) = range.into_inner();
                return Err(Invalid::range(key, value, format!("between {lo} and {hi}")));
            }
        }
        unit("render.alpha", r.alpha)?;
        if !(r.approximation.is_finite() && r.approximation >= 0.0) {
            return Err(Invalid::range(
                "render.approximation",
                r.approximation,
                "a number ≥ 0 (0: never stop early)",
            ));
        }
        let l = &r.lighting;
        if l.direction.iter().all(|c| *c == 0.0) || l.direction.iter().any(|c| !c.is_finite()) {
            return Err(Invalid::other(
                "render.lighting.direction",
                "the light direction must be finite and not all zero",
            ));
        }
        unit("render.lighting.ambient", l.ambient)?;
        unit("render.lighting.diffuse", l.diffuse)?;
        unit("render.lighting.specular", l.specular)?;
        positive("render.lighting.shininess", l.shininess)?;
        non_negative("render.silhouette.tolerance", r.silhouette.tolerance)?;
        non_negative("render.border.tolerance", r.border.tolerance)?;
        Ok(())
    }
}

/// A positive `v` within `range` (zoom: its lower end is above 0).
fn within(key: &str, v: f64, range: &std::ops::RangeInclusive<f64>) -> Result<(), Invalid> {
    if range.contains(&v) {
        Ok(())
    } else {
        Err(Invalid::range(
            key,
            v,
            format!("between {} and {}", range.start(), range.end()),
        ))
    }
}

fn unit(key: &str, v: f64) -> Result<(), Invalid> {
    if UNIT.contains(&v) {
        Ok(())
    } else {
        Err(Invalid::range(
            key,
            v,
            format!("between {} and {}", UNIT.start(), UNIT.end()),
        ))
    }
}

fn positive(key: &str, v: f64) -> Result<(), Invalid> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(Invalid::range(key, v, "a positive number"))
    }
}

fn non_negative(key: &str, v: f64) -> Result<(), Invalid> {
    if TOLERANCE.contains(&v) {
        Ok(())
    } else {
        Err(Invalid::range(key, v, "a number ≥ 0"))
    }
}
