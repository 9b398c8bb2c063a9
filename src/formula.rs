//! A compiled formula: the text, its graph, F and its four partials, and its parameters.
//! This is what every later stage (evaluators, tree, code generation) takes.

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

/// Stack for parsing and lowering: formulas up to the size limit can nest thousands deep.
#[cfg(not(target_arch = "wasm32"))]
const FRONT_END_STACK: usize = 256 * 1024 * 1024;

/// Parses and lowers `source`. The syntax tree is recursive; its construction, lowering and
/// drop run on a thread with a large stack (reserved, not committed) so no accepted input
/// can overflow. A web page has no threads: there it runs in place, and accepts shorter
/// formulas (`MAX_FORMULA_BYTES`).
fn front_end(source: &str) -> Result<(ExprGraph, NodeId, expr::lower::ParamSpans), SourceError> {
    let text = source.to_string();
    let work = move || {
        let ast = syntax::parse(&text)?;
        let mut graph = ExprGraph::new();
        let (root, spans) = expr::lower::lower(&ast, &mut graph)?;
        Ok::<_, SourceError>((graph, root, spans))
    };
    #[cfg(target_arch = "wasm32")]
    return work();
    #[cfg(not(target_arch = "wasm32"))]
    match std::thread::Builder::new()
        .name("fourfold-parse".into())
        .stack_size(FRONT_END_STACK)
        .spawn(work)
    {
        Ok(handle) => handle.join().unwrap_or_else(|_| {
            Err(SourceError::new(
                "internal error while parsing",
                0..source.len(),
                "here",
            ))
        }),
        Err(e) => Err(SourceError::new(
            format!("could not start the parser thread: {e}"),
            0..0,
            "here",
        )),
    }
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
            tape_all,
            tape_second,
        })
    }

    pub fn param_names(&self) -> Vec<&str> {
        self.params.iter().map(|p| p.name.as_str()).collect()
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
