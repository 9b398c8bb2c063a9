//! The interpreting shader: the ray-casting template with F, ∇F and both at once computed
//! by an interpreter of the formula's tapes (`templates/raycast/interpret.wgsl`), read from
//! a storage buffer. It is the same for every formula, so it is compiled once per run, and
//! draws a new formula's plain frames while the driver compiles the formula's own shader.
//! It has no certified pixels: those need the formula's shader.

use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::fmt::Write as _;

use crate::eval::{Instr, Tape};
use crate::expr::{BinaryOp, UnaryOp};
use crate::formula::CompiledFormula;
use crate::ops::{BINARY, UNARY};

use super::source::{CodegenError, Shader, plain_template, splice, validate};

/// The registers the interpreter holds (each a float and a flag, per pixel): a formula whose
/// tapes need more draws with its own shader only. The examples need 5 to 11.
pub const REGISTERS: usize = 32;

/// Instructions the interpreter runs a round of its loop (see `ff_run`).
const UNROLL: u32 = 8;

const REGISTERS_MARKER: &str = "//@FOURFOLD_REGISTERS@";
const STEPS_MARKER: &str = "//@FOURFOLD_STEPS@";
const OPS_MARKER: &str = "//@FOURFOLD_OPS@";
const INTERPRETER: &str = include_str!("../../../templates/raycast/interpret.wgsl");

/// Operation codes: five fixed ones, then a unary operation's is UNARY_CODE + its row, a
/// binary one's BINARY_CODE + its row (the cases of `ff_step` in interpret.wgsl).
const CONST: u32 = 0;
const VAR: u32 = 1;
const PARAM: u32 = 2;
/// b = a (the first factor of an integer power).
const COPY: u32 = 3;
/// 1 / a, NaN where b (the base of a negative integer power) is 0.
const INVERSE: u32 = 4;
const UNARY_CODE: u32 = 16;
const BINARY_CODE: u32 = 64;
const MUL: u32 = BINARY_CODE + BinaryOp::Mul as u32;

/// Why a formula cannot be drawn by the interpreter (it is drawn by its own shader alone).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum InterpretError {
    #[error("its tapes need {0} registers; the interpreting shader holds {REGISTERS}")]
    TooManyRegisters(usize),
}

/// The interpreting shader, validated by naga.
pub fn interpreter() -> Result<Shader, CodegenError> {
    // Arithmetic keeps a NaN in hardware, so only its operands' flags pass on; every other
    // operation is a builtin or a select, and its operands' bits are tested (tapes.rs).
    let mut cases = String::new();
    let mut case = |code: u32, value: String, flag: &str| {
        let _ = writeln!(
            cases,
            "            case {code}u: {{\n                v = {value};\n                n = {flag};\n            }}",
        );
    };
    for spec in &UNARY {
        let flag = match spec.op {
            UnaryOp::Neg => "na",
            _ => "na | ff_undefined(a)",
        };
        case(UNARY_CODE + spec.op as u32, (spec.wgsl)("a"), flag);
    }
    for spec in &BINARY {
        let flag = match spec.op {
            BinaryOp::Add | BinaryOp::Sub | BinaryOp::Mul => "na | nb",
            _ => "na | nb | ff_undefined(a) | ff_undefined(b)",
        };
        case(BINARY_CODE + spec.op as u32, (spec.wgsl)("a", "b"), flag);
    }
    let steps: Vec<String> = (0..UNROLL)
        .map(|k| format!("        ff_step(i + {k}u, head.y, p);"))
        .collect();
    let steps = steps.join("\n");
    let functions = INTERPRETER
        .replace(
            REGISTERS_MARKER,
            &format!("const FF_REGISTERS: u32 = {REGISTERS}u;\nconst FF_UNROLL: u32 = {UNROLL}u;"),
        )
        .replace(STEPS_MARKER, &steps)
        .replace(OPS_MARKER, cases.trim_end());
    let source = splice(&plain_template(), &functions, "", "", "");
    let module = validate(&source)?;
    Ok(Shader {
        source,
        module,
        interprets: true,
        constants: Vec::new(),
    })
}

/// The interpreting shader's binding 7 for `formula`: the heads of its three tapes, then
/// their instructions.
pub fn program(formula: &CompiledFormula) -> Result<Vec<[u32; 4]>, InterpretError> {
    let tapes = [&formula.tape_f, &formula.tape_grad, &formula.tape_all];
    let mut words = vec![[0u32; 4]; 2 * tapes.len()];
    for (t, tape) in tapes.into_iter().enumerate() {
        let start = words.len() as u32;
        let outputs = encode_tape(tape, &mut words)?;
        let out = |k: usize| outputs.get(k).copied().unwrap_or(0);
        words[2 * t] = [start, words.len() as u32, out(0), 0];
        words[2 * t + 1] = [out(1), out(2), out(3), out(4)];
    }
    Ok(words)
}

/// Appends `tape`'s instructions to `words` with registers allocated, and returns the
/// registers of its outputs. (Public for the tests: one tape's registers.)
pub fn encode_tape(tape: &Tape, words: &mut Vec<[u32; 4]>) -> Result<Vec<u32>, InterpretError> {
    let instrs = tape.instrs();
    let order = schedule(tape);
    // The position in `order` after which each value is read no more.
    let mut last_use = vec![0usize; instrs.len()];
    for (at, &i) in order.iter().enumerate() {
        last_use[i] = last_use[i].max(at);
        for a in operands(instrs[i]) {
            last_use[a as usize] = at;
        }
    }
    for &o in tape.outputs() {
        last_use[o as usize] = usize::MAX;
    }
    let mut register = vec![u32::MAX; instrs.len()];
    let mut registers = Registers::default();
    for (at, &i) in order.iter().enumerate() {
        let instr = instrs[i];
        let reg = |a: u32| register[a as usize];
        let mut dead: Vec<u32> = operands(instr)
            .filter(|&a| last_use[a as usize] == at)
            .map(reg)
            .collect();
        dead.dedup();
        let out = if let Instr::Powi(a, n) = instr {
            // An integer power reads its operand to its last multiplication: it takes its
            // registers first.
            let out = registers.take();
            power(words, &mut registers, reg(a), n, out);
            registers.give(dead);
            out
        } else {
            let [code, a, b] = match instr {
                Instr::Const(v) => [CONST, (v as f32).to_bits(), 0],
                Instr::Var(axis) => [VAR, u32::from(axis & 3), 0],
                Instr::Param(p) => [PARAM, p, 0],
                Instr::Unary(op, a) => [UNARY_CODE + op as u32, reg(a), 0],
                Instr::Binary(op, a, b) => [BINARY_CODE + op as u32, reg(a), reg(b)],
                Instr::Powi(..) => unreachable!("written above"),
            };
            // Operands read here for the last time give their registers back before the
            // result takes one (the interpreter reads both before it writes).
            registers.give(dead);
            let out = registers.take();
            words.push([code, a, b, out]);
            out
        };
        register[i] = out;
        if last_use[i] == at {
            registers.give([out]);
        }
    }
    if registers.used as usize > REGISTERS {
        return Err(InterpretError::TooManyRegisters(registers.used as usize));
    }
    Ok(tape
        .outputs()
        .iter()
        .map(|&o| register[o as usize])
        .collect())
}

/// Registers handed out lowest first, and how many were ever used.
#[derive(Default)]
struct Registers {
    free: BinaryHeap<Reverse<u32>>,
    used: u32,
}

impl Registers {
    fn take(&mut self) -> u32 {
        self.free.pop().map_or_else(
            || {
                self.used += 1;
                self.used - 1
            },
            |Reverse(r)| r,
        )
    }

    fn give(&mut self, registers: impl IntoIterator<Item = u32>) {
        self.free.extend(registers.into_iter().map(Reverse));
    }
}

/// `out` = the value in register `x` to the power n, as the generated code computes it
/// (tapes.rs `powi_lets`): a product of |n| copies up to 4, else square and multiply, then
/// 1 / that for a negative n. As multiplications, not a loop in the shader: llvmpipe
/// counts a loop's rounds against its budget at every instruction, whichever it runs.
fn power(words: &mut Vec<[u32; 4]>, registers: &mut Registers, x: u32, n: i32, out: u32) {
    let k = n.unsigned_abs();
    if k == 0 {
        words.push([CONST, 1f32.to_bits(), 0, out]);
        return;
    }
    if k <= 4 {
        words.push([COPY, x, 0, out]);
        for _ in 1..k {
            words.push([MUL, out, x, out]);
        }
    } else {
        let square = registers.take();
        let (mut factor, mut first, mut bits) = (x, true, k);
        loop {
            if bits & 1 == 1 {
                words.push(if first {
                    [COPY, factor, 0, out]
                } else {
                    [MUL, out, factor, out]
                });
                first = false;
            }
            bits >>= 1;
            if bits == 0 {
                break;
            }
            words.push([MUL, factor, factor, square]);
            factor = square;
        }
        registers.give([square]);
    }
    if n < 0 {
        words.push([INVERSE, out, x, out]);
    }
}

/// The order the interpreter runs `tape`'s instructions in: the tape's, but each one of its
/// uniform prefix (constants, parameters and what is made of them alone) just before its
/// first use, so that it holds no register until then.
fn schedule(tape: &Tape) -> Vec<usize> {
    let instrs = tape.instrs();
    let mut placed = vec![false; instrs.len()];
    let mut order = Vec::with_capacity(instrs.len());
    let users =
        (tape.uniform_len()..instrs.len()).chain(tape.outputs().iter().map(|&o| o as usize));
    for i in users {
        // (An output is placed already unless it is uniform.)
        if placed[i] {
            continue;
        }
        // i and the uniform values it needs that are not placed yet, in the tape's order
        // (which is a topological one).
        let mut needed = vec![i];
        let mut stack = vec![i];
        placed[i] = true;
        while let Some(j) = stack.pop() {
            for a in operands(instrs[j]).map(|a| a as usize) {
                if !placed[a] {
                    placed[a] = true;
                    needed.push(a);
                    stack.push(a);
                }
            }
        }
        needed.sort_unstable();
        order.extend(needed);
    }
    order
}

/// The values an instruction reads.
fn operands(instr: Instr) -> impl Iterator<Item = u32> {
    let (a, b) = match instr {
        Instr::Const(_) | Instr::Var(_) | Instr::Param(_) => (None, None),
        Instr::Powi(a, _) | Instr::Unary(_, a) => (Some(a), None),
        Instr::Binary(_, a, b) => (Some(a), Some(b)),
    };
    a.into_iter().chain(b)
}
