//! fourfold's fuzzer: random formulas (from the grammar, with constants at the edges of the
//! functions' domains), scene files and share links through every path a user has. A
//! formula case passes when every path draws it or refuses it with the same clear message
//! (exit 0 or 2); a panic, a hang (a time limit per case), exit 1, raw wgpu or naga text, or
//! the GPU and the CPU twin disagreeing fails it, and the failure prints the formula shrunk
//! to a small one. See docs/testing.md.

pub mod cases;
pub mod check;
pub mod formulas;
pub mod scenes;
pub mod shrink;

use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use fastrand::Rng;

use cases::FormulaCase;
use check::{Verdict, check_formula};
use formulas::Formula;

/// What a run does.
#[derive(Debug, Clone)]
pub struct Config {
    pub seed: u64,
    /// Formula cases.
    pub formulas: usize,
    /// Scene files and links (each).
    pub scenes: usize,
    /// Every this many formula cases also draws on the GPU (0: none does).
    pub gpu_every: usize,
    /// The longest a case may take before it counts as a hang.
    pub timeout: Duration,
    /// Where the cases write their pictures.
    pub dir: PathBuf,
    /// Where to write the WGSL of every this many accepted formulas (for the browser check).
    pub wgsl_sample: Option<(PathBuf, usize)>,
}

/// One failing case.
#[derive(Debug, Clone)]
pub struct Failure {
    /// What failed: `formula`, `scene file` or `link`.
    pub kind: &'static str,
    /// The input as generated (the formula's command-line arguments, the file, the link).
    pub input: String,
    /// The command of the case with its formula shrunk to a small one that still fails
    /// (formulas only): the case's own size, view, levels and parameters, without which
    /// the small formula may not fail.
    pub shrunk: Option<String>,
    pub reason: String,
}

impl std::fmt::Display for Failure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(f, "{} fails: {}", self.kind, self.reason)?;
        writeln!(f, "  input: {}", self.input)?;
        if let Some(s) = &self.shrunk {
            writeln!(f, "  shrunk: {s}")?;
        }
        Ok(())
    }
}

/// What a run found.
#[derive(Debug, Default)]
pub struct Report {
    pub formulas: usize,
    pub drawn: usize,
    pub refused: usize,
    /// How many formulas each refusal (its message's first words) turned away.
    pub refusals: std::collections::BTreeMap<String, usize>,
    pub on_gpu: usize,
    /// Drawn on the GPU, but its picture not compared with the twin's, by why
    /// (`check::UNCOMPARED_TRIG`, `check::UNCOMPARED_CUT`).
    pub uncompared: std::collections::BTreeMap<&'static str, usize>,
    pub scene_files: usize,
    pub links: usize,
    pub failures: Vec<Failure>,
    pub seconds: f64,
    pub formula_seconds: f64,
}

impl std::fmt::Display for Report {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let rate = self.formulas as f64 / self.formula_seconds.max(1e-9);
        writeln!(
            f,
            "{} formulas ({} drawn, {} refused, {} also on the GPU, {} of whose pictures \
             were not compared{}) at {rate:.1} per second; \
             {} scene files, {} links; {} failures in {:.0} s",
            self.formulas,
            self.drawn,
            self.refused,
            self.on_gpu,
            self.uncompared.values().sum::<usize>(),
            self.uncompared
                .iter()
                .map(|(why, n)| format!(", {n} for {why}"))
                .collect::<String>(),
            self.scene_files,
            self.links,
            self.failures.len(),
            self.seconds
        )?;
        for (why, count) in &self.refusals {
            writeln!(f, "  refused {count:>6}: {why}")?;
        }
        for failure in &self.failures {
            write!(f, "{failure}")?;
        }
        Ok(())
    }
}

/// How a case that did not answer in time is told.
const HANG: &str = "a hang";

/// Runs `work` on its own thread: its result, or a failure if it panics or takes longer
/// than `timeout` (the thread is left behind: a hang is reported, not waited for).
pub fn within<T: Send + 'static>(
    timeout: Duration,
    work: impl FnOnce() -> Result<T, String> + Send + 'static,
) -> Result<T, String> {
    let (send, receive) = mpsc::channel();
    let thread = std::thread::Builder::new()
        .name("fourfold-fuzz case".into())
        .spawn(move || {
            let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(work));
            let _ = send.send(outcome);
        })
        .map_err(|e| format!("could not start a thread: {e}"))?;
    match receive.recv_timeout(timeout) {
        Ok(Ok(result)) => {
            let _ = thread.join();
            result
        }
        Ok(Err(panic)) => {
            let text = panic
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default();
            Err(format!("panicked: {text}"))
        }
        Err(_) => Err(format!("no answer after {} s ({HANG})", timeout.as_secs())),
    }
}

fn run_case(case: &FormulaCase, config: &Config) -> Result<Verdict, String> {
    let case = case.clone();
    let dir = config.dir.clone();
    within(config.timeout, move || check_formula(&case, &dir))
}

/// Runs the fuzzer, calling `progress` after each case with the report so far.
pub fn run(config: &Config, mut progress: impl FnMut(&Report)) -> Report {
    let started = Instant::now();
    let mut rng = Rng::with_seed(config.seed);
    let mut report = Report::default();
    std::fs::create_dir_all(&config.dir).ok();
    for i in 0..config.formulas {
        let gpu = config.gpu_every > 0 && i % config.gpu_every == 0;
        let case = FormulaCase::random(&mut rng, gpu);
        report.formulas += 1;
        report.on_gpu += usize::from(gpu);
        match run_case(&case, config) {
            Ok(verdict @ (Verdict::Drew | Verdict::DrewUncompared(_))) => {
                report.drawn += 1;
                if let Verdict::DrewUncompared(why) = verdict {
                    *report.uncompared.entry(why).or_default() += 1;
                }
                sample_wgsl(config, &case, report.drawn);
            }
            Ok(Verdict::Refused(why)) => {
                report.refused += 1;
                *report.refusals.entry(kind_of(&why)).or_default() += 1;
            }
            Err(reason) => {
                // A hang is not shrunk: each try could take the whole time limit.
                let tries = if reason.contains(HANG) { 0 } else { 150 };
                let with_formula = |f: &Formula| {
                    let mut smaller = case.clone();
                    smaller.formula = f.clone();
                    smaller
                };
                let shrunk = shrink::shrink(&case.formula, tries, |f| {
                    run_case(&with_formula(f), config).is_err()
                });
                let command = |case: &FormulaCase| {
                    format!(
                        "fourfold {}",
                        quoted(&case.render_args(Path::new("out.png"), !gpu))
                    )
                };
                report.failures.push(Failure {
                    kind: "formula",
                    input: command(&case),
                    shrunk: Some(command(&with_formula(&shrunk))),
                    reason,
                });
            }
        }
        progress(&report);
    }
    report.formula_seconds = started.elapsed().as_secs_f64();
    for _ in 0..config.scenes {
        let text = scenes::broken_scene_file(&mut rng);
        let dir = config.dir.clone();
        let file = text.clone();
        report.scene_files += 1;
        if let Err(reason) = within(config.timeout, move || {
            scenes::check_scene_file(&file, &dir)
        }) {
            report.failures.push(Failure {
                kind: "scene file",
                input: text,
                shrunk: None,
                reason,
            });
        }
        let link = scenes::broken_link(&mut rng);
        let opened = link.clone();
        report.links += 1;
        if let Err(reason) = within(config.timeout, move || scenes::check_link(&opened)) {
            report.failures.push(Failure {
                kind: "link",
                input: link,
                shrunk: None,
                reason,
            });
        }
        progress(&report);
    }
    report.seconds = started.elapsed().as_secs_f64();
    report
}

/// A refusal's kind: its first line up to the first quote, number or colon after the word
/// `error:`, so that `unknown function 'sn'` and `unknown function 'q'` count together.
fn kind_of(headline: &str) -> String {
    let text = headline.strip_prefix("error: ").unwrap_or(headline);
    let end = text
        .find(|c: char| c == '\'' || c == ':' || c == '=' || c.is_ascii_digit())
        .unwrap_or(text.len());
    text[..end].trim().to_string()
}

/// Writes the WGSL of every n-th drawn formula to the sample folder, if asked.
fn sample_wgsl(config: &Config, case: &FormulaCase, drawn: usize) {
    let Some((dir, every)) = &config.wgsl_sample else {
        return;
    };
    if !drawn.is_multiple_of(*every.max(&1)) {
        return;
    }
    if let Ok(program) = fourfold::render::Program::new(&case.text()) {
        std::fs::create_dir_all(dir).ok();
        let name = dir.join(format!("case-{drawn:06}.wgsl"));
        let header = format!("// {}\n", case.text().replace('\n', " "));
        std::fs::write(name, header + &program.shader.source).ok();
    }
}

/// Arguments as a shell would take them.
fn quoted(args: &[String]) -> String {
    args.iter()
        .map(|a| {
            if a.chars()
                .all(|c| c.is_ascii_alphanumeric() || "-_.,=/".contains(c))
            {
                a.clone()
            } else {
                format!("'{}'", a.replace('\'', "'\\''"))
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}
