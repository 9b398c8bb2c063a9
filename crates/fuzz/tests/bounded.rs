//! The bounded fuzz run of CI: a fixed seed, a few hundred formula cases (one in twelve also
//! on the GPU), scene files and links; no case may fail. `cargo run --release -p
//! fourfold-fuzz -- --cases N --seed S` is the long run (docs/testing.md).

use std::time::Duration;

use fourfold_fuzz::{Config, run};

#[test]
fn a_bounded_run_finds_no_failure() {
    let dir = std::env::temp_dir().join("fourfold-fuzz-ci");
    let config = Config {
        seed: 20261125,
        formulas: 240,
        scenes: 150,
        gpu_every: 12,
        timeout: Duration::from_secs(120),
        dir,
        wgsl_sample: None,
    };
    let report = run(&config, |_| {});
    eprintln!("{report}");
    assert!(report.failures.is_empty(), "{report}");
    // The generator reaches both outcomes: most formulas draw, some are refused.
    assert!(report.drawn > report.formulas / 2, "{report}");
    assert!(report.refused > 0, "{report}");
}
