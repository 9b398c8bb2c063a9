//! The keyword arguments that set a scene, named as the command line's flags are (`rays`,
//! `max_level`, `colour_by`, …): one table for `Scene(...)`, `render(...)` and the scene's
//! attributes. Types are checked here (a `TypeError` names the keyword); values by the
//! library's scene rules afterwards (a `ValueError` names the keyword and its range).

use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};

use fourfold::scene::{AxisRange, Color, ColorBy, Domain, Sampling, Scene, Undecided};

use crate::errors::value_error;

/// Every keyword, in the order `help()` lists them.
pub const KEYWORDS: [&str; 29] = [
    "formula",
    "description",
    "params",
    "domain",
    "angles",
    "zoom",
    "pan",
    "slice",
    "slab",
    "size",
    "rays",
    "hits",
    "steps",
    "bisection_iters",
    "approximation",
    "seed",
    "alpha",
    "sampling",
    "background",
    "colour_by",
    "certified",
    "cert_budget",
    "undecided",
    "brute_force",
    "silhouette",
    "border",
    "lighting",
    "max_level",
    "min_level",
];

/// Also taken: `color_by` (as `colour_by`) and `node_budget`.
pub fn is_keyword(name: &str) -> bool {
    KEYWORDS.contains(&name) || name == "color_by" || name == "node_budget"
}

/// A scene and the picture size that goes with it (not part of a scene file).
pub struct Settings<'a> {
    pub scene: &'a mut Scene,
    pub size: &'a mut (u32, u32),
}

fn type_name(value: &Bound<'_, PyAny>) -> String {
    value
        .get_type()
        .name()
        .map_or_else(|_| "?".to_string(), |n| n.to_string())
}

fn expected(keyword: &str, what: &str, value: &Bound<'_, PyAny>) -> PyErr {
    PyTypeError::new_err(format!(
        "{keyword}: expected {what}, got {} {}",
        type_name(value),
        value
            .repr()
            .map_or_else(|_| String::new(), |r| r.to_string())
    ))
}

fn number(keyword: &str, value: &Bound<'_, PyAny>) -> PyResult<f64> {
    if value.is_instance_of::<PyString>() || value.extract::<bool>().is_ok() {
        return Err(expected(keyword, "a number", value));
    }
    value
        .extract::<f64>()
        .map_err(|_| expected(keyword, "a number", value))
}

fn count(keyword: &str, value: &Bound<'_, PyAny>) -> PyResult<u32> {
    if value.extract::<bool>().is_ok() {
        return Err(expected(keyword, "a whole number", value));
    }
    let v: i64 = value
        .extract()
        .map_err(|_| expected(keyword, "a whole number", value))?;
    u32::try_from(v).map_err(|_| value_error(format!("{keyword}={v}: a whole number from 0 up")))
}

fn flag(keyword: &str, value: &Bound<'_, PyAny>) -> PyResult<bool> {
    value
        .extract::<bool>()
        .map_err(|_| expected(keyword, "True or False", value))
}

fn numbers<const N: usize>(keyword: &str, value: &Bound<'_, PyAny>) -> PyResult<[f64; N]> {
    let what = format!("a sequence of {N} numbers");
    if value.is_instance_of::<PyString>() {
        return Err(expected(keyword, &what, value));
    }
    let items: Vec<Bound<'_, PyAny>> = value
        .try_iter()
        .map_err(|_| expected(keyword, &what, value))?
        .collect::<PyResult<_>>()?;
    if items.len() != N {
        return Err(value_error(format!(
            "{keyword}: expected {N} numbers, got {}",
            items.len()
        )));
    }
    let mut out = [0.0; N];
    for (o, item) in out.iter_mut().zip(&items) {
        *o = number(keyword, item)?;
    }
    Ok(out)
}

fn word<T: Copy>(keyword: &str, value: &Bound<'_, PyAny>, choices: &[(&str, T)]) -> PyResult<T> {
    let names: Vec<String> = choices.iter().map(|(n, _)| format!("'{n}'")).collect();
    let names = names.join(" or ");
    let text: String = value
        .extract()
        .map_err(|_| expected(keyword, &names, value))?;
    choices
        .iter()
        .find(|(n, _)| *n == text)
        .map(|&(_, v)| v)
        .ok_or_else(|| value_error(format!("{keyword}='{text}': use {names}")))
}

const SAMPLING: [(&str, Sampling); 2] = [
    ("random", Sampling::Random),
    ("stratified", Sampling::Stratified),
];
const COLOUR_BY: [(&str, ColorBy); 2] =
    [("surface", ColorBy::Surface), ("hidden", ColorBy::Hidden)];
const UNDECIDED: [(&str, Undecided); 2] =
    [("marker", Undecided::Marker), ("hatch", Undecided::Hatch)];

fn name_of<T: PartialEq>(choices: &[(&'static str, T)], value: T) -> &'static str {
    choices
        .iter()
        .find(|(_, v)| *v == value)
        .map_or("?", |(n, _)| n)
}

impl Settings<'_> {
    /// Sets `keyword` to `value` (its type checked; its range is the scene's check's).
    pub fn set(&mut self, keyword: &str, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let scene = &mut *self.scene;
        let (view, render, tree) = (&mut scene.view, &mut scene.render, &mut scene.tree);
        match keyword {
            "formula" | "description" => {
                let text: String = value
                    .extract()
                    .map_err(|_| expected(keyword, "a string", value))?;
                if keyword == "formula" {
                    // A scene's formula parses: its error is said where it is set.
                    fourfold::CompiledFormula::compile(&text)
                        .map_err(|e| crate::errors::formula_error(value.py(), &e, &text))?;
                    scene.formula = text;
                } else {
                    scene.description = text;
                }
            }
            "params" => scene.params = params(value)?,
            "domain" => scene.domain = domain(&numbers::<8>(keyword, value)?)?,
            "angles" => view.angles = numbers::<6>(keyword, value)?,
            "zoom" => view.zoom = number(keyword, value)?,
            "pan" => view.pan = numbers::<2>(keyword, value)?,
            "slice" => {
                view.slice = optional(value, |v| number(keyword, v))?;
                if view.slice.is_some() {
                    view.slab = None;
                }
            }
            "slab" => {
                view.slab = optional(value, |v| numbers::<2>(keyword, v))?;
                if view.slab.is_some() {
                    view.slice = None;
                }
            }
            "size" => *self.size = size(value)?,
            "rays" => render.rays = count(keyword, value)?,
            "hits" => render.hits = count(keyword, value)?,
            "steps" => render.steps = count(keyword, value)?,
            "bisection_iters" => render.bisection_iters = count(keyword, value)?,
            "seed" => render.seed = count(keyword, value)?,
            "cert_budget" => render.cert_budget = count(keyword, value)?,
            "approximation" => render.approximation = number(keyword, value)?,
            "alpha" => render.alpha = number(keyword, value)?,
            "sampling" => render.sampling = word(keyword, value, &SAMPLING)?,
            "colour_by" | "color_by" => render.color_by = word(keyword, value, &COLOUR_BY)?,
            "undecided" => render.undecided = word(keyword, value, &UNDECIDED)?,
            "background" => {
                let text: String = value
                    .extract()
                    .map_err(|_| expected(keyword, "a colour '#rrggbb'", value))?;
                render.background =
                    Color::parse(&text).map_err(|e| value_error(format!("background: {e}")))?;
            }
            "certified" => render.certified = flag(keyword, value)?,
            "brute_force" => render.brute_force = flag(keyword, value)?,
            "silhouette" => render.silhouette.enabled = flag(keyword, value)?,
            "border" => render.border.enabled = flag(keyword, value)?,
            "lighting" => render.lighting.enabled = flag(keyword, value)?,
            "max_level" => tree.set_levels(Some(count(keyword, value)?), None),
            "min_level" => tree.min_level = count(keyword, value)?,
            "node_budget" => tree.node_budget = count(keyword, value)?,
            _ => return Err(unknown(keyword)),
        }
        Ok(())
    }

    /// The value of `keyword`.
    pub fn get<'py>(&self, py: Python<'py>, keyword: &str) -> PyResult<Bound<'py, PyAny>> {
        let scene = &*self.scene;
        let (view, render, tree) = (&scene.view, &scene.render, &scene.tree);
        let d = scene.domain.axes();
        Ok(match keyword {
            "formula" => scene.formula.clone().into_pyobject(py)?.into_any(),
            "description" => scene.description.clone().into_pyobject(py)?.into_any(),
            "params" => scene.params.clone().into_pyobject(py)?.into_any(),
            "domain" => d
                .iter()
                .flat_map(|a| [a.lo, a.hi])
                .collect::<Vec<_>>()
                .into_pyobject(py)?,
            "angles" => view.angles.to_vec().into_pyobject(py)?,
            "zoom" => view.zoom.into_pyobject(py)?.into_any(),
            "pan" => view.pan.to_vec().into_pyobject(py)?,
            "slice" => view.slice.into_pyobject(py)?,
            "slab" => view.slab.map(|s| (s[0], s[1])).into_pyobject(py)?,
            "size" => (*self.size).into_pyobject(py)?.into_any(),
            "rays" => render.rays.into_pyobject(py)?.into_any(),
            "hits" => render.hits.into_pyobject(py)?.into_any(),
            "steps" => render.steps.into_pyobject(py)?.into_any(),
            "bisection_iters" => render.bisection_iters.into_pyobject(py)?.into_any(),
            "seed" => render.seed.into_pyobject(py)?.into_any(),
            "cert_budget" => render.cert_budget.into_pyobject(py)?.into_any(),
            "approximation" => render.approximation.into_pyobject(py)?.into_any(),
            "alpha" => render.alpha.into_pyobject(py)?.into_any(),
            "sampling" => name_of(&SAMPLING, render.sampling)
                .into_pyobject(py)?
                .into_any(),
            "colour_by" | "color_by" => name_of(&COLOUR_BY, render.color_by)
                .into_pyobject(py)?
                .into_any(),
            "undecided" => name_of(&UNDECIDED, render.undecided)
                .into_pyobject(py)?
                .into_any(),
            "background" => render.background.to_hex().into_pyobject(py)?.into_any(),
            "certified" => flag_object(py, render.certified),
            "brute_force" => flag_object(py, render.brute_force),
            "silhouette" => flag_object(py, render.silhouette.enabled),
            "border" => flag_object(py, render.border.enabled),
            "lighting" => flag_object(py, render.lighting.enabled),
            "max_level" => tree.max_level.into_pyobject(py)?.into_any(),
            "min_level" => tree.min_level.into_pyobject(py)?.into_any(),
            "node_budget" => tree.node_budget.into_pyobject(py)?.into_any(),
            _ => return Err(unknown(keyword)),
        })
    }
}

fn flag_object(py: Python<'_>, v: bool) -> Bound<'_, PyAny> {
    pyo3::types::PyBool::new(py, v).to_owned().into_any()
}

/// The error for a keyword no scene has, with the nearest one if it is close.
pub fn unknown(keyword: &str) -> PyErr {
    let nearest = KEYWORDS
        .iter()
        .chain(&["node_budget", "color_by"])
        .map(|k| (strsim::levenshtein(k, keyword), *k))
        .min()
        .filter(|(d, _)| *d <= 3)
        .map(|(_, k)| format!(": did you mean {k}?"))
        .unwrap_or_else(|| format!(" (the settings: {})", KEYWORDS.join(", ")));
    PyTypeError::new_err(format!("unknown setting '{keyword}'{nearest}"))
}

fn optional<T>(
    value: &Bound<'_, PyAny>,
    read: impl FnOnce(&Bound<'_, PyAny>) -> PyResult<T>,
) -> PyResult<Option<T>> {
    if value.is_none() {
        Ok(None)
    } else {
        read(value).map(Some)
    }
}

/// A dict of parameter values, name → number.
pub fn params(value: &Bound<'_, PyAny>) -> PyResult<std::collections::BTreeMap<String, f64>> {
    let dict = value
        .cast::<PyDict>()
        .map_err(|_| expected("params", "a dict of name → number", value))?;
    let mut out = std::collections::BTreeMap::new();
    for (k, v) in dict.iter() {
        let name: String = k
            .extract()
            .map_err(|_| expected("params", "names that are strings", &k))?;
        let v = number(&format!("params['{name}']"), &v)?;
        out.insert(name, v);
    }
    Ok(out)
}

fn domain(v: &[f64; 8]) -> PyResult<Domain> {
    let mut axes = Vec::with_capacity(4);
    for (a, name) in ["x", "y", "z", "w"].iter().enumerate() {
        let range = AxisRange::new(v[2 * a], v[2 * a + 1])
            .map_err(|e| value_error(format!("domain: the {name} range: {e}")))?;
        axes.push(range);
    }
    Ok(Domain::from_axes([axes[0], axes[1], axes[2], axes[3]]))
}

fn size(value: &Bound<'_, PyAny>) -> PyResult<(u32, u32)> {
    let what = "(width, height) in pixels";
    if value.is_instance_of::<PyString>() {
        return Err(expected("size", what, value));
    }
    let items: Vec<Bound<'_, PyAny>> = value
        .try_iter()
        .map_err(|_| expected("size", what, value))?
        .collect::<PyResult<_>>()?;
    let [w, h] = &items[..] else {
        return Err(value_error(format!(
            "size: expected (width, height), got {} values",
            items.len()
        )));
    };
    let side = |v: &Bound<'_, PyAny>| -> PyResult<u32> {
        let n = count("size", v)?;
        let max = fourfold::scene::MAX_PICTURE_SIDE;
        if !(1..=max).contains(&n) {
            return Err(value_error(format!(
                "size=({}, {}): each side must be between 1 and {max}",
                w.repr().map_or_else(|_| "?".into(), |r| r.to_string()),
                h.repr().map_or_else(|_| "?".into(), |r| r.to_string()),
            )));
        }
        Ok(n)
    };
    Ok((side(w)?, side(h)?))
}
