//! The interpreting shader (one shader for every formula, reading its tapes from a buffer):
//! it draws what each formula's own shader draws, and its register allocation keeps what
//! is live.

mod common;
#[path = "support/unseen.rs"]
mod unseen;

use common::{agreement, example_scenes};
use fourfold::CompiledFormula;
use fourfold::render::shader::{self, InterpretError, REGISTERS};
use fourfold::render::{Camera, FrameOptions, Gpu, RayCaster, Uniforms};
use fourfold::scene::Scene;
use fourfold::tree::Hierarchy;

/// Formulas of every kind of operation the interpreter dispatches on: undefined regions
/// (sqrt, ln, asin, a real power, division), negative and large integer powers, kinks,
/// two-argument functions, parameters, hyperbolic functions and tiny and huge constants.
const INVENTED: [&str; 8] = [
    "sqrt(1 - x^2 - y^2) - z^2 - w^2 + 0.2",
    "ln(x^2 + y^2 + 0.01) + z^-2 * 0.01 + w^7 - 0.3",
    "max(abs(x) + abs(y), min(z, w)) - 0.8 + 0.1 * sign(x) * step(y)",
    "atan2(y, x) * 0.2 + (x^2 + y^2 + z^2 + w^2)^0.75 - a",
    "asin(x * 0.9) + acos(y * 0.9) - cbrt(z) - tan(w) - b",
    "sinh(x) * cosh(y) + tanh(z) * exp(w) - 1 / (x + 2) - 0.2",
    "x^2 + y^2 + z^2 + w^2 - 1 + 1e-30 * x + 1e30 * (x - x)",
    "cos(3 x) * sin(3 y) + cos(3 z) * sin(3 w) - x^5 * y^-1 * 0.01",
];

fn gpu() -> Gpu {
    Gpu::new().unwrap_or_else(|e| panic!("GPU tests need an adapter: {e}"))
}

/// Every scene drawn: the examples, the unseen scenes (hard ones too) and the invented formulas in the
/// unit glome's domain, plain, with few levels and rays (a test of the shader, not the tree).
fn scenes() -> Vec<(String, Scene)> {
    let glome = example_scenes()
        .into_iter()
        .find(|(name, _)| *name == "glome")
        .expect("the glome example")
        .1;
    let invented = INVENTED.iter().map(|f| {
        let mut scene = glome.clone();
        scene.formula = f.to_string();
        scene.params.insert("a".into(), 0.9);
        scene.params.insert("b".into(), -0.4);
        (f.to_string(), scene)
    });
    example_scenes()
        .into_iter()
        .map(|(name, scene)| (name.to_string(), scene))
        .chain(unseen::unseen_scenes())
        .chain(unseen::hard_scenes())
        .chain(invented)
        .map(|(name, mut scene)| {
            scene.tree.max_level = scene.tree.max_level.min(5);
            scene.tree.min_level = scene.tree.min_level.min(4);
            scene.render.rays = scene.render.rays.min(8);
            scene.render.certified = false;
            (name, scene)
        })
        .collect()
}

#[test]
fn the_interpreter_draws_what_each_formula_s_own_shader_draws() {
    let gpu = gpu();
    let interpreter = shader::interpreter().expect("the interpreting shader validates");
    let mut first: Option<RayCaster> = None;
    let (mut worst_cover, mut worst_close) = (1.0f64, 1.0f64);
    for (name, scene) in scenes() {
        let (formula, params, tree) = common::build(&scene, scene.tree.into());
        let hierarchy = Hierarchy::for_formula(&tree, &formula, &params);
        let own = shader::generate(&formula).unwrap();
        let mut compiled = RayCaster::new(&gpu, &own, &hierarchy).unwrap();
        let base = first.get_or_insert_with(|| {
            RayCaster::new(&gpu, &interpreter, &Hierarchy::default()).unwrap()
        });
        let mut interpreted = base.interpret(&gpu, &formula, &hierarchy).unwrap();
        assert!(interpreted.interprets() && !compiled.interprets());
        let size = 64;
        let camera = Camera::new(&scene.domain, &scene.view, size, size);
        let (render, domain) = (&scene.render, &scene.domain);
        let options = FrameOptions::default();
        let uniforms = Uniforms::new(&camera, render, domain, &hierarchy, &params, options);
        compiled.bin_view(&gpu, &hierarchy, None, &camera, &uniforms);
        interpreted.bin_view(&gpu, &hierarchy, None, &camera, &uniforms);
        let a = compiled.render_rgba(&gpu, &uniforms).unwrap();
        let b = interpreted.render_rgba(&gpu, &uniforms).unwrap();
        let (close, cover) = agreement(&a, &b, scene.render.background.0, 8);
        // A pixel whose loops llvmpipe cut short (its budget of loop rounds spent): alpha
        // 254 (see pixel_color). The interpreter must not spend it faster than the
        // formula's own shader does.
        let cut = |rgba: &[u8]| rgba.chunks(4).filter(|p| p[3] == 254).count();
        let (cut_own, cut_interpreted) = (cut(&a), cut(&b));
        eprintln!(
            "{name}: colour {close:.4}, coverage {cover:.4}, loops cut {cut_own} / {cut_interpreted}"
        );
        assert!(
            cut_interpreted <= cut_own,
            "{name}: {cut_interpreted} pixels cut short"
        );
        worst_cover = worst_cover.min(cover);
        worst_close = worst_close.min(close);
        // Where a root lies within an f32 rounding of a ray's sample, the driver's compile
        // of the formula's own shader (which may fuse a multiply and an add) and the
        // interpreter (which rounds every operation) can see its sign change differently.
        assert!(cover >= 0.995, "{name}: coverage agrees on {cover}");
        assert!(close >= 0.99, "{name}: colours agree on {close}");
        // Where a root lies within an f32 rounding of a ray's sample, the driver's own
        // compile of the formula (which may fuse a multiply and an add) and the
        // interpreter (which rounds every operation) can see its sign change differently.
    }
    eprintln!("worst: coverage {worst_cover:.4}, colour {worst_close:.4}");
}

#[test]
fn a_formula_keeps_only_its_live_values_in_registers() {
    // Every example fits. F of a long sum needs a handful of registers however long it
    // is; its gradient, whose terms reuse the sum's arguments, and a formula that uses
    // seventy terms again at its end need more than the interpreter holds.
    for (name, scene) in example_scenes() {
        let formula = CompiledFormula::compile(&scene.formula).unwrap();
        let program = shader::program(&formula);
        assert!(program.is_ok(), "{name}: {program:?}");
    }
    let terms: Vec<String> = (1..=70).map(|i| format!("sin({i} x + w)")).collect();
    let sum = CompiledFormula::compile(&format!("{} - y", terms.join(" + "))).unwrap();
    let mut words = Vec::new();
    shader::encode_tape(&sum.tape_f, &mut words).expect("F of a sum fits");
    let highest = words.iter().map(|w| w[3]).max().unwrap();
    assert!(highest < 4, "F of a sum held {} registers", highest + 1);
    for text in [
        format!("{} - y", terms.join(" + ")),
        format!("({}) * ({}) - y", terms.join(" + "), terms.join(" * ")),
    ] {
        match shader::program(&CompiledFormula::compile(&text).unwrap()) {
            Err(InterpretError::TooManyRegisters(n)) => assert!(n > REGISTERS, "{n}"),
            other => panic!("seventy live terms: {other:?}"),
        }
    }
}
