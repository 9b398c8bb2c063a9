//! A compiled formula: the text, its graph, F and its four partials, and its parameters.
//! This is what every later stage (evaluators, tree, code generation) takes.

use std::collections::BTreeMap;

use crate::eval::Tape;
use crate::expr::{self, ExprGraph, NodeId};
use crate::syntax::{self, SourceError, Span};

/// A parameter of the formula: any name that is not a variable, constant or function.
#[derive(Debug, Clone, PartialEq)]
pub struct Parameter {
    pub name: String,
    /// Where it first appears in the formula.
    pub span: Span,
}

/// A formula ready for evaluation: F = lhs − rhs and ∇F, sharing one graph.
#[derive(Debug, Clone)]
pub struct CompiledFormula {
    pub source: String,
    pub graph: ExprGraph,
    pub f: NodeId,
    pub gradient: [NodeId; 4],
    pub params: Vec<Parameter>,
    /// Straight-line program for F alone.
    pub tape_f: Tape,
    /// Straight-line program for ∇F alone (the shader's `ff_grad`).
    pub tape_grad: Tape,
    /// Straight-line program for F and ∇F (outputs in that order).
    pub tape_all: Tape,
    /// Straight-line program for F, ∇F and the second derivatives ∂²F/∂x_i∂x_j, i ≤ j, in
    /// the order of [`HESSIAN_PAIRS`] (outputs in that order): their bounds over a box let
    /// the ray caster step further where F bends little (see `Hierarchy::curvature`).
    pub tape_second: Tape,
}

/// The (i, j) of the second derivatives in [`CompiledFormula::tape_second`], diagonal first:
/// xx, yy, zz, ww, then xy, xz, xw, yz, yw, zw.
pub const HESSIAN_PAIRS: [(u8, u8); 10] = [
    (0, 0),
    (1, 1),
    (2, 2),
    (3, 3),
    (0, 1),
    (0, 2),
    (0, 3),
    (1, 2),
    (1, 3),
    (2, 3),
];

/// Parses and lowers `source`. The syntax tree is recursive; its construction, lowering and
/// drop run with a large stack (`platform::with_large_stack`) so that no accepted input can
/// overflow it.
fn front_end(source: &str) -> Result<(ExprGraph, NodeId, expr::lower::ParamSpans), SourceError> {
    let text = source.to_string();
    let work = move || {
        let ast = syntax::parse(&text)?;
        let mut graph = ExprGraph::new();
        let (root, spans) = expr::lower::lower(&ast, &mut graph)?;
        Ok::<_, SourceError>((graph, root, spans))
    };
    crate::platform::with_large_stack(work)
        .unwrap_or_else(|e| Err(SourceError::new(e, 0..source.len(), "here")))
}

impl CompiledFormula {
    /// Parses, lowers and differentiates `source`. Errors carry a span into `source`.
    pub fn compile(source: &str) -> Result<Self, SourceError> {
        let (mut graph, f, spans) = front_end(source)?;
        let gradient = [0u8, 1, 2, 3].map(|axis| expr::derivative(&mut graph, f, axis));
        let params = graph
            .params()
            .iter()
            .zip(spans.0)
            .map(|(name, span)| Parameter {
                name: name.clone(),
                span,
            })
            .collect();
        let tape_f = Tape::new(&graph, &[f]);
        let tape_grad = Tape::new(&graph, &gradient);
        let mut outputs = vec![f];
        outputs.extend(gradient);
        let tape_all = Tape::new(&graph, &outputs);
        for (i, j) in HESSIAN_PAIRS {
            let second = expr::derivative(&mut graph, gradient[usize::from(i)], j);
            outputs.push(second);
        }
        let tape_second = Tape::new(&graph, &outputs);
        Ok(Self {
            source: source.to_string(),
            graph,
            f,
            gradient,
            params,
            tape_f,
            tape_grad,
            tape_all,
            tape_second,
        })
    }

    pub fn param_names(&self) -> Vec<&str> {
        self.params.iter().map(|p| p.name.as_str()).collect()
    }

    /// What parameter `values` (a scene's, by name) leave out of this formula (those
    /// parameters are 1.0), and what they set that it does not use: for the front ends'
    /// warnings.
    pub fn param_mismatch(&self, values: &BTreeMap<String, f64>) -> (Vec<String>, Vec<String>) {
        let missing = self
            .params
            .iter()
            .filter(|p| !values.contains_key(&p.name))
            .map(|p| p.name.clone())
            .collect();
        let unused = values
            .keys()
            .filter(|name| self.check_param(name).is_err())
            .cloned()
            .collect();
        (missing, unused)
    }

    /// Whether the formula has the parameter `name`; else what its parameters are, in words.
    pub fn check_param(&self, name: &str) -> Result<(), String> {
        if self.params.iter().any(|p| p.name == name) {
            return Ok(());
        }
        let names = self.param_names();
        Err(format!(
            "the formula has no parameter {name} (its parameters: {})",
            if names.is_empty() {
                "none".to_string()
            } else {
                names.join(", ")
            }
        ))
    }

    /// F in readable infix.
    pub fn f_text(&self) -> String {
        expr::to_infix(&self.graph, self.f)
    }

    /// ∂F/∂x, ∂F/∂y, ∂F/∂z, ∂F/∂w in readable infix.
    pub fn gradient_text(&self) -> [String; 4] {
        self.gradient.map(|g| expr::to_infix(&self.graph, g))
    }
}
