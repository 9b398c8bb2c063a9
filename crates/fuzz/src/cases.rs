//! A formula case: a random formula with what a user sets around it (parameter values, the
//! view's angles, a picture size, a render mode), as command-line arguments.

use std::path::Path;

use fastrand::Rng;

use crate::formulas::{Formula, FormulaMaker};

/// How a case is drawn: every mode of `fourfold render`.
#[derive(Debug, Clone, PartialEq)]
pub enum Mode {
    Plain,
    Certified { budget: u32 },
    Slice(f64),
    Slab(f64, f64),
    Hidden,
    BruteForce,
}

/// Parameter values a user might type: ordinary ones, edges, and ones the scene rules
/// refuse (not a number, beyond f64).
const PARAMETER_VALUES: &[&str] = &[
    "1", "0", "-1", "0.5", "2", "-0.25", "3", "1e-30", "1e30", "3.5e38", "-1e300", "nan", "1e400",
];

/// One formula case.
#[derive(Debug, Clone)]
pub struct FormulaCase {
    pub formula: Formula,
    /// Values for some of its parameters (the rest take the default, 1).
    pub params: Vec<(String, String)>,
    pub angles: [f64; 6],
    pub size: [u32; 2],
    pub max_level: u32,
    pub mode: Mode,
    /// Whether this case also draws on the GPU (and is compared with the CPU twin).
    pub gpu: bool,
}

impl FormulaCase {
    /// A random case; `gpu` says whether it is drawn on the GPU too.
    pub fn random(rng: &mut Rng, gpu: bool) -> Self {
        let formula = FormulaMaker::new(rng).formula();
        Self::around(formula, rng, gpu)
    }

    /// A random case for `formula`.
    pub fn around(formula: Formula, rng: &mut Rng, gpu: bool) -> Self {
        let mut params = Vec::new();
        for name in formula.parameters() {
            if rng.bool() {
                let value = PARAMETER_VALUES[rng.usize(..PARAMETER_VALUES.len())];
                params.push((name.to_string(), value.to_string()));
            }
        }
        let angles = std::array::from_fn(|_| (rng.f64() - 0.5) * 7.0);
        let mode = match rng.u32(..10) {
            0..=3 => Mode::Plain,
            4 => Mode::Certified {
                budget: [1, 16, 256][rng.usize(..3)],
            },
            5 => Mode::Slice((rng.f64() - 0.5) * 3.0),
            6 => Mode::Slab((rng.f64() - 0.5) * 2.0, rng.f64() * 1.5),
            7 => Mode::Hidden,
            8 => Mode::BruteForce,
            _ => Mode::Plain,
        };
        Self {
            formula,
            params,
            angles,
            size: [4 + rng.u32(..21), 4 + rng.u32(..21)],
            max_level: 3 + rng.u32(..3),
            mode,
            gpu,
        }
    }

    /// The formula's text, as typed.
    pub fn text(&self) -> String {
        self.formula.to_string()
    }

    /// `--param NAME=VALUE` for each value set.
    pub fn param_args(&self) -> Vec<String> {
        self.params
            .iter()
            .flat_map(|(name, value)| ["--param".to_string(), format!("{name}={value}")])
            .collect()
    }

    /// `fourfold render` of this case into `output`, on the CPU twin where `cpu`, else on
    /// the GPU.
    pub fn render_args(&self, output: &Path, cpu: bool) -> Vec<String> {
        let angles: Vec<String> = self.angles.iter().map(|a| format!("{a:.4}")).collect();
        let mut args = vec![
            "render".to_string(),
            self.text(),
            "-o".to_string(),
            output.display().to_string(),
            "--size".to_string(),
            format!("{}x{}", self.size[0], self.size[1]),
            "--angles".to_string(),
            angles.join(","),
            "--max-level".to_string(),
            self.max_level.to_string(),
            "--min-level".to_string(),
            "2".to_string(),
        ];
        args.extend(self.param_args());
        match &self.mode {
            Mode::Plain => args.push("--uncertified".to_string()),
            Mode::Certified { budget } => {
                args.extend(["--certified", "--cert-budget"].map(String::from));
                args.push(budget.to_string());
            }
            Mode::Slice(c) => args.push(format!("--slice={c:.3}")),
            Mode::Slab(c, h) => args.push(format!("--slab={c:.3},{h:.3}")),
            Mode::Hidden => args.extend(["--colour-by", "hidden"].map(String::from)),
            Mode::BruteForce => args.push("--brute-force".to_string()),
        }
        // (`render` itself would draw a small slice on the CPU: the GPU's case asks for it.)
        args.push(if cpu { "--cpu" } else { "--gpu" }.to_string());
        args
    }
}
