// fourfold's rigorous interval arithmetic in WGSL: the enclosures behind certified pixels
// (docs/method.md §5.9, with the error model of each operation and the WGSL spec's
// sections it rests on). fourfold splices this into the ray caster, followed by the
// generated `ff_f_box`, which runs F's tape over a box with these operations.
//
// An interval is a vec2<f32> (lo, hi). WGSL has no rounding modes and its + - * may round
// either way, so every computed bound is stepped outward by the operation's error through
// its bits (`iv_down`, `iv_up`): integer operations that no compiler may fold into the
// float arithmetic. Bounds are kept within ±IV_BIG, and ±IV_BIG itself stands for ±inf
// (a WGSL implementation may assume no infinity or NaN ever occurs, so none is made);
// an empty interval (F undefined on the whole box: sqrt or ln of negatives) is lo > hi.
//
// The operations have no branches: each computes its bounds and then selects the empty or
// unbounded answer. The certified shader inlines hundreds of them, and SwiftShader (the
// page's software WebGPU) compiled their early returns for minutes and gigabytes.

const IV_BIG: f32 = 4611686018427387904.0; // 2^62: a product of two finite bounds stays finite
const IV_LARGE: f32 = 2305843009213693952.0; // 2^61: the largest finite bound kept
const IV_TINY: f32 = 2.35098870164457501594e-38; // 2^-125: below it, subnormals may flush
const IV_EMPTY: vec2<f32> = vec2<f32>(4611686018427387904.0, -4611686018427387904.0);
const IV_WHOLE: vec2<f32> = vec2<f32>(-4611686018427387904.0, 4611686018427387904.0);

// Enclosures of F and of its gradient over a box (ff_f_grad_box).
struct IvFGrad {
    f: vec2<f32>,
    gx: vec2<f32>,
    gy: vec2<f32>,
    gz: vec2<f32>,
    gw: vec2<f32>,
}

// Set once an operation may make F discontinuous or unbounded on the box (division by an
// interval holding 0, a bound at ±inf, ...): a sign change there proves no root.
var<private> iv_jump: bool;

// x stepped n ulps toward -inf; a bound within ±2^-125 (a subnormal or 0, which an
// implementation may flush to 0) becomes -2^-125.
fn iv_down_n(x: f32, n: u32) -> f32 {
    let b = bitcast<u32>(x);
    let stepped = bitcast<f32>(select(b + n, b - n, x > 0.0));
    return select(stepped, -IV_TINY, abs(x) < IV_TINY);
}

fn iv_up_n(x: f32, n: u32) -> f32 {
    return -iv_down_n(-x, n);
}

fn iv_down(x: f32) -> f32 {
    return iv_down_n(x, 1u);
}

fn iv_up(x: f32) -> f32 {
    return iv_up_n(x, 1u);
}

fn iv_down4(x: vec4<f32>) -> vec4<f32> {
    let b = bitcast<vec4<u32>>(x);
    let stepped = bitcast<vec4<f32>>(select(b + 1u, b - 1u, x > vec4<f32>(0.0)));
    return select(stepped, vec4<f32>(-IV_TINY), abs(x) < vec4<f32>(IV_TINY));
}

fn iv_up4(x: vec4<f32>) -> vec4<f32> {
    return -iv_down4(-x);
}

fn iv_is_empty(a: vec2<f32>) -> bool {
    return a.x > a.y;
}

// Whether a bound is at ±inf (the interval is unbounded on that side).
fn iv_unbounded(a: vec2<f32>) -> bool {
    return (a.x <= -IV_BIG) | (a.y >= IV_BIG);
}

// The bounds brought back within ±IV_LARGE (widening only), with ±IV_BIG for ±inf; an
// unbounded result sets iv_jump (F's continuity is then not known). Where `none` says an
// operand was empty: the empty interval, flagging nothing.
fn iv_keep_or_empty(lo: f32, hi: f32, none: bool) -> vec2<f32> {
    let r = vec2<f32>(clamp(lo, -IV_BIG, IV_LARGE), clamp(hi, -IV_LARGE, IV_BIG));
    iv_jump = iv_jump | (iv_unbounded(r) & !none);
    return select(r, IV_EMPTY, none);
}

// An operand stood in by a harmless one (1) where the result will be empty anyway, so
// that the operation's arithmetic there makes no infinity and flags no jump.
fn iv_or_one(a: vec2<f32>, none: bool) -> vec2<f32> {
    return select(a, vec2<f32>(1.0), none);
}

// A value known only to f32's rounding to nearest (a parameter): within half an ulp.
fn iv_around(x: f32) -> vec2<f32> {
    return vec2<f32>(iv_down(x), iv_up(x));
}

fn iv_add(a: vec2<f32>, b: vec2<f32>) -> vec2<f32> {
    var lo = select(iv_down(a.x + b.x), -IV_BIG, (a.x <= -IV_BIG) | (b.x <= -IV_BIG));
    var hi = select(iv_up(a.y + b.y), IV_BIG, (a.y >= IV_BIG) | (b.y >= IV_BIG));
    // (A sum of terms >= 0 is >= 0: stepping a zero sum down would put sqrt(x^2 + y^2) at
    // the edge of its domain.)
    lo = select(lo, max(lo, 0.0), (a.x >= 0.0) & (b.x >= 0.0));
    hi = select(hi, min(hi, 0.0), (a.y <= 0.0) & (b.y <= 0.0));
    return iv_keep_or_empty(lo, hi, iv_is_empty(a) | iv_is_empty(b));
}

fn iv_neg(a: vec2<f32>) -> vec2<f32> {
    return vec2<f32>(-a.y, -a.x);
}

fn iv_sub(a: vec2<f32>, b: vec2<f32>) -> vec2<f32> {
    return iv_add(a, iv_neg(b));
}

// (Bounds are within ±2^62, so every product is finite. An unbounded operand makes the
// product unbounded, but only on a side where some corner's product lies: the product is
// bilinear in its operands, so the least and the most corner bound it, ±2^62 standing in
// for ±inf.
// Where every corner is >= 0 the lower bound is kept (2.29·x^x + 3 over x^x's [0, inf]
// stays >= 3). Exact products with infinite bounds, as iv_div's quotients, cost the
// certified pass a tenth on lavapipe, products being its commonest operation.)
fn iv_mul(a: vec2<f32>, b: vec2<f32>) -> vec2<f32> {
    let p = vec4<f32>(a.x * b.x, a.x * b.y, a.y * b.x, a.y * b.y);
    let least = min(min(p.x, p.y), min(p.z, p.w));
    let most = max(max(p.x, p.y), max(p.z, p.w));
    let whole = iv_unbounded(a) | iv_unbounded(b);
    let lo = select(iv_down(least), -IV_BIG, whole & (least < 0.0));
    let hi = select(iv_up(most), IV_BIG, whole & (most > 0.0));
    return iv_keep_or_empty(lo, hi, iv_is_empty(a) | iv_is_empty(b));
}

// The set of values both a and b hold (empty if none).
fn iv_meet(a: vec2<f32>, b: vec2<f32>) -> vec2<f32> {
    let r = vec2<f32>(max(a.x, b.x), min(a.y, b.y));
    return select(r, IV_EMPTY, (r.x > r.y) | iv_is_empty(a) | iv_is_empty(b));
}

fn iv_abs(a: vec2<f32>) -> vec2<f32> {
    let r = select(vec2<f32>(0.0, max(-a.x, a.y)), iv_neg(a), a.y <= 0.0);
    return select(r, a, iv_is_empty(a) | (a.x >= 0.0));
}

fn iv_sqr(a: vec2<f32>) -> vec2<f32> {
    let m = iv_abs(a);
    // |a| beyond 2^31 squares beyond 2^62: +inf.
    let hi = select(iv_up(m.y * m.y), IV_BIG, m.y > 2147483648.0);
    return iv_keep_or_empty(max(iv_down(m.x * m.x), 0.0), hi, iv_is_empty(m));
}

// 1/|b| may reach 2^62 at most: a divisor within ±2^-62 of 0 gives the whole line.
const IV_DIV_FLOOR: f32 = 2.16840434497100886801e-19; // 2^-62

// Whether each of four bounds stands for ±inf.
fn iv_infinite4(x: vec4<f32>) -> vec4<bool> {
    return abs(x) >= vec4<f32>(IV_BIG);
}

// x / y bound by bound (y nonzero), ±IV_BIG standing for ±inf: inf over a bound is inf of
// the quotient's sign, a finite bound over inf is 0, as the CPU's intervals take them.
fn iv_quot4(x: vec4<f32>, y: vec4<f32>) -> vec4<f32> {
    // (Over a finite or infinite bound y, |inf / y| >= 1: the quotient keeps its sign.)
    let q = x / y;
    return select(select(q, vec4<f32>(0.0), iv_infinite4(y)), sign(q) * IV_BIG, iv_infinite4(x));
}

// A divisor with 0 for one bound (|x|, x^2, sqrt(x) over a box that reaches 0) and the
// other beyond the floor gives a half-line where a keeps its sign, as the CPU's intervals
// do: 1 / sqrt(y) is then proved positive, not the whole line.
fn iv_div(a: vec2<f32>, b: vec2<f32>) -> vec2<f32> {
    let none = iv_is_empty(a) | iv_is_empty(b);
    let pole = (b.x <= IV_DIV_FLOOR) & (b.y >= -IV_DIV_FLOOR);
    // x / y is within 2.5 ulps for |y| in [2^-126, 2^126] (WGSL §15.7.4).
    let d = iv_or_one(b, none | pole);
    let q = iv_quot4(vec4<f32>(a.x, a.x, a.y, a.y), vec4<f32>(d.x, d.y, d.x, d.y));
    let lo = select(iv_down_n(min(min(q.x, q.y), min(q.z, q.w)), 3u), -IV_BIG, pole);
    let hi = select(iv_up_n(max(max(q.x, q.y), max(q.z, q.w)), 3u), IV_BIG, pole);
    // The half-line: a's bound nearer 0 over b's bound away from it is its finite end, and
    // it reaches +inf where a and b keep the same sign.
    let above = (b.x == 0.0) & (b.y > IV_DIV_FLOOR);
    let below = (b.y == 0.0) & (b.x < -IV_DIV_FLOOR);
    let a_pos = a.x >= 0.0;
    let half = (above | below) & (a_pos | (a.y <= 0.0));
    let end = iv_quot4(vec4<f32>(select(a.y, a.x, a_pos)), vec4<f32>(select(1.0, select(b.x, b.y, above), half))).x;
    let rising = above == a_pos;
    let half_lo = select(-IV_BIG, iv_down_n(end, 3u), rising);
    let half_hi = select(iv_up_n(end, 3u), IV_BIG, rising);
    return iv_keep_or_empty(select(lo, half_lo, half), select(hi, half_hi, half), none);
}

fn iv_min(a: vec2<f32>, b: vec2<f32>) -> vec2<f32> {
    return select(min(a, b), IV_EMPTY, iv_is_empty(a) | iv_is_empty(b));
}

fn iv_max(a: vec2<f32>, b: vec2<f32>) -> vec2<f32> {
    return select(max(a, b), IV_EMPTY, iv_is_empty(a) | iv_is_empty(b));
}

// sqrt over the part of a that is >= 0. WGSL's sqrt is inherited from 1 / inverseSqrt
// (2 ulps, then 2.5): 6 ulps; below 2^-100 the bound is taken as 0 or 2^-50.
fn iv_sqrt(a: vec2<f32>) -> vec2<f32> {
    let none = iv_is_empty(a) | (a.y < 0.0);
    iv_jump = iv_jump | ((a.x < 0.0) & !none);
    let b = iv_or_one(a, none);
    let small = 7.88860905221011805412e-31; // 2^-100
    let lo = select(max(iv_down_n(sqrt(max(b.x, 0.0)), 6u), 0.0), 0.0, b.x < small);
    let hi = select(select(iv_up_n(sqrt(b.y), 6u), IV_BIG, b.y >= IV_BIG), 8.88178419700125232339e-16, b.y < small);
    return iv_keep_or_empty(lo, hi, none);
}

// exp, monotone: within 3 + 2|x| ulps (WGSL §15.7.4); e^x for x > 42 is beyond 2^60
// (+inf here), for x < -87 below 2^-125 (0 is a lower bound).
fn iv_exp(a: vec2<f32>) -> vec2<f32> {
    let none = iv_is_empty(a);
    let b = iv_or_one(a, none);
    let lo_x = max(b.x, -87.0);
    let lo = select(0.0, max(iv_down_n(exp(lo_x), 3u + u32(2.0 * abs(lo_x)) + 1u), 0.0), b.x > -87.0);
    let hi_x = clamp(b.y, -80.0, 42.0);
    let hi = select(iv_up_n(exp(hi_x), 3u + u32(2.0 * abs(hi_x)) + 1u), IV_BIG, b.y > 42.0);
    return iv_keep_or_empty(lo, hi, none);
}

// The natural log of one bound x > 0: log is within 3 ulps outside [0.5, 2] and has an
// absolute error below 2^-21 inside (WGSL §15.7.4).
fn iv_ln_bound(x: f32, up: bool) -> f32 {
    let v = log(x);
    let near_one = (x >= 0.5) & (x <= 2.0);
    let slack = 9.5367431640625e-7; // 2^-20
    let dn = select(iv_down_n(v, 3u), iv_down(v - slack), near_one);
    let un = select(iv_up_n(v, 3u), iv_up(v + slack), near_one);
    return select(dn, un, up);
}

// ln over the part of a that is > 0; a bound below 2^-120 gives -inf.
fn iv_ln(a: vec2<f32>) -> vec2<f32> {
    let none = iv_is_empty(a) | (a.y <= 0.0);
    let floor = 7.52316384526264005100e-37; // 2^-120
    let b = iv_or_one(a, none);
    iv_jump = iv_jump | (b.x <= floor);
    let lo = select(iv_ln_bound(max(b.x, floor), false), -IV_BIG, b.x <= floor);
    let hi = iv_ln_bound(max(b.y, floor), true);
    return iv_keep_or_empty(lo, hi, none);
}

const IV_TAU: f32 = 6.28318530717958647692;
const IV_PI: f32 = 3.14159265358979323846;

// x - k 2pi for the k that brings it into [-pi, pi], for |x| < 2^12: within |x| 2^-20 + 4e-6
// of the exact value (the rounded 2pi, the product, the difference, and the clamp to the
// f32 below pi), which sin's slack adds.
fn iv_turn(x: f32) -> f32 {
    let pi_down = 3.14159250259399414062;
    return clamp(x - round(x / IV_TAU) * IV_TAU, -pi_down, pi_down);
}

// Whether [lo, hi] (lo in [-pi - 1e-3, pi + 1e-3], hi - lo < 2pi) holds c + 2pi k for some k.
fn iv_holds(lo: f32, hi: f32, c: f32) -> bool {
    return ((lo <= c) & (c <= hi)) | ((lo <= c + IV_TAU) & (c + IV_TAU <= hi)) | ((lo <= c - IV_TAU) & (c - IV_TAU <= hi));
}

// sin at one point x, |x| < 2^12, as an interval. WGSL's own sin promises only 2^-11
// (§15.7.4), which leaves every enclosure of a trigonometric F some 1e-3 wide and the
// pixels near M undecided, so it is computed from + - * alone (each within 2^-23
// relative): r = x - k pi/2 with k = round(x 2/pi), in interval arithmetic with pi/2
// split into 1.5703125 (k times it is exact) and the rest as an interval; then sin r or
// cos r (|r| < 0.786) by their Taylor polynomials to r^9 and r^10 at r's centre. The
// error: truncation below 0.786^11/11! < 2e-9, and a dozen roundings of terms whose
// magnitudes sum below cosh(0.786) < 1.33, under 2.1e-6; 4e-6 is taken, plus r's width
// (sin and cos are 1-Lipschitz).
fn iv_sin_at(x: f32) -> vec2<f32> {
    let k = round(x * 0.636619772);
    let head = iv_sub(vec2<f32>(x), vec2<f32>(k * 1.5703125));
    let r = iv_sub(head, iv_mul(vec2<f32>(k), vec2<f32>(4.83826792333275079727e-4, 4.83826821437105536461e-4)));
    let c = 0.5 * (r.x + r.y);
    let q = c * c;
    let s = c * (1.0 + q * (-0.16666667 + q * (0.008333334 + q * (-0.0001984127 + q * 2.7557319e-6))));
    let co = 1.0 + q * (-0.5 + q * (0.041666668 + q * (-0.0013888889 + q * (2.4801588e-5 - q * 2.755732e-7))));
    // x = k pi/2 + r: sin x is sin r, cos r, -sin r, -cos r as k is 0, 1, 2, 3 mod 4.
    let quadrant = i32(k) & 3;
    let v = select(s, co, (quadrant & 1) == 1) * select(1.0, -1.0, quadrant >= 2);
    let e = 4e-6 + (r.y - r.x);
    return vec2<f32>(iv_down(v - e), iv_up(v + e));
}

// sin over an interval: the enclosures at its two ends (iv_sin_at), widened to 1 or -1
// where it may hold an extreme; wider or farther intervals give [-1, 1]. The extremes are
// found on the interval turned into [-pi, pi] (the turn's own error, at most |x| 2^-20 +
// 4e-6 for |x| < 2^12, is far within the margin of 2e-3).
fn iv_sin(a: vec2<f32>) -> vec2<f32> {
    let far = max(abs(a.x), abs(a.y));
    let whole = (a.y - a.x >= IV_TAU - 0.01) | (far >= 4096.0);
    // (Where the answer is [-1, 1] or empty, the ends are taken at 0: no arithmetic far out.)
    let b = select(a, vec2<f32>(0.0), whole | iv_is_empty(a));
    let ra = iv_turn(b.x);
    let width = iv_up_n(b.y - b.x, 2u);
    let sa = iv_sin_at(b.x);
    let sb = iv_sin_at(b.y);
    let m = 2e-3;
    let hi = select(max(sa.y, sb.y), 1.0, iv_holds(ra - m, ra + width + m, 0.5 * IV_PI));
    let lo = select(min(sa.x, sb.x), -1.0, iv_holds(ra - m, ra + width + m, -0.5 * IV_PI));
    let r = select(vec2<f32>(max(iv_down(lo), -1.0), min(iv_up(hi), 1.0)), vec2<f32>(-1.0, 1.0), whole);
    return select(r, IV_EMPTY, iv_is_empty(a));
}

// cos x = sin(x + pi/2), with pi/2 as an interval.
fn iv_cos(a: vec2<f32>) -> vec2<f32> {
    return iv_sin(iv_add(a, vec2<f32>(IV_HALF_PI_DOWN, IV_HALF_PI_UP)));
}

fn iv_tan(a: vec2<f32>) -> vec2<f32> {
    return iv_div(iv_sin(a), iv_cos(a));
}

// sign and step are monotone: their values at the bounds, exact.
fn iv_sign(a: vec2<f32>) -> vec2<f32> {
    let none = iv_is_empty(a);
    iv_jump = iv_jump | ((a.x <= 0.0) & (a.y >= 0.0) & !none);
    return select(sign(a), IV_EMPTY, none);
}

fn iv_step(a: vec2<f32>) -> vec2<f32> {
    let none = iv_is_empty(a);
    iv_jump = iv_jump | ((a.x <= 0.0) & (a.y >= 0.0) & !none);
    let s = select(select(vec2<f32>(0.0), vec2<f32>(1.0), a > vec2<f32>(0.0)), vec2<f32>(0.5), a == vec2<f32>(0.0));
    return select(s, IV_EMPTY, none);
}

// The functions below are compositions of those above, so they are as rigorous, if wider
// than the CPU's. sinh x = (e^x - e^-x) / 2, cosh x = (e^x + e^-x) / 2 (x and -x move the
// two terms the same way for sinh; cosh takes |x|), tanh x = 1 - 2 / (e^2x + 1).
fn iv_sinh(a: vec2<f32>) -> vec2<f32> {
    let none = iv_is_empty(a);
    let b = iv_or_one(a, none);
    let lo = iv_half(iv_sub(iv_exp(vec2<f32>(b.x)), iv_exp(vec2<f32>(-b.x))));
    let hi = iv_half(iv_sub(iv_exp(vec2<f32>(b.y)), iv_exp(vec2<f32>(-b.y))));
    return select(vec2<f32>(lo.x, hi.y), IV_EMPTY, none);
}

fn iv_cosh(a: vec2<f32>) -> vec2<f32> {
    let m = iv_abs(a);
    let none = iv_is_empty(m);
    let b = iv_or_one(m, none);
    let lo = iv_half(iv_add(iv_exp(vec2<f32>(b.x)), iv_exp(vec2<f32>(-b.x))));
    let hi = iv_half(iv_add(iv_exp(vec2<f32>(b.y)), iv_exp(vec2<f32>(-b.y))));
    return select(vec2<f32>(max(lo.x, 1.0), hi.y), IV_EMPTY, none);
}

// a / 2: exact but for subnormals (each bound stepped outward), ±inf (±IV_BIG) kept. (As
// iv_mul by 0.5, an unbounded operand would give the whole line: sinh and cosh beyond 42,
// where e^x has no upper bound, lost their sign, and sinh(1000 y) = 0 its EMPTY pixels.)
fn iv_half(a: vec2<f32>) -> vec2<f32> {
    let lo = select(iv_down(0.5 * a.x), -IV_BIG, a.x <= -IV_BIG);
    let hi = select(iv_up(0.5 * a.y), IV_BIG, a.y >= IV_BIG);
    return select(vec2<f32>(lo, hi), IV_EMPTY, iv_is_empty(a));
}

fn iv_tanh(a: vec2<f32>) -> vec2<f32> {
    let jump = iv_jump;
    // (2a exactly, an infinite bound kept: tanh of a half-line to +inf is near 1, not the
    // whole line iv_mul would make of it.)
    let e = iv_exp(iv_keep_or_empty(2.0 * a.x, 2.0 * a.y, iv_is_empty(a)));
    let r = iv_sub(vec2<f32>(1.0), iv_div(vec2<f32>(2.0), iv_add(e, vec2<f32>(1.0))));
    // An unbounded e^2x only means tanh is near 1: it stays continuous.
    iv_jump = jump;
    return select(vec2<f32>(max(r.x, -1.0), min(r.y, 1.0)), IV_EMPTY, iv_is_empty(a));
}

// cbrt x = sign(x) e^(ln|x| / 3), monotone: applied to each bound.
fn iv_cbrt_bound(x: f32, up: bool) -> f32 {
    let m = iv_exp(iv_div(iv_ln(vec2<f32>(abs(x))), vec2<f32>(3.0)));
    let v = select(select(m.x, m.y, up), select(-m.y, -m.x, up), x < 0.0);
    return select(v, 0.0, x == 0.0);
}

fn iv_cbrt(a: vec2<f32>) -> vec2<f32> {
    let none = iv_is_empty(a);
    let jump = iv_jump;
    let b = iv_or_one(a, none);
    let r = vec2<f32>(iv_cbrt_bound(b.x, false), iv_cbrt_bound(b.y, true));
    iv_jump = jump | (iv_unbounded(r) & !none);
    return select(r, IV_EMPTY, none);
}

// a^b = e^(b ln a) over the part of a that is > 0 (a = 0 adds 0 or 1 where they belong).
// Where a reaches 0, e^(b ln a) is taken over a's part from 2^-119 (ln's lower bound is
// -inf below 2^-120, which made b ln a the whole line and a^b every value: pow(x, 2.5) over
// [-2^-125, 2^-125] was [0, +inf]). Below 2^-119, a^b lies between 0 and its value there
// for b > 0, beyond it for b < 0, and is 1 for b = 0: what a = 0 adds below covers it.
fn iv_pow(a: vec2<f32>, b: vec2<f32>) -> vec2<f32> {
    let none = iv_is_empty(a) | iv_is_empty(b) | (a.y < 0.0);
    let positive = (a.y > 0.0) & !none;
    let jump = iv_jump;
    let least = 1.50463276905252801020e-36; // 2^-119
    let from_least = vec2<f32>(least, max(a.y, least));
    let base = select(a, from_least, a.x <= 0.0);
    var r = iv_exp(iv_mul(iv_or_one(b, !positive), iv_ln(iv_or_one(base, !positive))));
    iv_jump = select(jump, iv_jump, positive);
    r = select(IV_EMPTY, r, positive);
    let zero = (a.x <= 0.0) & !none;
    iv_jump = iv_jump | zero;
    r = select(r, vec2<f32>(min(r.x, 0.0), max(r.y, 0.0)), zero & (b.y > 0.0));
    r = select(r, vec2<f32>(min(r.x, 1.0), max(r.y, 1.0)), zero & (b.x <= 0.0) & (b.y >= 0.0));
    r = select(r, vec2<f32>(r.x, IV_BIG), zero & (b.x < 0.0));
    return select(r, IV_EMPTY, none);
}

const IV_HALF_PI_DOWN: f32 = 1.57079625129699707031;
const IV_HALF_PI_UP: f32 = 1.57079637050628662109;
const IV_PI_UP: f32 = 3.14159274101257324219;
// atan and asin are increasing, so each bound is the function's value at an end of the
// interval, widened by 2^-10 of itself: WGSL's atan and atan2 are within 4096 ULPs (2^-11
// of the value), and asin's error is inherited from atan2(x, sqrt(1 - x x)), within 2^-11 of
// the value plus at most 2^-13 near |x| = 1 (docs/method.md §5.9). A bound is then kept on the side of
// 0 that the function's sign proves, as far as a plain bound proves: atan x and asin x have
// x's sign, |atan x| >= 0.785 min(|x|, 1) (atan x / x falls from 1 to pi/4 on (0, 1]) and
// |asin x| >= |x|; so a point's sign is decided however near 0 it is.
const IV_ARC_MARGIN: f32 = 0.0009765625;

fn iv_arc_bound(r: f32, up: bool) -> f32 {
    let m = abs(r) * IV_ARC_MARGIN;
    return select(iv_down(r - m), iv_up(r + m), up);
}

fn iv_atan(a: vec2<f32>) -> vec2<f32> {
    let none = iv_is_empty(a);
    let b = select(a, vec2<f32>(0.0), none);
    let least = select(-IV_HALF_PI_UP, min(b.x, 1.0) * 0.785, b.x >= 0.0);
    let most = select(IV_HALF_PI_UP, max(b.y, -1.0) * 0.785, b.y <= 0.0);
    let lo = max(iv_arc_bound(atan(b.x), false), least);
    let hi = min(iv_arc_bound(atan(b.y), true), most);
    return select(vec2<f32>(lo, hi), IV_EMPTY, none);
}

// Over the part of the interval in [-1, 1] (a part outside it is a jump: F is undefined there).
fn iv_asin(a: vec2<f32>) -> vec2<f32> {
    let none = iv_is_empty(a) | (a.x > 1.0) | (a.y < -1.0);
    iv_jump = iv_jump | (((a.x < -1.0) | (a.y > 1.0)) & !none);
    let b = select(clamp(a, vec2<f32>(-1.0), vec2<f32>(1.0)), vec2<f32>(0.0), none);
    let least = select(-IV_HALF_PI_UP, b.x, b.x >= 0.0);
    let most = select(IV_HALF_PI_UP, b.y, b.y <= 0.0);
    let lo = max(iv_arc_bound(asin(b.x), false), least);
    let hi = min(iv_arc_bound(asin(b.y), true), most);
    return select(vec2<f32>(lo, hi), IV_EMPTY, none);
}

// acos x = pi/2 - asin x, which is >= 0.
fn iv_acos(a: vec2<f32>) -> vec2<f32> {
    let r = iv_sub(vec2<f32>(IV_HALF_PI_DOWN, IV_HALF_PI_UP), iv_asin(a));
    return select(vec2<f32>(max(r.x, 0.0), min(r.y, IV_PI_UP)), IV_EMPTY, iv_is_empty(r));
}

// atan2(y, x) off its branch cut (x > 0, or y of one sign on the whole box) is the angle of
// a convex set that misses the origin, whose least and greatest are at corners: their
// values, widened as atan's, and kept on y's side of 0. A box on the cut or around the
// origin jumps, and takes the whole range.
fn iv_atan2(y: vec2<f32>, x: vec2<f32>) -> vec2<f32> {
    let none = iv_is_empty(y) | iv_is_empty(x);
    let off_cut = (x.x > 0.0) | (y.x > 0.0) | (y.y < 0.0);
    iv_jump = iv_jump | (!off_cut & !none);
    let by = select(y, vec2<f32>(1.0), none);
    let bx = select(x, vec2<f32>(1.0), none);
    let c = vec4<f32>(atan2(by.x, bx.x), atan2(by.x, bx.y), atan2(by.y, bx.x), atan2(by.y, bx.y));
    let least = select(-IV_PI_UP, 0.0, by.x >= 0.0);
    let most = select(IV_PI_UP, 0.0, by.y <= 0.0);
    let lo = max(iv_arc_bound(min(min(c.x, c.y), min(c.z, c.w)), false), least);
    let hi = min(iv_arc_bound(max(max(c.x, c.y), max(c.z, c.w)), true), most);
    let r = select(vec2<f32>(-IV_PI_UP, IV_PI_UP), vec2<f32>(lo, hi), off_cut);
    return select(r, IV_EMPTY, none);
}
