//! The command line: argument types and the glue from them to the library. No maths here.

use std::path::{Path, PathBuf};

use clap::{Args, Parser, Subcommand};

use crate::formula::CompiledFormula;
use crate::scene::{Domain, Scene};

#[derive(Debug, Parser)]
#[command(
    name = "fourfold",
    version,
    about = "See the 3-manifold F(x,y,z,w) = 0 in four dimensions"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Parse a formula and report problems (exit 0 if fine, 2 if not).
    Check(Input),
    /// Print F and its four partial derivatives.
    Grad(Input),
    /// Build the 16-tree and print its statistics.
    Tree(TreeArgs),
    /// Print or write the generated, validated WGSL shader.
    Wgsl(WgslArgs),
    /// Render a picture to a PNG file.
    Render(RenderArgs),
    /// Open the interactive viewer (the default with no command).
    View(ViewArgs),
}

/// A formula or a scene file, with parameter overrides.
#[derive(Debug, Clone, Args)]
pub struct Input {
    /// A formula such as "x^2 + y^2 + z^2 + w^2 = 1", or the path of a .toml scene file.
    pub formula_or_scene: String,
    /// Set a parameter, as NAME=VALUE (repeatable).
    #[arg(long = "param", value_name = "NAME=VALUE")]
    pub params: Vec<String>,
    /// The domain box: x0,x1,y0,y1,z0,z1,w0,w1.
    #[arg(
        long,
        value_name = "x0,x1,y0,y1,z0,z1,w0,w1",
        allow_hyphen_values = true
    )]
    pub domain: Option<String>,
}

#[derive(Debug, Clone, Args)]
pub struct TreeArgs {
    #[command(flatten)]
    pub input: Input,
    #[arg(long)]
    pub max_level: Option<u32>,
    #[arg(long)]
    pub min_level: Option<u32>,
    /// Most nodes the tree may keep.
    #[arg(long)]
    pub node_budget: Option<u32>,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Build on one thread.
    #[arg(long)]
    pub single_thread: bool,
}

#[derive(Debug, Clone, Args)]
pub struct WgslArgs {
    #[command(flatten)]
    pub input: Input,
    /// Write to this file instead of standard output.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
}

#[derive(Debug, Clone, Args)]
pub struct RenderArgs {
    #[command(flatten)]
    pub input: Input,
    /// The PNG file to write.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Image size, WxH.
    #[arg(long, default_value = "512x512")]
    pub size: String,
    /// The six rotation angles θ1..θ6 in radians.
    #[arg(long, allow_hyphen_values = true)]
    pub angles: Option<String>,
    #[arg(long)]
    pub rays: Option<u32>,
    #[arg(long)]
    pub hits: Option<u32>,
    #[arg(long)]
    pub max_level: Option<u32>,
    #[arg(long)]
    pub min_level: Option<u32>,
    /// Background colour, RRGGBB.
    #[arg(long)]
    pub background: Option<String>,
    /// random (the chapter's) or stratified.
    #[arg(long)]
    pub sampling: Option<String>,
    #[arg(long)]
    pub alpha: Option<f64>,
    #[arg(long)]
    pub zoom: Option<f64>,
    #[arg(long)]
    pub no_silhouette: bool,
    #[arg(long)]
    pub no_border: bool,
    /// Flat colour instead of Phong lighting.
    #[arg(long)]
    pub no_lighting: bool,
    /// Render on the CPU with the reference ray caster instead of the GPU.
    #[arg(long)]
    pub cpu: bool,
}

#[derive(Debug, Clone, Args, Default)]
pub struct ViewArgs {
    /// A formula or scene file to open.
    pub formula_or_scene: Option<String>,
}

/// A user-facing failure: the text to print and the exit code.
#[derive(Debug)]
pub struct Failure {
    pub message: String,
    pub code: i32,
}

impl Failure {
    pub fn usage(message: impl Into<String>) -> Self {
        Self {
            message: message.into(),
            code: 2,
        }
    }
    pub fn runtime(message: impl Into<String>) -> Self {
        Self {
            message: message.into(),
            code: 1,
        }
    }
}

/// Loads the scene named by `input` (a file, or a formula with default settings) and applies
/// the command-line overrides.
pub fn load_scene(input: &Input) -> Result<Scene, Failure> {
    let text = &input.formula_or_scene;
    let looks_like_file = text.ends_with(".toml") || Path::new(text).is_file();
    let mut scene = if looks_like_file {
        Scene::load(Path::new(text)).map_err(|e| Failure::usage(e.to_string()))?
    } else {
        Scene::from_formula(text)
    };
    for assignment in &input.params {
        let (name, value) = assignment.split_once('=').ok_or_else(|| {
            Failure::usage(format!(
                "--param {assignment}: expected NAME=VALUE, as in --param R=2"
            ))
        })?;
        let value: f64 = value.trim().parse().map_err(|_| {
            Failure::usage(format!("--param {assignment}: '{value}' is not a number"))
        })?;
        if !value.is_finite() {
            return Err(Failure::usage(format!(
                "--param {assignment}: the value must be finite"
            )));
        }
        scene.params.insert(name.trim().to_string(), value);
    }
    if let Some(domain) = &input.domain {
        scene.domain = Domain::parse_list(domain)
            .map_err(|e| Failure::usage(format!("--domain {domain}: {e}")))?;
    }
    Ok(scene)
}

/// Compiles the scene's formula, or renders its error with a caret under the formula.
pub fn compile(scene: &Scene) -> Result<CompiledFormula, Failure> {
    CompiledFormula::compile(&scene.formula)
        .map_err(|e| Failure::usage(e.render("formula", &scene.formula)))
}

/// Warnings about parameters the formula uses but the scene does not set, or the reverse.
pub fn parameter_warnings(scene: &Scene, formula: &CompiledFormula) -> Vec<String> {
    let mut warnings = Vec::new();
    for p in &formula.params {
        if !scene.params.contains_key(&p.name) {
            warnings.push(format!(
                "warning: parameter {} has no value; using 1.0 (set it with --param {}=VALUE)",
                p.name, p.name
            ));
        }
    }
    for name in scene.params.keys() {
        if !formula.params.iter().any(|p| &p.name == name) {
            warnings.push(format!(
                "warning: parameter {name} is set but the formula does not use it"
            ));
        }
    }
    warnings
}

/// `fourfold check`.
pub fn check(input: &Input) -> Result<String, Failure> {
    let scene = load_scene(input)?;
    let formula = compile(&scene)?;
    for w in parameter_warnings(&scene, &formula) {
        eprintln!("{w}");
    }
    let params = formula.param_names();
    Ok(format!(
        "ok: F = {}\n{} graph nodes ({} evaluated for F, {} for F and its gradient); parameters: {}",
        formula.f_text(),
        formula.graph.len(),
        formula.tape_f.len(),
        formula.tape_all.len(),
        if params.is_empty() {
            "none".to_string()
        } else {
            params.join(", ")
        }
    ))
}

/// `fourfold grad`.
pub fn grad(input: &Input) -> Result<String, Failure> {
    let scene = load_scene(input)?;
    let formula = compile(&scene)?;
    for w in parameter_warnings(&scene, &formula) {
        eprintln!("{w}");
    }
    let [dx, dy, dz, dw] = formula.gradient_text();
    Ok(format!(
        "F     = {}\ndF/dx = {dx}\ndF/dy = {dy}\ndF/dz = {dz}\ndF/dw = {dw}",
        formula.f_text()
    ))
}
