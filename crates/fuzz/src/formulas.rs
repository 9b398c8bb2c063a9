//! Random formulas from the language's grammar (`crates/fourfold/grammar/formula.pest`):
//! every function and alias of the operation tables, every operator spelling, implicit
//! products, `|…|`, parameters, `=`, and numbers at the edges of the functions' domains and
//! of f32 and f64 (0, ±1, π/2, huge, tiny, beyond f32, beyond f64). A formula is a tree of
//! [`Term`]s so that a failing one can be shrunk (`shrink`); its text is what a user types.

use std::fmt;

use fastrand::Rng;
use fourfold::ops::{Function, function, function_names};

/// A piece of formula text, as written.
#[derive(Debug, Clone, PartialEq)]
pub enum Term {
    /// A number as written (`2`, `.5`, `1e-320`).
    Number(String),
    /// A variable, a run of variables (`xy`), a constant or a parameter.
    Name(String),
    /// `-a` or `+a`.
    Prefix(char, Box<Term>),
    /// `|a|`.
    Bars(Box<Term>),
    /// `(a)`.
    Group(Box<Term>),
    /// `a op b`, the operator as written with its spaces (`" * "`, `"·"`, `"**"`).
    Infix(&'static str, Box<Term>, Box<Term>),
    /// `a b`: an implicit product (`2x`, `R(x + 1)`, `(a)(b)`).
    Juxtaposed(Box<Term>, Box<Term>),
    /// `name(a, …)`, possibly with the wrong number of arguments.
    Call(String, Vec<Term>),
    /// Text taken as it is: a formula written by hand, in a test.
    Text(String),
}

/// A formula: `lhs` or `lhs = rhs`.
#[derive(Debug, Clone, PartialEq)]
pub struct Formula {
    pub lhs: Term,
    pub rhs: Option<Term>,
}

/// Numbers at the edges: of asin's and acos's domain, of ln's and sqrt's, of exp's overflow
/// in f32 (88.7) and f64 (709.8), of f32's range (3.4e38) and f64's (1.8e308, and `1e309`,
/// which reads as ∞), subnormal and underflowing ones, and spellings the grammar allows.
pub const EDGE_NUMBERS: &[&str] = &[
    "0",
    "0.0",
    "00",
    "1",
    "1.",
    "2",
    "3",
    "0.5",
    ".5",
    "10",
    "-0",
    "1e3",
    "1E-3",
    "2.5e+2",
    "1.5707963267948966",
    "3.14159",
    "0.999999",
    "1.000001",
    "89",
    "90",
    "710",
    "1e30",
    "1e38",
    "3.5e38",
    "1e300",
    "1e308",
    "1e309",
    "1e-30",
    "1e-45",
    "1e-320",
    "1e-400",
];

/// Parameter names a user might pick (none is a function, a variable or a constant).
pub const PARAMETERS: &[&str] = &["a", "b", "R", "t", "k", "r_1", "Radius", "q2"];

/// Operator spellings, with and without spaces.
const INFIX: &[&str] = &[
    "+", " + ", "-", " - ", "*", " * ", "·", "×", "/", " / ", "^", "**",
];

const NAMES: &[&str] = &[
    "x", "y", "z", "w", "x", "y", "z", "w", "xy", "zw", "xyz", "xyzw", "pi", "tau", "e",
];

impl fmt::Display for Term {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Term::Number(text) | Term::Name(text) | Term::Text(text) => f.write_str(text),
            Term::Prefix(sign, a) => write!(f, "{sign}{a}"),
            Term::Bars(a) => write!(f, "|{a}|"),
            Term::Group(a) => write!(f, "({a})"),
            Term::Infix(op, a, b) => write!(f, "{a}{op}{b}"),
            Term::Juxtaposed(a, b) => {
                let (left, right) = (a.to_string(), b.to_string());
                // `2 3` and `a b`, not `23` and `ab`, which read as one token.
                let word = |c: Option<char>| {
                    c.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == '.')
                };
                let gap = if word(left.chars().last()) && word(right.chars().next()) {
                    " "
                } else {
                    ""
                };
                write!(f, "{left}{gap}{right}")
            }
            Term::Call(name, args) => {
                write!(f, "{name}(")?;
                for (i, arg) in args.iter().enumerate() {
                    if i > 0 {
                        f.write_str(", ")?;
                    }
                    write!(f, "{arg}")?;
                }
                f.write_str(")")
            }
        }
    }
}

impl fmt::Display for Formula {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.rhs {
            Some(rhs) => write!(f, "{} = {rhs}", self.lhs),
            None => write!(f, "{}", self.lhs),
        }
    }
}

impl Formula {
    /// The parameters it names, in order of first appearance.
    pub fn parameters(&self) -> Vec<&'static str> {
        let text = self.to_string();
        let words: Vec<&str> = text
            .split(|c: char| !(c.is_alphanumeric() || c == '_'))
            .collect();
        PARAMETERS
            .iter()
            .copied()
            .filter(|p| words.contains(p))
            .collect()
    }
}

/// Makes random formulas.
pub struct FormulaMaker<'r> {
    rng: &'r mut Rng,
    functions: Vec<&'static str>,
    /// Terms still to spend: a formula is at most a few dozen of them.
    budget: u32,
}

impl<'r> FormulaMaker<'r> {
    pub fn new(rng: &'r mut Rng) -> Self {
        Self {
            rng,
            functions: function_names().collect(),
            budget: 0,
        }
    }

    /// A random formula: an equation 40% of the time.
    pub fn formula(&mut self) -> Formula {
        self.budget = 4 + self.rng.u32(..28);
        let lhs = self.term(0);
        let rhs = self.rng.f32() < 0.4;
        Formula {
            lhs,
            rhs: rhs.then(|| self.term(1)),
        }
    }

    fn term(&mut self, depth: u32) -> Term {
        self.budget = self.budget.saturating_sub(1);
        if self.budget == 0 || depth > 6 || self.rng.f32() < 0.12 * depth as f32 {
            return self.leaf();
        }
        match self.rng.u32(..20) {
            0..=6 => {
                let op = INFIX[self.rng.usize(..INFIX.len())];
                let a = self.operand(depth);
                let b = self.operand(depth);
                Term::Infix(op, Box::new(a), Box::new(b))
            }
            7..=12 => self.call(depth),
            13 | 14 => {
                let a = self.operand(depth);
                let b = self.juxtaposable(depth);
                Term::Juxtaposed(Box::new(a), Box::new(b))
            }
            15 => Term::Prefix(
                if self.rng.bool() { '-' } else { '+' },
                Box::new(self.operand(depth)),
            ),
            16 => Term::Bars(Box::new(self.term(depth + 1))),
            17 => self.constant_expression(),
            _ => Term::Group(Box::new(self.term(depth + 1))),
        }
    }

    /// An operand of an operator: grouped where it is compound, mostly (ungrouped, the
    /// operators' precedence decides).
    fn operand(&mut self, depth: u32) -> Term {
        let t = self.term(depth + 1);
        let compound = matches!(t, Term::Infix(..) | Term::Juxtaposed(..) | Term::Prefix(..));
        if compound && self.rng.f32() < 0.85 {
            Term::Group(Box::new(t))
        } else {
            t
        }
    }

    /// The right operand of an implicit product: one that starts as the grammar needs.
    fn juxtaposable(&mut self, depth: u32) -> Term {
        match self.rng.u32(..4) {
            0 => self.leaf(),
            1 => self.call(depth + 1),
            2 => Term::Bars(Box::new(self.term(depth + 1))),
            _ => Term::Group(Box::new(self.term(depth + 1))),
        }
    }

    fn leaf(&mut self) -> Term {
        match self.rng.u32(..10) {
            0..=4 => Term::Name(NAMES[self.rng.usize(..NAMES.len())].to_string()),
            5 => Term::Name(PARAMETERS[self.rng.usize(..PARAMETERS.len())].to_string()),
            6 | 7 => Term::Number(self.number()),
            _ => Term::Number(format!("{:.2}", self.rng.f64() * 4.0)),
        }
    }

    fn number(&mut self) -> String {
        EDGE_NUMBERS[self.rng.usize(..EDGE_NUMBERS.len())].to_string()
    }

    /// A call of a random function or alias; 3% of the time with the wrong number of
    /// arguments; a third of the time on constants alone (`asin(2)`, `ln(e - pi)`).
    fn call(&mut self, depth: u32) -> Term {
        let name = self.functions[self.rng.usize(..self.functions.len())];
        let arity = match function(name) {
            Some(Function::Binary(_)) => 2,
            _ => 1,
        };
        let count = if self.rng.f32() < 0.03 {
            [0, 1, 2, 3][self.rng.usize(..4)]
        } else {
            arity
        };
        let constant = self.rng.f32() < 0.33;
        let args = (0..count)
            .map(|_| {
                if constant {
                    self.constant_expression()
                } else {
                    self.term(depth + 1)
                }
            })
            .collect();
        Term::Call(name.to_string(), args)
    }

    /// An expression of constants alone: a number, a constant, or one operation on two.
    fn constant_expression(&mut self) -> Term {
        let atom = |m: &mut Self| {
            if m.rng.f32() < 0.25 {
                Term::Name(["pi", "tau", "e"][m.rng.usize(..3)].to_string())
            } else {
                Term::Number(m.number())
            }
        };
        match self.rng.u32(..4) {
            0 => Term::Prefix('-', Box::new(atom(self))),
            1 => {
                let op = INFIX[self.rng.usize(..INFIX.len())];
                let (a, b) = (atom(self), atom(self));
                Term::Group(Box::new(Term::Infix(op, Box::new(a), Box::new(b))))
            }
            _ => atom(self),
        }
    }
}
