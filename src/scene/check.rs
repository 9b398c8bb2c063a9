//! The one check of a scene's values, shared by the scene file and the command line: each
//! problem names the key it is about, and each reader says it in its own words (the file
//! points at the key's line, the command line names the flag that set it).

use super::{MAX_CERT_BUDGET, MAX_HITS, MAX_RAYS, MAX_STEPS, MAX_TREE_LEVEL, Scene};

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

/// How a problem is told: by scene-file key, by command-line flag or by share-link key.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Speaker {
    File,
    Flag,
    Link,
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
            Speaker::Link => super::link::link_key(key),
        };
        let key = name(&self.key);
        let sep = match speaker {
            Speaker::File => " = ",
            Speaker::Flag => " ",
            Speaker::Link => "=",
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
                Speaker::Flag => format!("{key}: {message}"),
            },
        }
    }
}

/// The command-line flag that sets the scene key `key` (its last part, dashed).
pub fn flag_of(key: &str) -> String {
    if let Some(name) = key.strip_prefix("params.") {
        return format!("--param {name}");
    }
    let last = key.rsplit('.').next().unwrap_or(key);
    format!("--{}", last.replace('_', "-"))
}

/// The ranges of the counted settings: key, least, most.
const COUNTS: [(&str, u32, u32); 5] = [
    ("render.rays", 1, MAX_RAYS),
    ("render.hits", 1, MAX_HITS),
    ("render.steps", 1, MAX_STEPS),
    ("render.bisection_iters", 1, MAX_STEPS),
    ("render.cert_budget", 1, MAX_CERT_BUDGET),
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
        }
        if self.view.angles.iter().any(|a| !a.is_finite()) {
            return Err(Invalid::other(
                "view.angles",
                "angles must be finite numbers",
            ));
        }
        positive("view.zoom", self.view.zoom)?;
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
        let t = &self.tree;
        for (key, level) in [
            ("tree.max_level", t.max_level),
            ("tree.min_level", t.min_level),
        ] {
            if level > MAX_TREE_LEVEL {
                return Err(Invalid::range(
                    key,
                    level,
                    format!(
                        "the deepest level is {MAX_TREE_LEVEL} (each level multiplies the boxes by up to 16)"
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
        if t.node_budget < 16 {
            return Err(Invalid::range(
                "tree.node_budget",
                t.node_budget,
                "at least 16",
            ));
        }
        let r = &self.render;
        let counts = [r.rays, r.hits, r.steps, r.bisection_iters, r.cert_budget];
        for ((key, lo, hi), value) in COUNTS.into_iter().zip(counts) {
            if !(lo..=hi).contains(&value) {
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

fn unit(key: &str, v: f64) -> Result<(), Invalid> {
    if (0.0..=1.0).contains(&v) {
        Ok(())
    } else {
        Err(Invalid::range(key, v, "between 0 and 1"))
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
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(Invalid::range(key, v, "a number ≥ 0"))
    }
}

/// The span of the line that sets `key` (a dotted path) in scene text, for problems found
/// after parsing: the key within its table (`[render.border]`, then `tolerance`), or the
/// table's header; 0..0 where the text does not set it.
pub fn locate(text: &str, key: &str) -> std::ops::Range<usize> {
    let (table, leaf) = key.rsplit_once('.').unwrap_or(("", key));
    let mut section = String::new();
    let mut header = None;
    let mut offset = 0;
    for line in text.split_inclusive('\n') {
        let trimmed = line.trim_start();
        let start = offset + (line.len() - trimmed.len());
        let span = start..offset + line.trim_end().len();
        offset += line.len();
        if let Some(name) = trimmed.strip_prefix('[') {
            section = name.split(']').next().unwrap_or("").trim().to_string();
            if section == key || (section == table && header.is_none()) {
                header = Some(span.clone());
            }
            continue;
        }
        let sets_leaf = trimmed
            .strip_prefix(leaf)
            .is_some_and(|rest| rest.trim_start().starts_with('='));
        if section == table && sets_leaf {
            return span;
        }
    }
    header.unwrap_or(0..0)
}
