//! Symbolic differentiation on the expression graph: each operation's rule is its row of the
//! table in `crate::ops`, built with the graph's simplifying constructors, so d/dx of x^2 is
//! `2x`, and derivatives share nodes with F.

use crate::ops::Operands;

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
            Node::Binary(op, u, v) => {
                let (du, dv) = (d[u.index()], d[v.index()]);
                binary(
                    graph,
                    op,
                    Operands {
                        u,
                        v,
                        f: id,
                        du,
                        dv,
                    },
                )
            }
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

/// d f(u) = f'(u)·du, by the operation's rule (`crate::ops`).
fn unary(g: &mut ExprGraph, op: UnaryOp, f: NodeId, u: NodeId, du: NodeId) -> NodeId {
    if g.is_const(du, 0.0) {
        return du;
    }
    (op.spec().derivative)(g, u, f, du)
}

/// d f(u, v), by the operation's rule (`crate::ops`).
fn binary(g: &mut ExprGraph, op: BinaryOp, operands: Operands) -> NodeId {
    if g.is_const(operands.du, 0.0) && g.is_const(operands.dv, 0.0) {
        return operands.du;
    }
    (op.spec().derivative)(g, operands)
}
