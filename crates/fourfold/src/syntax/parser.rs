//! Formula text → [`Formula`] syntax tree. pest matches the grammar in `grammar/formula.pest`,
//! the Pratt parser applies precedence, and this file turns pest's errors into messages a
//! person can act on.

use std::num::NonZeroUsize;
use std::sync::LazyLock;

use pest::Parser as _;
use pest::iterators::{Pair, Pairs};
use pest::pratt_parser::{Assoc, Op, PrattParser};

use super::ast::{BinOp, Expr, ExprKind, Formula};
use super::diagnostic::SourceError;

pub use crate::platform::MAX_FORMULA_BYTES;
/// The deepest nesting of brackets accepted.
pub const MAX_NESTING: usize = 256;
/// pest stops after this many rule calls, so that no input can make the parser backtrack for
/// minutes, whatever the grammar becomes.
const PEST_CALL_LIMIT: usize = 20_000_000;

#[derive(pest_derive::Parser)]
#[grammar = "../grammar/formula.pest"]
struct FormulaGrammar;

static PRATT: LazyLock<PrattParser<Rule>> = LazyLock::new(|| {
    PrattParser::new()
        .op(Op::infix(Rule::add, Assoc::Left) | Op::infix(Rule::sub, Assoc::Left))
        .op(Op::infix(Rule::mul, Assoc::Left)
            | Op::infix(Rule::div, Assoc::Left)
            | Op::infix(Rule::implicit, Assoc::Left))
        .op(Op::prefix(Rule::neg) | Op::prefix(Rule::pos))
        .op(Op::infix(Rule::pow, Assoc::Right))
});

/// Parses a formula. Never panics; deep or huge input gives an error, not a stack overflow.
pub fn parse(source: &str) -> Result<Formula, SourceError> {
    prescan(source)?;
    let bracketed = classify_bars(source)?;
    // The grammar recurses once per bracket level; MAX_NESTING keeps that far inside a
    // normal thread stack, so no thread of our own is needed here.
    pest::set_call_limit(NonZeroUsize::new(PEST_CALL_LIMIT));
    let mut pairs =
        FormulaGrammar::parse(Rule::formula, &bracketed).map_err(|e| translate_error(source, e))?;
    let formula = pairs
        .next()
        .expect("the formula rule always yields one pair");
    let mut sides = formula.into_inner().filter(|p| p.as_rule() == Rule::expr);
    let lhs = build_expr(sides.next().expect("grammar: formula starts with expr"))?;
    let rhs = sides.next().map(build_expr).transpose()?;
    Ok(Formula { lhs, rhs })
}

fn build_expr(pair: Pair<'_, Rule>) -> Result<Expr, SourceError> {
    fold(pair.into_inner())
}

fn fold(pairs: Pairs<'_, Rule>) -> Result<Expr, SourceError> {
    PRATT
        .map_primary(build_primary)
        .map_prefix(|op, rhs| {
            let rhs = rhs?;
            let span = op.as_span().start()..rhs.span.end;
            Ok(match op.as_rule() {
                Rule::neg => Expr::new(ExprKind::Neg(Box::new(rhs)), span),
                _ => Expr::new(rhs.kind, span),
            })
        })
        .map_infix(|lhs, op, rhs| {
            let (lhs, rhs) = (lhs?, rhs?);
            let span = lhs.span.start..rhs.span.end;
            let op = match op.as_rule() {
                Rule::add => BinOp::Add,
                Rule::sub => BinOp::Sub,
                Rule::mul | Rule::implicit => BinOp::Mul,
                Rule::div => BinOp::Div,
                Rule::pow => BinOp::Pow,
                rule => unreachable!("grammar: {rule:?} is not an infix operator"),
            };
            Ok(Expr::new(
                ExprKind::Binary(op, Box::new(lhs), Box::new(rhs)),
                span,
            ))
        })
        .parse(pairs)
}

fn build_primary(pair: Pair<'_, Rule>) -> Result<Expr, SourceError> {
    let span = pair.as_span().start()..pair.as_span().end();
    match pair.as_rule() {
        Rule::number => {
            let text = pair.as_str();
            let value: f64 = text.parse().map_err(|_| {
                SourceError::new(format!("'{text}' is not a number"), span.clone(), "here")
            })?;
            if !value.is_finite() {
                return Err(SourceError::new(
                    format!("the number {text} is too large"),
                    span,
                    "overflows a 64-bit float",
                )
                .with_hint("numbers must stay below about 1.8e308"));
            }
            Ok(Expr::new(ExprKind::Number(value), span))
        }
        Rule::ident => Ok(Expr::new(ExprKind::Ident(pair.as_str().to_string()), span)),
        Rule::paren => fold_single(pair),
        Rule::abs => {
            let inner = fold_single(pair)?;
            Ok(Expr::new(ExprKind::Abs(Box::new(inner)), span))
        }
        Rule::call => {
            let mut inner = pair.into_inner();
            let name = inner.next().expect("grammar: call starts with ident");
            let name_span = name.as_span().start()..name.as_span().end();
            let args = inner.map(build_expr).collect::<Result<Vec<_>, _>>()?;
            Ok(Expr::new(
                ExprKind::Call {
                    name: name.as_str().to_string(),
                    name_span,
                    args,
                },
                span,
            ))
        }
        Rule::expr => build_expr(pair),
        rule => unreachable!("grammar: {rule:?} is not a primary"),
    }
}

/// `( expr )` and `| expr |`: the span of the result covers the brackets.
fn fold_single(pair: Pair<'_, Rule>) -> Result<Expr, SourceError> {
    let span = pair.as_span().start()..pair.as_span().end();
    let inner = pair
        .into_inner()
        .next()
        .expect("grammar: brackets hold an expr");
    let mut expr = build_expr(inner)?;
    if matches!(expr.kind, ExprKind::Abs(_)) {
        return Ok(expr);
    }
    expr.span = span;
    Ok(expr)
}

/// Cheap checks before pest runs: size, characters, bracket balance and depth. They give
/// sharper messages than a grammar error and bound the parser's recursion.
fn prescan(source: &str) -> Result<(), SourceError> {
    if source.len() > MAX_FORMULA_BYTES {
        return Err(SourceError::new(
            format!(
                "the formula is {} bytes long; fourfold accepts at most {MAX_FORMULA_BYTES}",
                source.len()
            ),
            0..0,
            "formula starts here",
        )
        .with_hint("factor repeated parts into parameters or shorter expressions"));
    }
    if source.trim().is_empty() {
        return Err(
            SourceError::new("the formula is empty", 0..source.len(), "nothing here")
                .with_hint("type an expression such as x^2 + y^2 + z^2 + w^2 = 1"),
        );
    }
    let mut open: Vec<usize> = Vec::new();
    let mut bars = 0usize;
    for (at, c) in source.char_indices() {
        let span = at..at + c.len_utf8();
        match c {
            '(' => {
                open.push(at);
                if open.len() + bars / 2 > MAX_NESTING {
                    return Err(SourceError::new(
                        format!("brackets are nested more than {MAX_NESTING} deep"),
                        span,
                        "too deep here",
                    )
                    .with_hint("simplify the formula"));
                }
            }
            ')' => {
                if open.pop().is_none() {
                    return Err(SourceError::new("unmatched ')'", span, "no '(' opens this")
                        .with_hint("remove it, or add a '(' where the group starts"));
                }
            }
            '|' => bars += 1,
            c if c.is_ascii_alphanumeric() || c.is_whitespace() => {}
            '_' | '.' | '+' | '-' | '*' | '/' | '^' | ',' | '=' | '·' | '×' => {}
            other => {
                let hint = match other {
                    '²' => "write x^2 for a square".to_string(),
                    '³' => "write x^3 for a cube".to_string(),
                    '√' => "write sqrt(x)".to_string(),
                    'π' => "write pi".to_string(),
                    '−' => "use the ASCII minus sign '-'".to_string(),
                    '[' | ']' | '{' | '}' => "use ( and ) for grouping".to_string(),
                    _ => "formulas use x y z w, numbers, names, + - * / ^ ( ) | and =".to_string(),
                };
                // An invisible one is named by its escape (`'\u{0}'`).
                let shown = if other.is_control() {
                    other.escape_unicode().to_string()
                } else {
                    other.to_string()
                };
                return Err(SourceError::new(
                    format!("unexpected character '{shown}'"),
                    span,
                    "not part of the formula language",
                )
                .with_hint(hint));
            }
        }
    }
    if let Some(&at) = open.last() {
        return Err(
            SourceError::new("this '(' is never closed", at..at + 1, "opened here")
                .with_hint("add a ')' where the group ends"),
        );
    }
    if source.matches('=').count() > 1 {
        let second = source
            .match_indices('=')
            .nth(1)
            .map(|(i, _)| i)
            .unwrap_or(0);
        return Err(SourceError::new(
            "a formula has at most one '='",
            second..second + 1,
            "second '=' here",
        )
        .with_hint("write F = 0 or lhs = rhs"));
    }
    Ok(())
}

/// Decides which `|` opens an absolute value and which closes one, and returns the text
/// with openers as `{` and closers as `}` (same byte offsets). A bar closes when an
/// absolute value is open and an operand comes just before it; otherwise it opens. So
/// `|x||y|` is |x|·|y| and `||x| - 1|` nests.
fn classify_bars(source: &str) -> Result<String, SourceError> {
    let mut out = String::with_capacity(source.len());
    let mut open_bars: Vec<usize> = Vec::new();
    let mut after_operand = false;
    for (at, c) in source.char_indices() {
        match c {
            '|' if after_operand && !open_bars.is_empty() => {
                open_bars.pop();
                out.push('}');
                after_operand = true;
            }
            '|' => {
                open_bars.push(at);
                out.push('{');
                after_operand = false;
            }
            c if c.is_whitespace() => out.push(c),
            c => {
                after_operand = c.is_ascii_alphanumeric() || c == '_' || c == '.' || c == ')';
                out.push(c);
            }
        }
    }
    if let Some(&at) = open_bars.last() {
        return Err(SourceError::new(
            "an absolute value |…| is not closed",
            at..at + 1,
            "this '|' has no partner",
        )
        .with_hint("absolute values need a '|' on each side, as in |x - 1|"));
    }
    Ok(out)
}

fn translate_error(source: &str, error: pest::error::Error<Rule>) -> SourceError {
    use pest::error::{ErrorVariant, InputLocation};
    let at = match error.location {
        InputLocation::Pos(p) => p,
        InputLocation::Span((s, _)) => s,
    };
    if let ErrorVariant::CustomError { message } = &error.variant {
        // pest reports its call limit this way.
        return SourceError::new(
            format!("the formula is too hard to parse ({message})"),
            0..source.len(),
            "here",
        )
        .with_hint("use parentheses instead of nested |…| bars");
    }
    let rest = &source[at..];
    let next = rest.chars().next();
    let before = source[..at].trim_end();
    let previous = before.chars().last();
    let prev_span = before
        .len()
        .saturating_sub(previous.map_or(0, char::len_utf8))..before.len();
    let here = at..at + next.map_or(0, char::len_utf8);

    let run: String = rest
        .chars()
        .take_while(|c| c.is_ascii_digit() || *c == '.')
        .collect();
    if run.matches('.').count() > 1 {
        return SourceError::new(
            format!("malformed number '{run}'"),
            at..at + run.len(),
            "a number has at most one decimal point",
        )
        .with_hint("write 1.25, or put an operator between two numbers");
    }
    let operator_name = |c: char| match c {
        '^' => Some("exponent after '^'"),
        '+' => Some("operand after '+'"),
        '-' => Some("operand after '-'"),
        '*' | '·' | '×' => Some("operand after '*'"),
        '/' => Some("divisor after '/'"),
        '=' => Some("right-hand side after '='"),
        '(' => Some("expression inside '('"),
        ',' => Some("argument after ','"),
        '|' => Some("expression inside '|…|'"),
        _ => None,
    };
    let next_is_closer = matches!(next, None | Some(')') | Some(',') | Some('=') | Some('|'));
    if let Some(prev) = previous
        && (next_is_closer || next.is_some_and(|c| "+*/^·×".contains(c)))
        && let Some(what) = operator_name(prev)
    {
        {
            let (message, hint) = match prev {
                '^' => ("missing exponent", "write the power after '^', as in x^2"),
                '(' => (
                    "empty parentheses",
                    "put an expression inside, as in (x + 1)",
                ),
                _ => (
                    "missing operand",
                    "complete the expression or remove the operator",
                ),
            };
            return SourceError::new(
                message,
                prev_span,
                format!("expected an {what}")
                    .replace("an divisor", "a divisor")
                    .replace("an right", "a right"),
            )
            .with_hint(hint);
        }
    }
    match next {
        None => SourceError::new(
            "the formula ends too early",
            source.len()..source.len(),
            "expected more here",
        ),
        Some(',') => SourceError::new(
            "unexpected ','",
            here,
            "commas only separate a function's arguments",
        )
        .with_hint("write min(a, b), max(a, b), pow(a, b) or atan2(y, x)"),
        Some(')') => SourceError::new("unexpected ')'", here, "expected an operand before it"),
        Some('=') => SourceError::new("unexpected '='", here, "expected an operand before it"),
        Some(c) if "+*/^·×".contains(c) => SourceError::new(
            format!("unexpected '{c}'"),
            here,
            "expected a number, variable or '(' before this operator",
        ),
        Some('.') => SourceError::new("malformed number", here, "a '.' needs digits after it")
            .with_hint("write 0.5 or .5"),
        Some(c) => SourceError::new(
            format!("unexpected '{c}'"),
            here,
            "expected an operator, a number, a name or '('",
        ),
    }
}

/// What a stretch of formula text is, for syntax colouring.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TokenKind {
    Number,
    /// x, y, z or w.
    Variable,
    /// A function name in a call: `sin` in `sin(x)`.
    Function,
    /// A named constant: pi, e, tau.
    Constant,
    /// Any other name: a parameter with a slider.
    Parameter,
    Operator,
    Bracket,
}

/// A coloured stretch: byte range of the source and its kind.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Token {
    pub start: usize,
    pub end: usize,
    pub kind: TokenKind,
}

/// The tokens of `source` as the grammar sees them, in order. When the formula does not parse,
/// the tokens of the longest prefix that does are returned and the rest is left uncoloured
/// (the editor underlines the error span from [`parse`]).
pub fn tokens(source: &str) -> Vec<Token> {
    if prescan(source).is_err() {
        return Vec::new();
    }
    let Ok(bracketed) = classify_bars(source) else {
        return Vec::new();
    };
    pest::set_call_limit(NonZeroUsize::new(PEST_CALL_LIMIT));
    let Ok(mut pairs) = FormulaGrammar::parse(Rule::formula, &bracketed) else {
        return Vec::new();
    };
    let Some(formula) = pairs.next() else {
        return Vec::new();
    };
    let mut out = Vec::new();
    let mut brackets = Vec::new();
    for pair in formula.into_inner().flatten() {
        let span = pair.as_span();
        let kind = match pair.as_rule() {
            Rule::number => TokenKind::Number,
            Rule::ident => {
                let name = pair.as_str();
                if matches!(name, "x" | "y" | "z" | "w") {
                    TokenKind::Variable
                } else if crate::ops::CONSTANTS.iter().any(|(c, _)| *c == name) {
                    TokenKind::Constant
                } else {
                    TokenKind::Parameter
                }
            }
            Rule::call => {
                // The call's name is its first inner ident; mark it before the walk reaches it.
                if let Some(name) = pair.clone().into_inner().next() {
                    let s = name.as_span();
                    out.push(Token {
                        start: s.start(),
                        end: s.end(),
                        kind: TokenKind::Function,
                    });
                }
                // Its brackets: the '(' after the name and the final ')'.
                let name_end = pair.clone().into_inner().next().map(|n| n.as_span().end());
                if let Some(open) = name_end.and_then(|e| bracketed[e..].find('(').map(|i| e + i)) {
                    brackets.push(open);
                }
                brackets.push(span.end() - 1);
                continue;
            }
            Rule::paren | Rule::abs => {
                brackets.push(span.start());
                brackets.push(span.end() - 1);
                continue;
            }
            Rule::add
            | Rule::sub
            | Rule::mul
            | Rule::div
            | Rule::pow
            | Rule::neg
            | Rule::pos
            | Rule::equals => TokenKind::Operator,
            _ => continue,
        };
        // A call's name was already marked as a function.
        if out
            .last()
            .is_some_and(|t: &Token| t.start == span.start() && t.kind == TokenKind::Function)
        {
            continue;
        }
        out.push(Token {
            start: span.start(),
            end: span.end(),
            kind,
        });
    }
    for at in brackets {
        let len = bracketed[at..].chars().next().map_or(1, char::len_utf8);
        out.push(Token {
            start: at,
            end: at + len,
            kind: TokenKind::Bracket,
        });
    }
    // Commas in calls are left plain. Sort by position; spans never overlap.
    out.sort_by_key(|t| t.start);
    out
}
