//! Syntax tree → expression graph: resolves names (variables, constants, functions,
//! parameters) and reports the ones it cannot make sense of, with a suggestion.

use crate::ops::{CONSTANTS, Function, function, function_names};
use crate::syntax::{BinOp, Expr, ExprKind, Formula, SourceError, Span};

use super::graph::{BinaryOp, ExprGraph, NodeId, UnaryOp, VARIABLES};

/// The closest function name to a mistyped one, if it is close enough to be a likely typo.
fn suggest_function(name: &str) -> Option<&'static str> {
    let lower = name.to_ascii_lowercase();
    if function(&lower).is_some() {
        return function_names().find(|f| *f == lower);
    }
    let (best, distance) = function_names()
        .map(|f| (f, strsim::damerau_levenshtein(&lower, f)))
        .min_by_key(|(_, d)| *d)?;
    let allowed = if name.len() >= 4 { 2 } else { 1 };
    (distance <= allowed && name.len() >= 2).then_some(best)
}

/// Where each parameter first appears in the formula.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ParamSpans(pub Vec<Span>);

/// Lowers a parsed formula to `lhs − rhs` in `graph`; returns the root and parameter spans.
/// A formula that folds to an undefined constant is refused, pointing at the operation that
/// first made a defined value undefined; so is one that folds to 0 (M would be the whole
/// domain).
pub fn lower(
    formula: &Formula,
    graph: &mut ExprGraph,
) -> Result<(NodeId, ParamSpans), SourceError> {
    let mut lowering = Lowering {
        graph,
        spans: ParamSpans::default(),
        undefined: None,
    };
    let whole = formula.lhs.span.start
        ..formula
            .rhs
            .as_ref()
            .map_or(formula.lhs.span.end, |r| r.span.end);
    let lhs = lowering.expr(&formula.lhs)?;
    let root = match &formula.rhs {
        Some(rhs) => {
            let rhs = lowering.expr(rhs)?;
            let root = lowering.graph.sub(lhs, rhs);
            lowering.note_undefined(root, &whole, BinaryOp::Sub.spec().undefined);
            root
        }
        None => lhs,
    };
    if lowering.is_undefined(root) {
        let (span, why) = lowering
            .undefined
            .take()
            .unwrap_or((whole, "every value in it is undefined"));
        return Err(
            SourceError::new("F is undefined everywhere in the domain", span, why).with_hint(
                "an operation on an undefined value is undefined, so F has no value at any \
                 point: change this part",
            ),
        );
    }
    if lowering.graph.const_value(root) == Some(0.0) {
        let why = if formula.rhs.is_some() {
            "the two sides are equal at every point"
        } else {
            "this is 0 at every point"
        };
        return Err(SourceError::new("F is 0 everywhere", whole, why).with_hint(
            "every point of the domain would be on M, a solid and not a 3-manifold, so there \
             is nothing to draw: write F so that it is 0 only on M (the glome: x^2 + y^2 + \
             z^2 + w^2 = 1)",
        ));
    }
    Ok((root, lowering.spans))
}

struct Lowering<'g> {
    graph: &'g mut ExprGraph,
    spans: ParamSpans,
    /// The first expression (innermost, leftmost) whose defined operands gave an undefined
    /// constant, and why.
    undefined: Option<(Span, &'static str)>,
}

impl Lowering<'_> {
    fn is_undefined(&self, id: NodeId) -> bool {
        self.graph.const_value(id).is_some_and(f64::is_nan)
    }

    /// Remembers `span` as the culprit if `id` is the first undefined constant.
    fn note_undefined(&mut self, id: NodeId, span: &Span, why: &'static str) {
        if self.undefined.is_none() && self.is_undefined(id) {
            self.undefined = Some((span.clone(), why));
        }
    }

    fn expr(&mut self, expr: &Expr) -> Result<NodeId, SourceError> {
        match &expr.kind {
            ExprKind::Number(v) => Ok(self.graph.constant(*v)),
            ExprKind::Ident(name) => self.ident(name, &expr.span),
            ExprKind::Neg(a) => {
                let a = self.expr(a)?;
                Ok(self.graph.neg(a))
            }
            ExprKind::Abs(a) => {
                let a = self.expr(a)?;
                Ok(self.graph.unary(UnaryOp::Abs, a))
            }
            ExprKind::Binary(op, a, b) => {
                let (a, b) = (self.expr(a)?, self.expr(b)?);
                let op = match op {
                    BinOp::Add => BinaryOp::Add,
                    BinOp::Sub => BinaryOp::Sub,
                    BinOp::Mul => BinaryOp::Mul,
                    BinOp::Div => BinaryOp::Div,
                    BinOp::Pow => BinaryOp::Pow,
                };
                let node = self.graph.binary(op, a, b);
                self.note_undefined(node, &expr.span, op.spec().undefined);
                Ok(node)
            }
            ExprKind::Call {
                name,
                name_span,
                args,
            } => self.call(name, name_span, args, &expr.span),
        }
    }

    fn ident(&mut self, name: &str, span: &Span) -> Result<NodeId, SourceError> {
        if let Some(axis) = VARIABLES.iter().position(|v| *v == name) {
            return Ok(self.graph.var(axis as u8));
        }
        if let Some((_, value)) = CONSTANTS.iter().find(|(n, _)| *n == name) {
            return Ok(self.graph.constant(*value));
        }
        // A run of coordinates, `xy` or `xyzw`, is their product, as mathematicians write it.
        if name.len() > 1 && name.chars().all(|c| "xyzw".contains(c)) {
            let mut product = self.graph.constant(1.0);
            for c in name.chars() {
                let axis = VARIABLES
                    .iter()
                    .position(|v| v.starts_with(c))
                    .expect("checked");
                let v = self.graph.var(axis as u8);
                product = self.graph.mul(product, v);
            }
            return Ok(product);
        }
        if function(name).is_some() {
            return Err(SourceError::new(
                format!("'{name}' is a function and needs its argument in parentheses"),
                span.clone(),
                "function used without '('",
            )
            .with_hint(format!("write {name}(x)")));
        }
        Ok(self.param(name, span))
    }

    fn param(&mut self, name: &str, span: &Span) -> NodeId {
        let before = self.graph.params().len();
        let id = self.graph.param(name);
        if self.graph.params().len() > before {
            self.spans.0.push(span.clone());
        }
        id
    }

    fn call(
        &mut self,
        name: &str,
        name_span: &Span,
        args: &[Expr],
        span: &Span,
    ) -> Result<NodeId, SourceError> {
        let Some(f) = function(name) else {
            if let Some(suggestion) = suggest_function(name) {
                return Err(SourceError::new(
                    format!("unknown function '{name}'"),
                    name_span.clone(),
                    "not a function fourfold knows",
                )
                .with_hint(format!("did you mean {suggestion}?")));
            }
            // `R(x + 1)`, `x(y - 1)`: a name before a bracket is a product, as on paper.
            if let [single] = args {
                let factor = self.ident(name, name_span)?;
                let inner = self.expr(single)?;
                let node = self.graph.mul(factor, inner);
                self.note_undefined(node, span, BinaryOp::Mul.spec().undefined);
                return Ok(node);
            }
            return Err(SourceError::new(
                format!("unknown function '{name}'"),
                name_span.clone(),
                "not a function fourfold knows",
            )
            .with_hint(format!(
                "the functions are: {}",
                function_names().collect::<Vec<_>>().join(", ")
            )));
        };
        let expected = f.arity();
        if args.len() != expected {
            let plural = if expected == 1 { "" } else { "s" };
            return Err(SourceError::new(
                format!(
                    "{name} takes {expected} argument{plural}, but {} were given",
                    args.len()
                ),
                span.clone(),
                format!("expected {expected} argument{plural}"),
            )
            .with_hint(match f {
                Function::Unary(_) => format!("write {name}(x)"),
                Function::Binary(_) => format!("write {name}(a, b)"),
            }));
        }
        let lowered = args
            .iter()
            .map(|a| self.expr(a))
            .collect::<Result<Vec<_>, _>>()?;
        let (node, why) = match f {
            Function::Unary(op) => (self.graph.unary(op, lowered[0]), op.spec().undefined),
            Function::Binary(op) => (
                self.graph.binary(op, lowered[0], lowered[1]),
                op.spec().undefined,
            ),
        };
        self.note_undefined(node, span, why);
        Ok(node)
    }
}
