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

/// The tree settings of `scene` with the command-line overrides, checked.
fn tree_settings(
    scene: &Scene,
    max_level: Option<u32>,
    min_level: Option<u32>,
    node_budget: Option<u32>,
) -> Result<crate::tree::BuildSettings, Failure> {
    let mut s = scene.tree;
    if let Some(v) = max_level {
        s.max_level = v;
    }
    if let Some(v) = min_level {
        s.min_level = v;
    }
    if let Some(v) = node_budget {
        s.node_budget = v;
    }
    if s.max_level > crate::scene::MAX_TREE_LEVEL {
        return Err(Failure::usage(format!(
            "--max-level {}: the deepest level is {} (each level multiplies the boxes by up to 16)",
            s.max_level,
            crate::scene::MAX_TREE_LEVEL
        )));
    }
    if max_level.is_some() && min_level.is_none() && s.min_level > s.max_level {
        s.min_level = s.max_level;
    }
    if s.min_level > s.max_level {
        return Err(Failure::usage(format!(
            "--min-level {} is above --max-level {}: lower the first or raise the second",
            s.min_level, s.max_level
        )));
    }
    if s.node_budget < 16 {
        return Err(Failure::usage("--node-budget must be at least 16"));
    }
    Ok(s.into())
}

/// `fourfold tree`.
pub fn tree(args: &TreeArgs) -> Result<String, Failure> {
    use std::sync::atomic::AtomicBool;
    let scene = load_scene(&args.input)?;
    let formula = compile(&scene)?;
    for w in parameter_warnings(&scene, &formula) {
        eprintln!("{w}");
    }
    let settings = tree_settings(&scene, args.max_level, args.min_level, args.node_budget)?;
    let params = scene.param_values(&formula.param_names());
    let cancel = AtomicBool::new(false);
    let build =
        || crate::tree::Tree16::build(&formula, &params, &scene.domain, settings, &cancel, None);
    let tree = if args.single_thread {
        rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .map_err(|e| Failure::runtime(format!("cannot start a thread pool: {e}")))?
            .install(build)
    } else {
        build()
    }
    .map_err(|e| Failure::runtime(e.to_string()))?;
    let hierarchy = crate::tree::Hierarchy::from_tree(&tree);
    let s = &tree.stats;
    if args.json {
        let mut value = serde_json::to_value(s).expect("stats serialise");
        value["tree_bytes"] = value["bytes"].clone();
        value["bytes"] = hierarchy.bytes().into();
        value["max_level"] = settings.max_level.into();
        value["min_level"] = settings.min_level.into();
        value["node_budget"] = settings.node_budget.into();
        return Ok(value.to_string());
    }
    let mut out = String::new();
    out.push_str(&format!(
        "16-tree of F = {}\nlevels {}..{} (min..max), node budget {}\n\n",
        formula.f_text(),
        settings.min_level,
        settings.max_level,
        settings.node_budget
    ));
    out.push_str("level      kept    leaves  discarded\n");
    for l in 0..s.nodes_per_level.len().max(s.discarded_per_level.len()) {
        out.push_str(&format!(
            "{l:>5} {:>9} {:>9} {:>10}\n",
            s.nodes_per_level.get(l).copied().unwrap_or(0),
            s.leaves_per_level.get(l).copied().unwrap_or(0),
            s.discarded_per_level.get(l).copied().unwrap_or(0),
        ));
    }
    out.push_str(&format!(
        "\nnodes {}, leaves {}, hierarchy {} bytes, {} interval evaluations, built in {:.1} ms\n",
        s.nodes,
        s.leaves,
        hierarchy.bytes(),
        s.interval_evaluations,
        s.build_ms
    ));
    if tree.is_empty() {
        out.push_str(
            "no surface in this domain: F has no zero in the box (try a larger --domain)\n",
        );
    }
    if s.budget_hit {
        out.push_str(&format!(
            "node budget hit: refinement stopped after level {} (raise --node-budget or lower --max-level)\n",
            s.budget_level.unwrap_or(0)
        ));
    }
    if s.singular_boxes > 0 {
        out.push_str(&format!(
            "{} boxes at the maximum level may hold a critical point of F (0 in every partial): \
             M may be singular there\n",
            s.singular_boxes
        ));
    }
    Ok(out)
}
