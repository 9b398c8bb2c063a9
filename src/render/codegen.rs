//! WGSL for F, ∇F, and both at once (`ff_f_grad`, for the march's step bound), spliced into
//! `templates/raycast.wgsl` at its markers and validated by naga before any pipeline sees it.
//!
//! One `let` per tape instruction, in order: shared subexpressions are computed once and a
//! deep formula never nests deeply. Integer powers become multiplications (square and
//! multiply). Parameters are read from the frame's settings (binding 0), so changing one
//! needs no new shader.
//!
//! Undefined values follow the CPU point evaluator: sqrt/ln/asin/acos outside their domain,
//! division by 0, a negative or zero base of a real power with an exponent that needs a
//! positive one — all give NaN (from the uniform, `ff_nan()`), and a NaN sample never makes a
//! sign change, so no root is drawn there. Constants that do not fit in f32 are clamped to
//! ±f32::MAX so every literal is finite.

use std::fmt::Write as _;

use crate::eval::{Instr, Tape};
use crate::expr::{BinaryOp, UnaryOp};
use crate::formula::CompiledFormula;

/// The ray-casting template.
pub const TEMPLATE: &str = include_str!("../../templates/raycast.wgsl");
const F_MARKER: &str = "//@FOURFOLD_F@";
const GRAD_MARKER: &str = "//@FOURFOLD_GRAD@";
const F_GRAD_MARKER: &str = "//@FOURFOLD_F_GRAD@";
const INTERVAL_MARKER: &str = "//@FOURFOLD_INTERVAL@";
/// Rigorous interval arithmetic in WGSL (certified pixels), spliced in before `ff_f_box`.
pub const INTERVAL_LIBRARY: &str = include_str!("../../templates/interval.wgsl");

/// The most parameters a shader can read (the uniform holds 16 × vec4).
pub const MAX_PARAMS: usize = 64;

/// A generated shader that naga rejected: a bug in fourfold, reported rather than crashed on.
#[derive(Debug, Clone, thiserror::Error)]
pub enum CodegenError {
    #[error("the formula has {0} parameters; the shader holds at most {MAX_PARAMS}")]
    TooManyParams(usize),
    #[error("internal error: the generated WGSL does not parse: {0}")]
    Parse(String),
    #[error("internal error: the generated WGSL does not validate: {0}")]
    Validate(String),
}

/// A complete, validated shader.
#[derive(Debug, Clone)]
pub struct Shader {
    pub source: String,
    pub module: naga::Module,
}

/// Generates and validates the ray-casting shader for `formula`.
pub fn generate(formula: &CompiledFormula) -> Result<Shader, CodegenError> {
    if formula.params.len() > MAX_PARAMS {
        return Err(CodegenError::TooManyParams(formula.params.len()));
    }
    let f = tape_function(&POINT, "ff_f", "f32", &formula.tape_f, |v| v[0].clone());
    let grad_tape = Tape::new(&formula.graph, &formula.gradient);
    let grad = tape_function(&POINT, "ff_grad", "vec4<f32>", &grad_tape, |v| {
        format!("vec4<f32>({}, {}, {}, {})", v[0], v[1], v[2], v[3])
    });
    let f_grad = tape_function(&POINT, "ff_f_grad", "FGrad", &formula.tape_all, |v| {
        format!(
            "FGrad({}, vec4<f32>({}, {}, {}, {}))",
            v[0], v[1], v[2], v[3], v[4]
        )
    });
    let interval = format!(
        "{INTERVAL_LIBRARY}\n{}\n\n{}",
        tape_function(&INTERVAL, "ff_f_box", "vec2<f32>", &formula.tape_f, |v| v
            [0]
        .clone()),
        tape_function(
            &INTERVAL,
            "ff_f_grad_box",
            "IvFGrad",
            &formula.tape_all,
            |v| format!("IvFGrad({}, {}, {}, {}, {})", v[0], v[1], v[2], v[3], v[4])
        )
    );
    let source = TEMPLATE
        .replace(F_MARKER, &f)
        .replace(GRAD_MARKER, &grad)
        .replace(F_GRAD_MARKER, &f_grad)
        .replace(INTERVAL_MARKER, &interval);
    let module = validate(&source)?;
    Ok(Shader { source, module })
}

/// Parses and validates WGSL with naga (all capabilities a WebGPU device has).
pub fn validate(source: &str) -> Result<naga::Module, CodegenError> {
    let module = naga::front::wgsl::parse_str(source)
        .map_err(|e| CodegenError::Parse(e.emit_to_string(source)))?;
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::default(),
    )
    .validate(&module)
    .map_err(|e| CodegenError::Validate(e.emit_to_string(source)))?;
    Ok(module)
}

/// How a tape becomes WGSL: in f32 at a point, or as rigorous intervals over a box.
struct Flavour {
    /// The parameters after the function's name.
    params: &'static str,
    /// An instruction's value, as an expression of earlier `s{i}` (all but Powi).
    expression: fn(Instr) -> String,
    /// `let s{i} = s{a}^n`, through helper lets as needed.
    powi_lets: fn(&mut String, usize, u32, i32),
}

const POINT: Flavour = Flavour {
    params: "p: vec4<f32>",
    expression,
    powi_lets,
};

/// With the operations of `templates/interval.wgsl` (see docs/method.md §5.9).
const INTERVAL: Flavour = Flavour {
    params: "lo: vec4<f32>, hi: vec4<f32>",
    expression: interval_expression,
    powi_lets: interval_powi_lets,
};

/// The WGSL function `name` computing `tape` in `flavour`: one `let` per instruction, then
/// the return of `result` of the outputs, of type `ret`.
fn tape_function(
    flavour: &Flavour,
    name: &str,
    ret: &str,
    tape: &Tape,
    result: impl Fn(&[String]) -> String,
) -> String {
    let mut body = String::new();
    let _ = writeln!(body, "fn {name}({}) -> {ret} {{", flavour.params);
    for (i, instr) in tape.instrs().iter().enumerate() {
        if let Instr::Powi(a, n) = *instr {
            (flavour.powi_lets)(&mut body, i, a, n);
        } else {
            let _ = writeln!(body, "    let s{i} = {};", (flavour.expression)(*instr));
        }
    }
    let outputs: Vec<String> = tape.outputs().iter().map(|o| format!("s{o}")).collect();
    let _ = writeln!(body, "    return {};", result(&outputs));
    body.push('}');
    body
}

/// An interval holding the real number `v`: the point where f32 holds it exactly, else its
/// nearest f32 stepped an ulp either way, or a half-line beyond the library's largest bound.
fn interval_constant(v: f64) -> String {
    const LARGE: f64 = 2305843009213693952.0; // IV_LARGE, 2^61
    if v.is_nan() {
        "IV_EMPTY".into()
    } else if v > LARGE {
        "vec2<f32>(IV_LARGE, IV_BIG)".into()
    } else if v < -LARGE {
        "vec2<f32>(-IV_BIG, -IV_LARGE)".into()
    } else if f64::from(v as f32) == v && (v == 0.0 || v.abs() >= 2f64.powi(-125)) {
        // Exact in f32, and no subnormal a device may flush: a point.
        format!("vec2<f32>({})", literal(v))
    } else {
        format!("iv_around({})", literal(v))
    }
}

fn interval_expression(instr: Instr) -> String {
    let s = |i: u32| format!("s{i}");
    match instr {
        Instr::Const(v) => interval_constant(v),
        Instr::Var(a) => {
            let c = ["x", "y", "z", "w"][a as usize & 3];
            format!("vec2<f32>(lo.{c}, hi.{c})")
        }
        Instr::Param(i) => format!("iv_around(ff_param({i}u))"),
        Instr::Powi(..) => unreachable!("integer powers are written by interval_powi_lets"),
        Instr::Unary(op, a) => {
            let name = match op {
                UnaryOp::Neg => "iv_neg",
                UnaryOp::Abs => "iv_abs",
                UnaryOp::Sqrt => "iv_sqrt",
                UnaryOp::Cbrt => "iv_cbrt",
                UnaryOp::Exp => "iv_exp",
                UnaryOp::Ln => "iv_ln",
                UnaryOp::Sin => "iv_sin",
                UnaryOp::Cos => "iv_cos",
                UnaryOp::Tan => "iv_tan",
                UnaryOp::Asin => "iv_asin",
                UnaryOp::Acos => "iv_acos",
                UnaryOp::Atan => "iv_atan",
                UnaryOp::Sinh => "iv_sinh",
                UnaryOp::Cosh => "iv_cosh",
                UnaryOp::Tanh => "iv_tanh",
                UnaryOp::Sign => "iv_sign",
                UnaryOp::Step => "iv_step",
            };
            format!("{name}({})", s(a))
        }
        Instr::Binary(op, a, b) => {
            let name = match op {
                BinaryOp::Add => "iv_add",
                BinaryOp::Sub => "iv_sub",
                BinaryOp::Mul => "iv_mul",
                BinaryOp::Div => "iv_div",
                BinaryOp::Pow => "iv_pow",
                BinaryOp::Min => "iv_min",
                BinaryOp::Max => "iv_max",
                BinaryOp::Atan2 => "iv_atan2",
            };
            format!("{name}({}, {})", s(a), s(b))
        }
    }
}

/// `let s{i} = s{a}^n` in intervals: square and multiply (squares through `iv_sqr`, never
/// negative), and 1 / x^|n| for a negative n.
fn interval_powi_lets(body: &mut String, i: usize, a: u32, n: i32) {
    let mut result: Option<String> = None;
    let mut square = format!("s{a}");
    let mut bits = n.unsigned_abs();
    let mut j = 0;
    while bits > 0 {
        if bits & 1 == 1 {
            result = Some(match result {
                None => square.clone(),
                Some(r) => {
                    let next = format!("s{i}_m{j}");
                    let _ = writeln!(body, "    let {next} = iv_mul({r}, {square});");
                    next
                }
            });
        }
        bits >>= 1;
        if bits > 0 {
            let next = format!("s{i}_q{j}");
            let _ = writeln!(body, "    let {next} = iv_sqr({square});");
            square = next;
        }
        j += 1;
    }
    let positive = result.unwrap_or_else(|| "vec2<f32>(1.0)".into());
    let value = if n < 0 {
        format!("iv_div(vec2<f32>(1.0), {positive})")
    } else {
        positive
    };
    let _ = writeln!(body, "    let s{i} = {value};");
}

/// A finite f32 literal.
fn literal(v: f64) -> String {
    let v = if v.is_nan() {
        return "ff_nan()".into();
    } else {
        v.clamp(-f64::from(f32::MAX), f64::from(f32::MAX)) as f32
    };
    let text = format!("{v:?}");
    let text = if text.contains(['.', 'e']) {
        text
    } else {
        format!("{text}.0")
    };
    if v < 0.0 { format!("({text})") } else { text }
}

fn expression(instr: Instr) -> String {
    let s = |i: u32| format!("s{i}");
    match instr {
        Instr::Const(v) => format!("f32({})", literal(v)),
        Instr::Var(a) => format!("p.{}", ["x", "y", "z", "w"][a as usize]),
        Instr::Param(i) => format!("ff_param({i}u)"),
        Instr::Powi(..) => unreachable!("integer powers are written by powi_lets"),
        Instr::Unary(op, a) => {
            let a = s(a);
            match op {
                UnaryOp::Neg => format!("-{a}"),
                UnaryOp::Abs => format!("abs({a})"),
                UnaryOp::Sqrt => format!("select(sqrt({a}), ff_nan(), {a} < 0.0)"),
                UnaryOp::Cbrt => format!("sign({a}) * pow(abs({a}), 1.0 / 3.0)"),
                UnaryOp::Exp => format!("exp({a})"),
                UnaryOp::Ln => format!("select(log({a}), ff_nan(), {a} <= 0.0)"),
                UnaryOp::Sin => format!("sin({a})"),
                UnaryOp::Cos => format!("cos({a})"),
                UnaryOp::Tan => format!("tan({a})"),
                UnaryOp::Asin => format!("select(asin({a}), ff_nan(), abs({a}) > 1.0)"),
                UnaryOp::Acos => format!("select(acos({a}), ff_nan(), abs({a}) > 1.0)"),
                UnaryOp::Atan => format!("atan({a})"),
                UnaryOp::Sinh => format!("sinh({a})"),
                UnaryOp::Cosh => format!("cosh({a})"),
                UnaryOp::Tanh => format!("tanh({a})"),
                UnaryOp::Sign => format!("sign({a})"),
                UnaryOp::Step => {
                    format!("select(select(0.0, 1.0, {a} > 0.0), 0.5, {a} == 0.0)")
                }
            }
        }
        Instr::Binary(op, a, b) => {
            let (a, b) = (s(a), s(b));
            match op {
                BinaryOp::Add => format!("{a} + {b}"),
                BinaryOp::Sub => format!("{a} - {b}"),
                BinaryOp::Mul => format!("{a} * {b}"),
                BinaryOp::Div => format!("select({a} / {b}, ff_nan(), {b} == 0.0)"),
                BinaryOp::Pow => format!(
                    "select(select(pow({a}, {b}), 1.0, {b} == 0.0), ff_nan(), {a} < 0.0 || ({a} == 0.0 && {b} < 0.0))"
                ),
                BinaryOp::Min => format!("min({a}, {b})"),
                BinaryOp::Max => format!("max({a}, {b})"),
                BinaryOp::Atan2 => format!("atan2({a}, {b})"),
            }
        }
    }
}

/// `let s{i} = s{a}^n` as multiplications: square and multiply, one `let` per square.
fn powi_lets(body: &mut String, i: usize, a: u32, n: i32) {
    let k = n.unsigned_abs();
    let x = format!("s{a}");
    let positive = if k <= 4 {
        vec![x.as_str(); k as usize].join(" * ")
    } else {
        let mut factors = Vec::new();
        let mut square = x.clone();
        let mut bits = k;
        let mut j = 0;
        while bits > 0 {
            if bits & 1 == 1 {
                factors.push(square.clone());
            }
            bits >>= 1;
            if bits > 0 {
                let next = format!("s{i}_{j}");
                let _ = writeln!(body, "    let {next} = {square} * {square};");
                square = next;
                j += 1;
            }
        }
        factors.join(" * ")
    };
    let value = if n < 0 {
        format!("select(1.0 / ({positive}), ff_nan(), {x} == 0.0)")
    } else {
        format!("({positive})")
    };
    let _ = writeln!(body, "    let s{i} = {value};");
}
