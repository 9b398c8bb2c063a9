// F, its gradient and both at once as an interpreter of the formula's tapes (binding 7):
// one shader, compiled once, that draws any formula's plain pixels, so that an edit's first
// frames need not wait for the driver to compile the formula's own shader (which replaces
// this one once it is ready). It computes what the generated functions compute, operation
// for operation (see tapes.rs; integer powers as their multiplications): each instruction
// is four words, its operation, its operands (registers, or a constant's bits, a
// coordinate's or a parameter's index) and the register it writes; each register carries
// the undefined flag of the generated code's `n{i}`.
//
// Words 0-5 of binding 7 head the three tapes (F, the gradient, both), two words each:
// (first instruction, end, register of output 0, 0) and (registers of outputs 1 to 4).
@group(0) @binding(7) var<storage, read> program: array<vec4<u32>>;

//@FOURFOLD_REGISTERS@
var<private> registers: array<f32, FF_REGISTERS>;
var<private> flags: array<bool, FF_REGISTERS>;

// Runs tape `t` (0 F, 1 the gradient, 2 both) at `p`, leaving its values in `registers`:
// FF_UNROLL instructions a round, since llvmpipe allows an invocation 65 535 rounds of
// loops in all, and one instruction a round would spend them on a few hundred samples.
fn ff_run(t: u32, p: vec4<f32>) {
    let head = program[2u * t];
    var i = head.x;
    loop {
        if (i >= head.y) {
            break;
        }
//@FOURFOLD_STEPS@
        i = i + FF_UNROLL;
    }
}

// Instruction i of a tape that ends before `end`, at `p` (nothing at or past the end).
fn ff_step(i: u32, end: u32, p: vec4<f32>) {
    if (i < end) {
        let op = program[i];
        let ra = min(op.y, FF_REGISTERS - 1u);
        let rb = min(op.z, FF_REGISTERS - 1u);
        let a = registers[ra];
        let b = registers[rb];
        let na = flags[ra];
        let nb = flags[rb];
        var v = 0.0;
        var n = false;
        switch op.x {
            case 0u: {
                v = bitcast<f32>(op.y);
            }
            case 1u: {
                v = p[op.y & 3u];
            }
            case 2u: {
                v = ff_param(op.y);
            }
            case 3u: {
                v = a;
                n = na;
            }
            case 4u: {
                v = select(1.0 / a, ff_nan(), b == 0.0);
                n = na | nb;
            }
//@FOURFOLD_OPS@
            default: {
                v = ff_nan();
            }
        }
        let out = min(op.w, FF_REGISTERS - 1u);
        registers[out] = v;
        flags[out] = n;
    }
}

// Output `k` of the tape run last, whose head is `head`: NaN where its flag is set.
fn ff_output(t: u32, k: u32) -> f32 {
    let head = program[2u * t];
    let outs = program[2u * t + 1u];
    let r = min(select(outs[max(k, 1u) - 1u], head.z, k == 0u), FF_REGISTERS - 1u);
    return select(registers[r], ff_nan(), flags[r]);
}

fn ff_f(p: vec4<f32>) -> f32 {
    ff_run(0u, p);
    return ff_output(0u, 0u);
}

fn ff_grad(p: vec4<f32>) -> vec4<f32> {
    ff_run(1u, p);
    return vec4<f32>(ff_output(1u, 0u), ff_output(1u, 1u), ff_output(1u, 2u), ff_output(1u, 3u));
}

fn ff_f_grad(p: vec4<f32>) -> FGrad {
    ff_run(2u, p);
    let g = vec4<f32>(ff_output(2u, 1u), ff_output(2u, 2u), ff_output(2u, 3u), ff_output(2u, 4u));
    return FGrad(ff_output(2u, 0u), g);
}
