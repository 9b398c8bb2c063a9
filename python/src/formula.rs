//! `Formula`: a parsed formula, its derivatives as text, and F, ∇F and F's rigorous
//! enclosure evaluated from numpy (points in parallel with the GIL released).

use std::sync::Arc;

use numpy::{PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;

use fourfold::eval::{Interval, IntervalEvaluator, PointEvaluator, Tape};
use fourfold::formula::CompiledFormula;

use crate::errors::{formula_error, value_error};

/// Points evaluated on one thread between two splits of the work.
const CHUNK: usize = 4096;

/// A formula F(x, y, z, w) = 0, parsed, lowered and differentiated.
#[pyclass(module = "fourfold", subclass, frozen)]
pub struct Formula {
    pub compiled: Arc<CompiledFormula>,
}

impl Formula {
    pub fn compile(py: Python<'_>, text: &str) -> PyResult<Arc<CompiledFormula>> {
        CompiledFormula::compile(text)
            .map(Arc::new)
            .map_err(|e| formula_error(py, &e, text))
    }

    /// The parameter values in the formula's order from `params` (a dict of name → number;
    /// names the formula lacks are refused); 1.0 for those left out, named in the second
    /// list.
    fn values(&self, params: Option<&Bound<'_, PyDict>>) -> PyResult<(Vec<f64>, Vec<String>)> {
        let given = match params {
            Some(params) => crate::keywords::params(params.as_any())?,
            None => Default::default(),
        };
        let (missing, unused) = self.compiled.param_mismatch(&given);
        if let Some(name) = unused.first() {
            let problem = self.compiled.check_param(name).unwrap_err();
            return Err(value_error(format!("params['{name}']: {problem}")));
        }
        let values = self
            .compiled
            .params
            .iter()
            .map(|p| given.get(&p.name).copied().unwrap_or(1.0))
            .collect();
        Ok((values, missing))
    }

    fn evaluate(
        &self,
        py: Python<'_>,
        tape: &Tape,
        outputs: usize,
        points: PyReadonlyArray2<'_, f64>,
        params: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<(Vec<f64>, Vec<String>)> {
        if points.shape()[1] != 4 {
            return Err(value_error(format!(
                "points: expected an array of shape (n, 4), got {:?}",
                points.shape()
            )));
        }
        let (values, missing) = self.values(params)?;
        let points = points.as_array().to_owned();
        let n = points.shape()[0];
        let mut out = vec![f64::NAN; n * outputs];
        py.detach(|| {
            out.par_chunks_mut(CHUNK * outputs)
                .enumerate()
                .for_each(|(c, chunk)| {
                    let mut eval = PointEvaluator::new();
                    for (k, o) in chunk.chunks_mut(outputs).enumerate() {
                        let row = points.row(c * CHUNK + k);
                        eval.eval_into(tape, [row[0], row[1], row[2], row[3]], &values, o);
                    }
                })
        });
        Ok((out, missing))
    }
}

#[pymethods]
impl Formula {
    #[new]
    fn new(py: Python<'_>, text: &str) -> PyResult<Self> {
        Ok(Self {
            compiled: Self::compile(py, text)?,
        })
    }

    /// The formula as written.
    #[getter]
    fn text(&self) -> &str {
        &self.compiled.source
    }

    /// F = left side − right side, in readable infix.
    #[getter]
    fn f(&self) -> String {
        self.compiled.f_text()
    }

    /// The parameters' names, in order of first appearance.
    #[getter]
    fn parameters(&self) -> Vec<String> {
        self.compiled
            .params
            .iter()
            .map(|p| p.name.clone())
            .collect()
    }

    /// ∂F/∂x, ∂F/∂y, ∂F/∂z, ∂F/∂w as text (each parses as a formula again).
    fn gradient(&self) -> (String, String, String, String) {
        let [x, y, z, w] = self.compiled.gradient_text();
        (x, y, z, w)
    }

    /// ∂F/∂`variable` as text; `variable` is one of "x", "y", "z", "w".
    fn derivative(&self, variable: &str) -> PyResult<String> {
        let axis = ["x", "y", "z", "w"]
            .iter()
            .position(|v| *v == variable)
            .ok_or_else(|| {
                value_error(format!(
                    "derivative('{variable}'): the variables are x, y, z and w"
                ))
            })?;
        Ok(self.compiled.gradient_text()[axis].clone())
    }

    /// F at each row (x, y, z, w) of `points`, NaN where F is undefined; and the
    /// parameters left at 1.0 because `params` did not give them.
    #[pyo3(signature = (points, params=None))]
    fn _values<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<'_, f64>,
        params: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<(Bound<'py, PyArray1<f64>>, Vec<String>)> {
        let (out, missing) = self.evaluate(py, &self.compiled.tape_f, 1, points, params)?;
        Ok((PyArray1::from_vec(py, out), missing))
    }

    /// ∇F at each row of `points`, as an (n, 4) array.
    #[pyo3(signature = (points, params=None))]
    fn _gradients<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<'_, f64>,
        params: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<(Bound<'py, PyArray2<f64>>, Vec<String>)> {
        let n = points.shape()[0];
        let (out, missing) = self.evaluate(py, &self.compiled.tape_grad, 4, points, params)?;
        let array = PyArray1::from_vec(py, out).reshape([n, 4])?;
        Ok((array, missing))
    }

    /// A rigorous enclosure (lo, hi) of F over the box `bounds` = [x0, x1, y0, y1, z0, z1,
    /// w0, w1], whether F is defined and continuous on the whole box, and the parameters
    /// left at 1.0. An empty enclosure (F undefined on the whole box) is (nan, nan).
    #[pyo3(signature = (bounds, params=None))]
    fn _interval(
        &self,
        bounds: [f64; 8],
        params: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<((f64, f64), bool, Vec<String>)> {
        let mut bx = [Interval::EMPTY; 4];
        for (a, name) in ["x", "y", "z", "w"].iter().enumerate() {
            let (lo, hi) = (bounds[2 * a], bounds[2 * a + 1]);
            if !(lo <= hi) || !lo.is_finite() || !hi.is_finite() {
                return Err(value_error(format!(
                    "box: the {name} range [{lo}, {hi}] must be two finite numbers, low first"
                )));
            }
            bx[a] = Interval::new(lo, hi);
        }
        let (values, missing) = self.values(params)?;
        let mut eval = IntervalEvaluator::new();
        let tape = &self.compiled.tape_f;
        let f = eval.eval(tape, &bx, &values);
        let continuous = eval.continuous_on_last_box(tape);
        let bounds = if f.is_empty() {
            (f64::NAN, f64::NAN)
        } else {
            (f.lo(), f.hi())
        };
        Ok((bounds, continuous, missing))
    }

    fn __repr__(&self) -> String {
        format!("Formula({:?})", self.compiled.source)
    }

    fn __str__(&self) -> String {
        self.compiled.source.clone()
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other
            .cast::<Formula>()
            .is_ok_and(|o| o.get().compiled.source == self.compiled.source)
    }

    fn __hash__(&self) -> u64 {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        self.compiled.source.hash(&mut h);
        h.finish()
    }
}
