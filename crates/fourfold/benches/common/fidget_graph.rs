//! Our expression graph in fidget's terms, for the benchmarks that race fidget (the interval
//! evaluators here, the slice renderers in the command line's `peer` bench).

use fidget::context::{Context, Node as FNode};
use fourfold::CompiledFormula;
use fourfold::expr::{BinaryOp, Node, NodeId, UnaryOp};

fn bad<E: std::fmt::Display>(e: E) -> String {
    e.to_string()
}

/// Translates the nodes reachable from `roots` into `ctx`, x, y, z and w standing for the
/// four `axes` (fidget's own variables or expressions of them). Only the operations the
/// benchmarked formulas use are needed; others are reported.
pub fn translate(
    ctx: &mut Context,
    f: &CompiledFormula,
    params: &[f64],
    roots: &[NodeId],
    axes: [FNode; 4],
) -> Result<Vec<FNode>, String> {
    let live = f.graph.reachable(roots);
    let mut map: Vec<Option<FNode>> = vec![None; f.graph.len()];
    for (i, node) in f.graph.nodes().iter().enumerate() {
        if !live[i] {
            continue;
        }
        let get = |id: NodeId| map[id.index()].ok_or("operand before node".to_string());
        let n = match *node {
            Node::Const(c) => ctx.constant(c as f32),
            Node::Var(k) => axes[usize::from(k).min(3)],
            Node::Param(p) => ctx.constant(params[p as usize] as f32),
            Node::Unary(op, a) => {
                let a = get(a)?;
                match op {
                    UnaryOp::Neg => ctx.neg(a),
                    UnaryOp::Abs => ctx.abs(a),
                    UnaryOp::Sqrt => ctx.sqrt(a),
                    UnaryOp::Exp => ctx.exp(a),
                    UnaryOp::Ln => ctx.ln(a),
                    UnaryOp::Sin => ctx.sin(a),
                    UnaryOp::Cos => ctx.cos(a),
                    other => return Err(format!("{other:?} not translated")),
                }
                .map_err(bad)?
            }
            Node::Binary(op, a, b) => {
                let (a, b) = (get(a)?, get(b)?);
                match op {
                    BinaryOp::Add => ctx.add(a, b),
                    BinaryOp::Sub => ctx.sub(a, b),
                    BinaryOp::Mul => ctx.mul(a, b),
                    BinaryOp::Div => ctx.div(a, b),
                    BinaryOp::Min => ctx.min(a, b),
                    BinaryOp::Max => ctx.max(a, b),
                    other => return Err(format!("{other:?} not translated")),
                }
                .map_err(bad)?
            }
            Node::Powi(a, n) => {
                let a = get(a)?;
                // The same square-and-multiply chain our evaluators and the WGSL use.
                if n < 1 {
                    return Err(format!("power {n} not translated"));
                }
                let mut result: Option<FNode> = None;
                let mut base = a;
                let mut k = n;
                let mut first = true;
                while k > 0 {
                    if !first {
                        base = ctx.square(base).map_err(bad)?;
                    }
                    first = false;
                    if k & 1 == 1 {
                        result = Some(match result {
                            None => base,
                            Some(r) => ctx.mul(r, base).map_err(bad)?,
                        });
                    }
                    k >>= 1;
                }
                result.unwrap_or(a)
            }
        };
        map[i] = Some(n);
    }
    let outs = roots
        .iter()
        .map(|r| map[r.index()].ok_or("root not translated".to_string()))
        .collect::<Result<_, _>>()?;
    Ok(outs)
}
