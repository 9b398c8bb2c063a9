//! Expression graph → readable infix text, as a mathematician would write it (`2x`,
//! `4R^2(x^2 + y^2)`). Used by `fourfold grad` and the viewer. Very large shared
//! subexpressions are abbreviated rather than printed exponentially often.

use super::graph::{BinaryOp, ExprGraph, Node, NodeId, UnaryOp, VARIABLES};

/// Text longer than this for one subexpression is shortened to `…`.
const MAX_TEXT: usize = 20_000;

/// Binding strength of what a node prints as; higher binds tighter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Prec {
    Sum = 1,
    Product = 2,
    Negation = 3,
    Power = 4,
    Atom = 5,
}

struct Printed {
    text: String,
    prec: Prec,
}

/// Infix text of `root`.
pub fn to_infix(graph: &ExprGraph, root: NodeId) -> String {
    let needed = graph.reachable(&[root]);
    let mut printed: Vec<Option<Printed>> = Vec::with_capacity(root.index() + 1);
    for i in 0..=root.index() {
        if !needed[i] {
            printed.push(None);
            continue;
        }
        let p = print_node(graph, graph.node(NodeId(i as u32)), &printed);
        let p = if p.text.len() > MAX_TEXT {
            Printed {
                text: "(…)".to_string(),
                prec: Prec::Atom,
            }
        } else {
            p
        };
        printed.push(Some(p));
    }
    printed[root.index()].take().expect("root is needed").text
}

/// Text of a number: integers without a decimal point, named constants by name.
pub fn number(v: f64) -> String {
    if v == std::f64::consts::PI {
        return "pi".into();
    }
    if v == std::f64::consts::E {
        return "e".into();
    }
    if v.fract() == 0.0 && v.abs() < 1e15 {
        return format!("{}", v as i64);
    }
    format!("{v:?}")
}

fn print_node(graph: &ExprGraph, node: Node, done: &[Option<Printed>]) -> Printed {
    let get = |id: NodeId| done[id.index()].as_ref().expect("operands come first");
    let wrap = |id: NodeId, min: Prec| {
        let p = get(id);
        if p.prec < min {
            format!("({})", p.text)
        } else {
            p.text.clone()
        }
    };
    match node {
        Node::Const(v) => Printed {
            text: number(v),
            prec: if v < 0.0 { Prec::Negation } else { Prec::Atom },
        },
        Node::Var(a) => atom(VARIABLES[a as usize].to_string()),
        Node::Param(i) => atom(graph.params()[i as usize].clone()),
        Node::Powi(a, n) => {
            let exponent = if n < 0 {
                format!("({n})")
            } else {
                n.to_string()
            };
            Printed {
                text: format!("{}^{exponent}", wrap(a, Prec::Atom)),
                prec: Prec::Power,
            }
        }
        Node::Unary(UnaryOp::Neg, a) => Printed {
            text: format!("-{}", wrap(a, Prec::Power)),
            prec: Prec::Negation,
        },
        Node::Unary(UnaryOp::Abs, a) => atom(format!("|{}|", get(a).text)),
        Node::Unary(op, a) => atom(format!("{}({})", op.spec().name, get(a).text)),
        Node::Binary(op, a, b) => match op {
            BinaryOp::Add => Printed {
                text: format!("{} + {}", wrap(a, Prec::Sum), plus_operand(get(b))),
                prec: Prec::Sum,
            },
            BinaryOp::Sub => Printed {
                text: format!("{} - {}", wrap(a, Prec::Sum), wrap(b, Prec::Product)),
                prec: Prec::Sum,
            },
            BinaryOp::Mul => {
                let left = wrap(a, Prec::Product);
                let numeric_left = graph.const_value(a).is_some();
                // After a number, a product needs no brackets: 4(x + y)*R^2.
                let right = if numeric_left && get(b).prec == Prec::Product {
                    get(b).text.clone()
                } else {
                    wrap(b, Prec::Power)
                };
                // Juxtapose a leading number with what follows, as on paper: 2x, 3sin(w).
                let juxtapose = numeric_left
                    && right
                        .chars()
                        .next()
                        .is_some_and(|c| c.is_ascii_alphabetic() || c == '(')
                    && !left.ends_with(|c: char| c.is_ascii_alphabetic());
                let text = if juxtapose {
                    format!("{left}{right}")
                } else {
                    format!("{left}*{right}")
                };
                Printed {
                    text,
                    prec: Prec::Product,
                }
            }
            BinaryOp::Div => Printed {
                text: format!("{}/{}", wrap(a, Prec::Product), wrap(b, Prec::Power)),
                prec: Prec::Product,
            },
            BinaryOp::Pow => Printed {
                text: format!("{}^{}", wrap(a, Prec::Atom), wrap(b, Prec::Atom)),
                prec: Prec::Power,
            },
            BinaryOp::Min | BinaryOp::Max | BinaryOp::Atan2 => {
                let name = op.spec().name;
                atom(format!("{name}({}, {})", get(a).text, get(b).text))
            }
        },
    }
}

fn plus_operand(p: &Printed) -> String {
    if p.prec <= Prec::Negation && p.text.starts_with('-') {
        format!("({})", p.text)
    } else {
        p.text.clone()
    }
}

fn atom(text: String) -> Printed {
    Printed {
        text,
        prec: Prec::Atom,
    }
}
