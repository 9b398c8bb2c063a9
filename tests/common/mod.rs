//! Helpers shared by the integration tests.
#![allow(dead_code)]

use fourfold::CompiledFormula;
use fourfold::eval::PointEvaluator;
use std::sync::atomic::AtomicBool;

use fourfold::scene::{EXAMPLES, Scene};
use fourfold::tree::{BuildSettings, Tree16};

/// A small deterministic generator (xorshift64*), so failures reproduce.
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
}

/// Every example scene, parsed.
pub fn example_scenes() -> Vec<(&'static str, Scene)> {
    EXAMPLES
        .iter()
        .map(|(name, text)| {
            (
                *name,
                Scene::parse(text, name).expect("example scenes parse"),
            )
        })
        .collect()
}

/// F at a point with the given parameter values.
pub fn eval_f(formula: &CompiledFormula, p: [f64; 4], params: &[f64]) -> f64 {
    PointEvaluator::new().eval(&formula.tape_f, p, params)
}

/// The compiled formula, its parameter values and its tree, for `scene` with `settings`.
pub fn build(scene: &Scene, settings: BuildSettings) -> (CompiledFormula, Vec<f64>, Tree16) {
    let f = CompiledFormula::compile(&scene.formula).unwrap();
    let params = scene.param_values(&f.param_names());
    let tree = Tree16::build(
        &f,
        &params,
        &scene.domain,
        settings,
        &AtomicBool::new(false),
        None,
    )
    .unwrap();
    (f, params, tree)
}
