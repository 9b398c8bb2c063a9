//! Symbolic differentiation on the expression graph. Derivatives are built with the
//! simplifying constructors, so d/dx of x^2 is `2x`, and they share nodes with F.

use super::graph::{BinaryOp, ExprGraph, Node, NodeId, UnaryOp};

/// ∂root/∂(axis), added to `graph`. Iterative: visits the nodes `root` depends on in order.
pub fn derivative(graph: &mut ExprGraph, root: NodeId, axis: u8) -> NodeId {
    let needed = graph.reachable(&[root]);
    let zero = graph.constant(0.0);
    let mut d: Vec<NodeId> = vec![zero; root.index() + 1];
    for i in 0..=root.index() {
        if !needed[i] {
            continue;
        }
        let id = NodeId(i as u32);
        d[i] = match graph.node(id) {
            Node::Const(_) | Node::Param(_) => zero,
            Node::Var(a) => graph.constant(if a == axis { 1.0 } else { 0.0 }),
            Node::Unary(op, u) => unary(graph, op, id, u, d[u.index()]),
            Node::Binary(op, u, v) => binary(graph, op, id, u, v, d[u.index()], d[v.index()]),
            Node::Powi(u, n) => {
                let du = d[u.index()];
                if graph.is_const(du, 0.0) {
                    zero
                } else {
                    let k = graph.constant(n as f64);
                    let p = graph.powi(u, n - 1);
                    let kp = graph.mul(k, p);
                    graph.mul(kp, du)
                }
            }
        };
    }
    d[root.index()]
}

/// d f(u) = f'(u)·du.
fn unary(g: &mut ExprGraph, op: UnaryOp, f: NodeId, u: NodeId, du: NodeId) -> NodeId {
    if g.is_const(du, 0.0) {
        return du;
    }
    let fprime = match op {
        UnaryOp::Neg => return g.neg(du),
        UnaryOp::Abs => g.unary(UnaryOp::Sign, u),
        UnaryOp::Sign | UnaryOp::Step => return g.constant(0.0),
        UnaryOp::Sqrt => {
            // 1 / (2 sqrt u)
            let two = g.constant(2.0);
            let den = g.mul(two, f);
            return g.div(du, den);
        }
        UnaryOp::Cbrt => {
            let three = g.constant(3.0);
            let sq = g.powi(f, 2);
            let den = g.mul(three, sq);
            return g.div(du, den);
        }
        UnaryOp::Exp => f,
        UnaryOp::Ln => return g.div(du, u),
        UnaryOp::Sin => g.unary(UnaryOp::Cos, u),
        UnaryOp::Cos => {
            let s = g.unary(UnaryOp::Sin, u);
            g.neg(s)
        }
        UnaryOp::Tan => {
            let c = g.unary(UnaryOp::Cos, u);
            let c2 = g.powi(c, 2);
            return g.div(du, c2);
        }
        UnaryOp::Asin | UnaryOp::Acos => {
            let one = g.constant(1.0);
            let u2 = g.powi(u, 2);
            let diff = g.sub(one, u2);
            let root = g.unary(UnaryOp::Sqrt, diff);
            let q = g.div(du, root);
            return if op == UnaryOp::Asin { q } else { g.neg(q) };
        }
        UnaryOp::Atan => {
            let one = g.constant(1.0);
            let u2 = g.powi(u, 2);
            let den = g.add(one, u2);
            return g.div(du, den);
        }
        UnaryOp::Sinh => g.unary(UnaryOp::Cosh, u),
        UnaryOp::Cosh => g.unary(UnaryOp::Sinh, u),
        UnaryOp::Tanh => {
            let one = g.constant(1.0);
            let t2 = g.powi(f, 2);
            g.sub(one, t2)
        }
    };
    g.mul(fprime, du)
}

#[allow(clippy::too_many_arguments)]
fn binary(
    g: &mut ExprGraph,
    op: BinaryOp,
    f: NodeId,
    u: NodeId,
    v: NodeId,
    du: NodeId,
    dv: NodeId,
) -> NodeId {
    let du_zero = g.is_const(du, 0.0);
    let dv_zero = g.is_const(dv, 0.0);
    if du_zero && dv_zero {
        return du;
    }
    match op {
        BinaryOp::Add => g.add(du, dv),
        BinaryOp::Sub => g.sub(du, dv),
        BinaryOp::Mul => {
            let a = g.mul(du, v);
            let b = g.mul(u, dv);
            g.add(a, b)
        }
        BinaryOp::Div => {
            if dv_zero {
                return g.div(du, v);
            }
            // (u'v − uv') / v²
            let a = g.mul(du, v);
            let b = g.mul(u, dv);
            let num = g.sub(a, b);
            let den = g.powi(v, 2);
            g.div(num, den)
        }
        BinaryOp::Pow => {
            if dv_zero {
                // v·u^(v−1)·u'
                let one = g.constant(1.0);
                let vm1 = g.sub(v, one);
                let p = g.binary(BinaryOp::Pow, u, vm1);
                let vp = g.mul(v, p);
                return g.mul(vp, du);
            }
            // u^v · (v'·ln u + v·u'/u)
            let ln = g.unary(UnaryOp::Ln, u);
            let a = g.mul(dv, ln);
            let vdu = g.mul(v, du);
            let b = g.div(vdu, u);
            let s = g.add(a, b);
            g.mul(f, s)
        }
        BinaryOp::Min | BinaryOp::Max => {
            // The derivative of the branch that is taken: step(v − u) picks u for min.
            let diff = if op == BinaryOp::Min {
                g.sub(v, u)
            } else {
                g.sub(u, v)
            };
            let pick_u = g.unary(UnaryOp::Step, diff);
            let one = g.constant(1.0);
            let pick_v = g.sub(one, pick_u);
            let a = g.mul(pick_u, du);
            let b = g.mul(pick_v, dv);
            g.add(a, b)
        }
        BinaryOp::Atan2 => {
            // atan2(u, v)' = (v u' − u v') / (u² + v²)
            let a = g.mul(v, du);
            let b = g.mul(u, dv);
            let num = g.sub(a, b);
            let u2 = g.powi(u, 2);
            let v2 = g.powi(v, 2);
            let den = g.add(u2, v2);
            g.div(num, den)
        }
    }
}
