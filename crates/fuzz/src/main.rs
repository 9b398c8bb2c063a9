//! The long run: `cargo run --release -p fourfold-fuzz -- --cases N --seed S` (docs/testing.md).

use std::path::PathBuf;
use std::time::Duration;

use clap::Parser;
use fourfold_fuzz::{Config, run};

/// Random formulas, scene files and share links through every path of fourfold.
#[derive(Debug, Parser)]
#[command(name = "fourfold-fuzz")]
struct Args {
    /// Formula cases to run.
    #[arg(long, default_value_t = 1000)]
    cases: usize,
    /// Scene files and share links to run (each).
    #[arg(long, default_value_t = 100)]
    scenes: usize,
    /// Seed of the run: the same seed makes the same cases.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Every this many formula cases also draws on the GPU and is compared with the CPU
    /// twin (0: none).
    #[arg(long, default_value_t = 50)]
    gpu_every: usize,
    /// Seconds a case may take before it counts as a hang.
    #[arg(long, default_value_t = 120)]
    timeout: u64,
    /// Where the cases write their pictures.
    #[arg(long)]
    dir: Option<PathBuf>,
    /// Write the WGSL of some drawn formulas to this folder (for the browser check).
    #[arg(long)]
    wgsl_out: Option<PathBuf>,
    /// With --wgsl-out: every this many drawn formulas.
    #[arg(long, default_value_t = 10)]
    wgsl_every: usize,
}

fn main() {
    let args = Args::parse();
    let config = Config {
        seed: args.seed,
        formulas: args.cases,
        scenes: args.scenes,
        gpu_every: args.gpu_every,
        timeout: Duration::from_secs(args.timeout.max(1)),
        dir: args
            .dir
            .unwrap_or_else(|| std::env::temp_dir().join(format!("fourfold-fuzz-{}", args.seed))),
        wgsl_sample: args.wgsl_out.map(|dir| (dir, args.wgsl_every)),
    };
    let (mut shown, mut failures_shown) = (0, 0);
    let report = run(&config, |r| {
        // A failure is told when it is found: a long run's last line may be hours away.
        for failure in &r.failures[failures_shown..] {
            eprint!("{failure}");
        }
        failures_shown = r.failures.len();
        let done = r.formulas + r.scene_files;
        if done >= shown + 500 {
            shown = done;
            eprintln!(
                "{} formulas, {} scene files and links, {} failures",
                r.formulas,
                r.scene_files,
                r.failures.len()
            );
        }
    });
    println!("seed {}: {report}", args.seed);
    if !report.failures.is_empty() {
        std::process::exit(1);
    }
}
