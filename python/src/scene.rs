//! `Scene`: everything a scene file holds (and the picture's size), set by keyword
//! arguments or attributes named as the command line's flags, or by any key of the file by
//! its dotted path (`scene["render.border.tolerance"]`); read from and written to TOML and
//! share links; drawn inline in Jupyter.

use std::path::PathBuf;

use pyo3::exceptions::{PyFileNotFoundError, PyKeyError, PyOSError, PyTypeError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

use fourfold::scene::Scene as CoreScene;
use fourfold::scene::{SceneError, Speaker};

use crate::drawing::{Want, draw, warn_all};
use crate::errors::value_error;
use crate::keywords::{KEYWORDS, Settings, is_keyword, unknown};

/// The picture size a scene draws at unless told otherwise.
pub const DEFAULT_SIZE: (u32, u32) = (512, 512);

/// A scene: the formula, its parameters, the domain, the view and the settings.
#[pyclass(module = "fourfold", subclass)]
#[derive(Clone)]
pub struct Scene {
    pub scene: CoreScene,
    pub size: (u32, u32),
}

impl Scene {
    pub fn of(scene: CoreScene) -> Self {
        Self {
            scene,
            size: DEFAULT_SIZE,
        }
    }

    /// This scene with `settings` applied, each checked (a `TypeError` for a wrong type, a
    /// `ValueError` naming the keyword for a value out of range).
    pub fn with(&self, settings: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let mut out = self.clone();
        let Some(settings) = settings else {
            return Ok(out);
        };
        let mut pairs: Vec<(String, Bound<'_, PyAny>)> = Vec::new();
        for (k, v) in settings.iter() {
            pairs.push((k.extract()?, v));
        }
        // min_level after max_level, whatever the order given, so that a lower max_level
        // alone takes min_level down with it and an explicit min_level wins.
        pairs.sort_by_key(|(k, _)| k == "min_level");
        let mut settings = Settings {
            scene: &mut out.scene,
            size: &mut out.size,
        };
        for (k, v) in &pairs {
            settings.set(k, v)?;
        }
        check(&out.scene)?;
        Ok(out)
    }
}

/// The scene's values checked by the library's rules, a `ValueError` naming the keyword.
pub fn check(scene: &CoreScene) -> PyResult<()> {
    scene
        .check()
        .map_err(|invalid| value_error(invalid.message(Speaker::Keyword)))
}

fn scene_error(e: SceneError) -> PyErr {
    match e {
        SceneError::Io { ref source, .. } if source.kind() == std::io::ErrorKind::NotFound => {
            PyFileNotFoundError::new_err(e.to_string())
        }
        SceneError::Io { .. } => PyOSError::new_err(e.to_string()),
        SceneError::Invalid { .. } => value_error(e.to_string()),
    }
}

#[pymethods]
impl Scene {
    #[new]
    #[pyo3(signature = (formula, **settings))]
    fn new(formula: &Bound<'_, PyAny>, settings: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let text: String = formula
            .str()
            .and_then(|s| s.extract())
            .map_err(|_| PyTypeError::new_err("Scene(formula): the formula must be a string"))?;
        if !formula.is_instance_of::<PyString>()
            && !formula.is_instance_of::<crate::formula::Formula>()
        {
            return Err(PyTypeError::new_err(format!(
                "Scene(formula): expected a formula string or a Formula, got {}",
                formula.get_type().name()?
            )));
        }
        crate::formula::Formula::compile(formula.py(), &text)?;
        Self::of(CoreScene::from_formula(&text)).with(settings)
    }

    /// Reads a scene file (TOML); a problem is a `ValueError` with a caret at its line.
    #[staticmethod]
    fn load(path: PathBuf) -> PyResult<Self> {
        CoreScene::load(&path).map(Self::of).map_err(scene_error)
    }

    /// A scene from the text of a scene file.
    #[staticmethod]
    #[pyo3(signature = (text, name = "<string>"))]
    fn from_toml(text: &str, name: &str) -> PyResult<Self> {
        CoreScene::parse(text, name)
            .map(Self::of)
            .map_err(scene_error)
    }

    /// A scene from a share link (a whole address, or what follows '#'). A wrong key is
    /// a `ValueError` listing every problem, a mistyped formula a `FormulaError`; with
    /// `strict=False` such keys are left at their defaults, as the page does, and each is a
    /// warning (the formula's error then comes with the first picture).
    #[staticmethod]
    #[pyo3(signature = (link, strict = true))]
    fn from_link(py: Python<'_>, link: &str, strict: bool) -> PyResult<Self> {
        let fallback = CoreScene::from_formula("x^2 + y^2 + z^2 + w^2 = 1");
        let (scene, problems) = CoreScene::from_link(link, &fallback);
        if !problems.is_empty() {
            let lines: Vec<String> = problems.iter().map(|p| p.to_string()).collect();
            if strict {
                return Err(value_error(format!(
                    "the link has {} problem{}:\n{}",
                    lines.len(),
                    if lines.len() == 1 { "" } else { "s" },
                    lines.join("\n")
                )));
            }
            warn_all(py, &lines)?;
        }
        if strict {
            // A mistyped formula is said now, as a `FormulaError`, not at the first picture.
            crate::formula::Formula::compile(py, &scene.formula)?;
        }
        Ok(Self::of(scene))
    }

    /// One of the example scenes (`fourfold.examples()` lists them), as the gallery has it.
    #[staticmethod]
    fn example(name: &str) -> PyResult<Self> {
        CoreScene::example(name).map(Self::of).ok_or_else(|| {
            let names: Vec<&str> = fourfold::scene::EXAMPLES.iter().map(|(n, _)| *n).collect();
            value_error(format!(
                "no example scene '{name}': the examples are {}",
                names.join(", ")
            ))
        })
    }

    /// The scene file's text.
    fn to_toml(&self) -> String {
        self.scene.to_toml()
    }

    /// Writes the scene file.
    fn save(&self, path: PathBuf) -> PyResult<()> {
        std::fs::write(&path, self.scene.to_toml())
            .map_err(|e| PyOSError::new_err(format!("cannot write {}: {e}", path.display())))
    }

    /// The share link's fragment (`#formula=…&angles=…`); `base` goes before it (the
    /// page's address, say).
    #[pyo3(signature = (base = ""))]
    fn link(&self, base: &str) -> String {
        format!("{base}#{}", self.scene.to_link())
    }

    /// A copy with `settings` changed.
    #[pyo3(signature = (**settings))]
    fn replace(&self, settings: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        self.with(settings)
    }

    fn copy(&self) -> Self {
        self.clone()
    }

    fn __copy__(&self) -> Self {
        self.clone()
    }

    fn __deepcopy__(&self, _memo: &Bound<'_, PyAny>) -> Self {
        self.clone()
    }

    fn __getattr__<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
        if !is_keyword(name) {
            return Err(pyo3::exceptions::PyAttributeError::new_err(format!(
                "'Scene' object has no attribute '{name}'"
            )));
        }
        let (mut scene, mut size) = (self.scene.clone(), self.size);
        Settings {
            scene: &mut scene,
            size: &mut size,
        }
        .get(py, name)
    }

    fn __setattr__(&mut self, name: &str, value: Bound<'_, PyAny>) -> PyResult<()> {
        if !is_keyword(name) {
            return Err(unknown(name));
        }
        let (mut scene, mut size) = (self.scene.clone(), self.size);
        Settings {
            scene: &mut scene,
            size: &mut size,
        }
        .set(name, &value)?;
        check(&scene)?;
        (self.scene, self.size) = (scene, size);
        Ok(())
    }

    fn __dir__(&self) -> Vec<&'static str> {
        let mut names: Vec<&'static str> = KEYWORDS.to_vec();
        names.extend([
            "node_budget",
            "load",
            "from_toml",
            "from_link",
            "example",
            "to_toml",
            "save",
            "link",
            "replace",
            "copy",
        ]);
        names
    }

    /// Any key of the scene file by its dotted path, as `scene["render.border.tolerance"]`.
    fn __getitem__<'py>(&self, py: Python<'py>, path: &str) -> PyResult<Bound<'py, PyAny>> {
        let table = toml::Value::try_from(&self.scene)
            .map_err(|e| value_error(format!("internal error: {e}")))?;
        let mut at = &table;
        for part in path.split('.') {
            at = at
                .get(part)
                .ok_or_else(|| PyKeyError::new_err(format!("the scene has no key '{path}'")))?;
        }
        to_python(py, at)
    }

    fn __setitem__(&mut self, path: &str, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let mut table = toml::Value::try_from(&self.scene)
            .map_err(|e| value_error(format!("internal error: {e}")))?;
        let parts: Vec<&str> = path.split('.').collect();
        let (last, tables) = parts.split_last().expect("split gives one part at least");
        let mut at = &mut table;
        for part in tables {
            at = at.get_mut(*part).filter(|v| v.is_table()).ok_or_else(|| {
                PyKeyError::new_err(format!("the scene has no table '{part}' (in '{path}')"))
            })?;
        }
        let map = at.as_table_mut().expect("filtered to tables");
        if value.is_none() {
            map.remove(*last);
        } else {
            map.insert(last.to_string(), from_python(path, value)?);
        }
        let scene: CoreScene = table
            .try_into()
            .map_err(|e: toml::de::Error| value_error(format!("{path}: {}", e.message())))?;
        scene
            .check()
            .map_err(|invalid| value_error(invalid.message(Speaker::Link)))?;
        self.scene = scene;
        Ok(())
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other.cast::<Scene>().is_ok_and(|o| {
            let o = o.borrow();
            o.scene == self.scene && o.size == self.size
        })
    }

    fn __repr__(&self) -> String {
        let s = &self.scene;
        let mut parts = vec![format!("{:?}", s.formula)];
        if !s.params.is_empty() {
            let params: Vec<String> = s
                .params
                .iter()
                .map(|(k, v)| format!("{k:?}: {v}"))
                .collect();
            parts.push(format!("params={{{}}}", params.join(", ")));
        }
        if s.view.angles != [0.0; 6] {
            parts.push(format!("angles={:?}", s.view.angles));
        }
        if let Some(c) = s.view.slice {
            parts.push(format!("slice={c}"));
        }
        if let Some([c, h]) = s.view.slab {
            parts.push(format!("slab=({c}, {h})"));
        }
        if !s.render.certified {
            parts.push("certified=False".into());
        }
        if self.size != DEFAULT_SIZE {
            parts.push(format!("size={:?}", self.size));
        }
        format!("Scene({})", parts.join(", "))
    }

    /// The scene drawn at its size, for Jupyter (on the CPU where no GPU opens).
    fn _repr_png_(&self, py: Python<'_>) -> PyResult<Vec<u8>> {
        let drawn = draw(py, &self.scene, self.size, false, Want::Any)?;
        drawn.picture.to_png().map_err(crate::errors::render_error)
    }
}

/// The example scenes: (name, description) pairs, in the gallery's order.
#[pyfunction]
pub fn examples() -> Vec<(String, String)> {
    fourfold::scene::EXAMPLES
        .iter()
        .filter_map(|(name, _)| CoreScene::example(name).map(|s| (name.to_string(), s.description)))
        .collect()
}

/// Whether `text` is a share link rather than a formula.
#[pyfunction]
pub fn is_link(text: &str) -> bool {
    fourfold::scene::link::is_link(text)
}

fn to_python<'py>(py: Python<'py>, value: &toml::Value) -> PyResult<Bound<'py, PyAny>> {
    use toml::Value as V;
    Ok(match value {
        V::String(s) => PyString::new(py, s).into_any(),
        V::Integer(i) => i.into_pyobject(py)?.into_any(),
        V::Float(f) => PyFloat::new(py, *f).into_any(),
        V::Boolean(b) => PyBool::new(py, *b).to_owned().into_any(),
        V::Datetime(d) => PyString::new(py, &d.to_string()).into_any(),
        V::Array(items) => {
            let items: Vec<Bound<'py, PyAny>> = items
                .iter()
                .map(|v| to_python(py, v))
                .collect::<PyResult<_>>()?;
            PyList::new(py, items)?.into_any()
        }
        V::Table(t) => {
            let dict = PyDict::new(py);
            for (k, v) in t {
                dict.set_item(k, to_python(py, v)?)?;
            }
            dict.into_any()
        }
    })
}

fn from_python(path: &str, value: &Bound<'_, PyAny>) -> PyResult<toml::Value> {
    use toml::Value as V;
    if let Ok(b) = value.cast::<PyBool>() {
        return Ok(V::Boolean(b.is_true()));
    }
    if value.is_instance_of::<PyInt>() {
        return Ok(V::Integer(value.extract()?));
    }
    if let Ok(s) = value.cast::<PyString>() {
        return Ok(V::String(s.to_str()?.to_string()));
    }
    if let Ok(f) = value.extract::<f64>() {
        return Ok(V::Float(f));
    }
    if let Ok(d) = value.cast::<PyDict>() {
        let mut table = toml::Table::new();
        for (k, v) in d.iter() {
            table.insert(k.extract()?, from_python(path, &v)?);
        }
        return Ok(V::Table(table));
    }
    if value.is_instance_of::<PyList>() || value.is_instance_of::<PyTuple>() {
        let items = value
            .try_iter()?
            .map(|v| from_python(path, &v?))
            .collect::<PyResult<_>>()?;
        return Ok(V::Array(items));
    }
    Err(PyTypeError::new_err(format!(
        "{path}: a scene value is a number, a string, True/False, a list or a dict, not {}",
        value.get_type().name()?
    )))
}
