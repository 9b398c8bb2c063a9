//! The shared expression graph: a hash-consed DAG in which every node is created after its
//! operands, so node order is a topological order and every pass (evaluation, derivatives,
//! code generation) is a loop, not a recursion. Constructors fold constants and apply the
//! small algebraic rules that keep derivatives readable (`x*x` → `x^2`, `0*a` → `0`, ...).
//!
//! Folding is total: no node applies an operation to constants alone, whatever the value
//! (an undefined one is NaN, which every operation keeps; an overflow is ±∞). So the shader
//! never asks a WGSL compiler to evaluate an out-of-domain builtin or an infinite constant.

use std::collections::HashMap;

pub use crate::ops::{BinaryOp, NodeId, UnaryOp};

/// A node of the graph.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Node {
    Const(f64),
    /// 0 = x, 1 = y, 2 = z, 3 = w.
    Var(u8),
    /// Index into [`ExprGraph::params`]: a named value that changes without re-parsing.
    Param(u32),
    Unary(UnaryOp, NodeId),
    Binary(BinaryOp, NodeId, NodeId),
    /// Integer power, kept apart from `Pow` because it is defined for negative bases and has
    /// tight interval bounds.
    Powi(NodeId, i32),
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum Key {
    Const(u64),
    Var(u8),
    Param(u32),
    Unary(UnaryOp, NodeId),
    Binary(BinaryOp, NodeId, NodeId),
    Powi(NodeId, i32),
}

impl From<Node> for Key {
    fn from(node: Node) -> Self {
        match node {
            // -0.0 and 0.0 are one constant; every NaN is one constant.
            Node::Const(0.0) => Key::Const(0),
            Node::Const(v) if v.is_nan() => Key::Const(f64::NAN.to_bits()),
            Node::Const(v) => Key::Const(v.to_bits()),
            Node::Var(i) => Key::Var(i),
            Node::Param(i) => Key::Param(i),
            Node::Unary(op, a) => Key::Unary(op, a),
            Node::Binary(op, a, b) => Key::Binary(op, a, b),
            Node::Powi(a, n) => Key::Powi(a, n),
        }
    }
}

/// Names of the four coordinates, in axis order.
pub const VARIABLES: [&str; 4] = ["x", "y", "z", "w"];

/// Integer exponents up to this size stay integer powers.
const MAX_INT_EXPONENT: f64 = 1024.0;

/// A hash-consed expression DAG with named parameters.
#[derive(Debug, Clone, Default)]
pub struct ExprGraph {
    nodes: Vec<Node>,
    index: HashMap<Key, NodeId>,
    params: Vec<String>,
}

impl ExprGraph {
    pub fn new() -> Self {
        Self::default()
    }

    pub fn nodes(&self) -> &[Node] {
        &self.nodes
    }

    pub fn node(&self, id: NodeId) -> Node {
        self.nodes[id.index()]
    }

    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Parameter names, in the order of their first appearance.
    pub fn params(&self) -> &[String] {
        &self.params
    }

    pub fn const_value(&self, id: NodeId) -> Option<f64> {
        match self.node(id) {
            Node::Const(v) => Some(v),
            _ => None,
        }
    }

    fn intern(&mut self, node: Node) -> NodeId {
        let key = Key::from(node);
        if let Some(&id) = self.index.get(&key) {
            return id;
        }
        let id = NodeId(u32::try_from(self.nodes.len()).expect("fewer than 2^32 nodes"));
        self.nodes.push(node);
        self.index.insert(key, id);
        id
    }

    pub fn constant(&mut self, value: f64) -> NodeId {
        self.intern(Node::Const(if value == 0.0 { 0.0 } else { value }))
    }

    pub fn var(&mut self, axis: u8) -> NodeId {
        assert!(axis < 4, "there are four coordinates");
        self.intern(Node::Var(axis))
    }

    /// The node of parameter `name`, registering the name on first use.
    pub fn param(&mut self, name: &str) -> NodeId {
        let index = match self.params.iter().position(|p| p == name) {
            Some(i) => i,
            None => {
                self.params.push(name.to_string());
                self.params.len() - 1
            }
        };
        self.intern(Node::Param(index as u32))
    }

    pub fn is_const(&self, id: NodeId, value: f64) -> bool {
        self.const_value(id) == Some(value)
    }

    pub fn add(&mut self, a: NodeId, b: NodeId) -> NodeId {
        self.binary(BinaryOp::Add, a, b)
    }
    pub fn sub(&mut self, a: NodeId, b: NodeId) -> NodeId {
        self.binary(BinaryOp::Sub, a, b)
    }
    pub fn mul(&mut self, a: NodeId, b: NodeId) -> NodeId {
        self.binary(BinaryOp::Mul, a, b)
    }
    pub fn div(&mut self, a: NodeId, b: NodeId) -> NodeId {
        self.binary(BinaryOp::Div, a, b)
    }
    pub fn neg(&mut self, a: NodeId) -> NodeId {
        self.unary(UnaryOp::Neg, a)
    }

    /// A unary node, folded and simplified.
    pub fn unary(&mut self, op: UnaryOp, a: NodeId) -> NodeId {
        if let Some(v) = self.const_value(a) {
            return self.constant((op.spec().point)(v));
        }
        match (op, self.node(a)) {
            (UnaryOp::Neg, Node::Unary(UnaryOp::Neg, inner)) => return inner,
            (UnaryOp::Neg, Node::Binary(BinaryOp::Sub, p, q)) => return self.sub(q, p),
            (UnaryOp::Neg, Node::Binary(BinaryOp::Mul, p, q)) if self.const_value(p).is_some() => {
                let c = self.constant(-self.const_value(p).expect("checked"));
                return self.mul(c, q);
            }
            (UnaryOp::Abs, Node::Unary(UnaryOp::Neg | UnaryOp::Abs, inner)) => {
                return self.unary(UnaryOp::Abs, inner);
            }
            (UnaryOp::Abs, Node::Powi(_, n)) if n % 2 == 0 => return a,
            (UnaryOp::Abs, Node::Unary(UnaryOp::Exp | UnaryOp::Sqrt | UnaryOp::Cosh, _)) => {
                return a;
            }
            (UnaryOp::Sign | UnaryOp::Step, Node::Unary(UnaryOp::Exp | UnaryOp::Cosh, _)) => {
                return self.constant(1.0);
            }
            _ => {}
        }
        self.intern(Node::Unary(op, a))
    }

    /// An integer power, folded and simplified.
    pub fn powi(&mut self, a: NodeId, n: i32) -> NodeId {
        match n {
            0 => return self.constant(1.0),
            1 => return a,
            _ => {}
        }
        if let Some(v) = self.const_value(a) {
            return self.constant(crate::ops::powi(v, n));
        }
        match self.node(a) {
            Node::Powi(base, m) if (m as i64 * n as i64).abs() <= MAX_INT_EXPONENT as i64 => {
                return self.powi(base, m * n);
            }
            Node::Unary(UnaryOp::Neg, inner) => {
                let p = self.powi(inner, n);
                return if n % 2 == 0 { p } else { self.neg(p) };
            }
            Node::Unary(UnaryOp::Abs, inner) if n % 2 == 0 => return self.powi(inner, n),
            _ => {}
        }
        self.intern(Node::Powi(a, n))
    }

    /// A binary node, folded and simplified.
    pub fn binary(&mut self, op: BinaryOp, a: NodeId, b: NodeId) -> NodeId {
        use BinaryOp::*;
        let (ca, cb) = (self.const_value(a), self.const_value(b));
        if let Some(folded) = fold_binary(op, ca, cb) {
            return self.constant(folded);
        }
        match op {
            Add => {
                if ca == Some(0.0) {
                    return b;
                }
                if cb == Some(0.0) {
                    return a;
                }
                if a == b {
                    let two = self.constant(2.0);
                    return self.mul(two, a);
                }
                if let Node::Unary(UnaryOp::Neg, q) = self.node(b) {
                    return self.sub(a, q);
                }
                if let Node::Unary(UnaryOp::Neg, p) = self.node(a) {
                    return self.sub(b, p);
                }
                // Constants first, then by id: a + b and b + a become one node.
                let (a, b) = canonical_order(ca, cb, a, b);
                self.intern(Node::Binary(Add, a, b))
            }
            Sub => {
                if cb == Some(0.0) {
                    return a;
                }
                if ca == Some(0.0) {
                    return self.neg(b);
                }
                if a == b {
                    return self.constant(0.0);
                }
                if let Node::Unary(UnaryOp::Neg, q) = self.node(b) {
                    return self.add(a, q);
                }
                self.intern(Node::Binary(Sub, a, b))
            }
            Mul => self.mul_simplified(a, b, ca, cb),
            Div => {
                if cb == Some(1.0) {
                    return a;
                }
                if ca == Some(0.0) {
                    return a;
                }
                if a == b {
                    return self.constant(1.0);
                }
                if let Some(c) = cb {
                    // x/2 = 0.5x exactly; other divisors keep their division for accuracy.
                    let inverse = 1.0 / c;
                    if c != 0.0 && inverse.is_finite() && inverse * c == 1.0 && is_power_of_two(c) {
                        let k = self.constant(inverse);
                        return self.mul(k, a);
                    }
                }
                // Constant factors move out of quotients: (c·u)/v → c·(u/v).
                if let Node::Binary(BinaryOp::Mul, p, q) = self.node(a)
                    && self.const_value(p).is_some()
                {
                    let inner = self.div(q, b);
                    return self.mul(p, inner);
                }
                if let Node::Binary(BinaryOp::Mul, p, q) = self.node(b)
                    && let Some(c) = self.const_value(p).filter(|c| is_power_of_two(*c))
                {
                    let k = self.constant(1.0 / c);
                    let inner = self.div(a, q);
                    return self.mul(k, inner);
                }
                if ca == Some(1.0)
                    && let Node::Powi(base, n) = self.node(b)
                {
                    return self.powi(base, -n);
                }
                self.intern(Node::Binary(Div, a, b))
            }
            Pow => {
                if let Some(e) = cb {
                    if e.fract() == 0.0 && e.abs() <= MAX_INT_EXPONENT {
                        return self.powi(a, e as i32);
                    }
                    if e.fract() == 0.0 {
                        return self.large_integer_power(a, b, e);
                    }
                    if e == 0.5 {
                        return self.unary(UnaryOp::Sqrt, a);
                    }
                }
                if ca == Some(std::f64::consts::E) {
                    return self.unary(UnaryOp::Exp, b);
                }
                self.intern(Node::Binary(Pow, a, b))
            }
            Min | Max => {
                if a == b {
                    return a;
                }
                let (a, b) = canonical_order(ca, cb, a, b);
                self.intern(Node::Binary(op, a, b))
            }
            Atan2 => self.intern(Node::Binary(Atan2, a, b)),
        }
    }

    fn mul_simplified(&mut self, a: NodeId, b: NodeId, ca: Option<f64>, cb: Option<f64>) -> NodeId {
        if ca == Some(0.0) || cb == Some(0.0) {
            return self.constant(0.0);
        }
        if ca == Some(1.0) {
            return b;
        }
        if cb == Some(1.0) {
            return a;
        }
        if ca == Some(-1.0) {
            return self.neg(b);
        }
        if cb == Some(-1.0) {
            return self.neg(a);
        }
        if a == b {
            return self.powi(a, 2);
        }
        // Constants gather on the left: c1·(c2·u) → (c1·c2)·u.
        if ca.is_none() && cb.is_some() {
            return self.mul(b, a);
        }
        if let (Some(c1), Node::Binary(BinaryOp::Mul, p, q)) = (ca, self.node(b))
            && let Some(c2) = self.const_value(p)
        {
            let c = self.constant(c1 * c2);
            return self.mul(c, q);
        }
        // Constants move outwards: a·(c·v) → c·(a·v), so that 4R²·2x becomes 8·(R²·x).
        if ca.is_none() {
            if let Node::Binary(BinaryOp::Mul, p, q) = self.node(b)
                && self.const_value(p).is_some()
            {
                let inner = self.mul(a, q);
                return self.mul(p, inner);
            }
            if let Node::Binary(BinaryOp::Mul, p, q) = self.node(a)
                && self.const_value(p).is_some()
            {
                let inner = self.mul(q, b);
                return self.mul(p, inner);
            }
        }
        if let Node::Unary(UnaryOp::Neg, p) = self.node(a) {
            let m = self.mul(p, b);
            return self.neg(m);
        }
        if let Node::Unary(UnaryOp::Neg, q) = self.node(b) {
            let m = self.mul(a, q);
            return self.neg(m);
        }
        // Powers of one base merge: x·x^n → x^(n+1), x^m·x^n → x^(m+n).
        let (base_a, exp_a) = self.as_power(a);
        let (base_b, exp_b) = self.as_power(b);
        if base_a == base_b && (exp_a + exp_b).abs() <= MAX_INT_EXPONENT as i32 {
            return self.powi(base_a, exp_a + exp_b);
        }
        let (a, b) = canonical_order(ca, cb, a, b);
        self.intern(Node::Binary(BinaryOp::Mul, a, b))
    }

    /// `a` to the integer `e` (node `b`), too large to multiply out: |a|^e, with a's sign
    /// for an odd `e`, so that a negative `a` has the power `x^3` would give it (a real power
    /// of a negative number is undefined).
    fn large_integer_power(&mut self, a: NodeId, b: NodeId, e: f64) -> NodeId {
        let magnitude = self.unary(UnaryOp::Abs, a);
        let power = self.intern(Node::Binary(BinaryOp::Pow, magnitude, b));
        if e % 2.0 == 0.0 {
            return power;
        }
        let sign = self.unary(UnaryOp::Sign, a);
        self.mul(sign, power)
    }

    fn as_power(&self, id: NodeId) -> (NodeId, i32) {
        match self.node(id) {
            Node::Powi(base, n) => (base, n),
            _ => (id, 1),
        }
    }

    /// The nodes that `roots` depend on, as a mask over node ids.
    pub fn reachable(&self, roots: &[NodeId]) -> Vec<bool> {
        let mut seen = vec![false; self.nodes.len()];
        for root in roots {
            seen[root.index()] = true;
        }
        for i in (0..self.nodes.len()).rev() {
            if !seen[i] {
                continue;
            }
            for child in operands(self.nodes[i]) {
                seen[child.index()] = true;
            }
        }
        seen
    }
}

/// The operands of a node (zero, one or two).
pub fn operands(node: Node) -> impl Iterator<Item = NodeId> {
    let (a, b) = match node {
        Node::Const(_) | Node::Var(_) | Node::Param(_) => (None, None),
        Node::Unary(_, a) | Node::Powi(a, _) => (Some(a), None),
        Node::Binary(_, a, b) => (Some(a), Some(b)),
    };
    a.into_iter().chain(b)
}

/// The value of `op` known from its constant operands alone, with the language's meaning
/// (NaN is undefined): both constant; an undefined operand, which leaves every operation
/// undefined; division by 0; a real power of a negative number.
fn fold_binary(op: BinaryOp, a: Option<f64>, b: Option<f64>) -> Option<f64> {
    match (a, b) {
        // A negative number's integer power, which the real power leaves undefined.
        (Some(x), Some(y)) if op == BinaryOp::Pow && x < 0.0 && y.fract() == 0.0 => Some(x.powf(y)),
        (Some(x), Some(y)) => Some((op.spec().point)(x, y)),
        (Some(v), None) | (None, Some(v)) if v.is_nan() => Some(f64::NAN),
        (_, Some(0.0)) if op == BinaryOp::Div => Some(f64::NAN),
        (Some(x), None) if op == BinaryOp::Pow && x < 0.0 => Some(f64::NAN),
        _ => None,
    }
}

fn canonical_order(ca: Option<f64>, cb: Option<f64>, a: NodeId, b: NodeId) -> (NodeId, NodeId) {
    match (ca.is_some(), cb.is_some()) {
        (false, true) => (b, a),
        (true, false) => (a, b),
        _ if b < a => (b, a),
        _ => (a, b),
    }
}

fn is_power_of_two(c: f64) -> bool {
    let bits = c.abs().to_bits();
    c.is_normal() && bits & ((1u64 << 52) - 1) == 0
}

/// The graph builds derivative rules' terms (see `crate::ops`).
impl crate::ops::Builder for ExprGraph {
    fn constant(&mut self, value: f64) -> NodeId {
        ExprGraph::constant(self, value)
    }
    fn unary(&mut self, op: UnaryOp, a: NodeId) -> NodeId {
        ExprGraph::unary(self, op, a)
    }
    fn binary(&mut self, op: BinaryOp, a: NodeId, b: NodeId) -> NodeId {
        ExprGraph::binary(self, op, a, b)
    }
    fn powi(&mut self, a: NodeId, n: i32) -> NodeId {
        ExprGraph::powi(self, a, n)
    }
    fn is_const(&self, a: NodeId, value: f64) -> bool {
        ExprGraph::is_const(self, a, value)
    }
}
