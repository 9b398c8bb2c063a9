//! The command line: argument types and the glue from them to the library. No maths here.

use std::path::{Path, PathBuf};

use clap::{Args, Parser, Subcommand};

use crate::formula::CompiledFormula;
use crate::render::Gpu;
use crate::render::animation::{
    Animation, Drawn, FrameDevice, MAX_FRAMES, Output, Sweep, Turn, draw, parse_range,
};
use crate::render::framing::fit_scene;
use crate::render::{MAX_PICTURE_SIDE, Prepared};
use crate::scene::{Color, ColorBy, Domain, Sampling, Scene, Speaker, Undecided};
use crate::tree::BuildSettings;

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
    /// Render an animation (the manifold turning, or a parameter sweeping) to a GIF, an
    /// animated PNG or a folder of PNGs.
    Animate(AnimateArgs),
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
    /// Deepest level of the 16-tree (the scene's, else 6): each level halves the boxes'
    /// sides; boxes that may hold M are split down to it.
    #[arg(long, allow_hyphen_values = true)]
    pub max_level: Option<u32>,
    /// Level down to which every box is split, whatever the interval test says (the
    /// scene's, else 4; at most --max-level).
    #[arg(long, allow_hyphen_values = true)]
    pub min_level: Option<u32>,
    /// Most nodes the tree may keep.
    #[arg(long, allow_hyphen_values = true)]
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
    /// Rays per pixel in its observer plane, 1 to 1024 (the scene's, else 16): more rays
    /// miss less of M.
    #[arg(long, allow_hyphen_values = true)]
    pub rays: Option<u32>,
    /// Nearest hits kept and blended per pixel, 1 to 16 (the scene's, else 4).
    #[arg(long, allow_hyphen_values = true)]
    pub hits: Option<u32>,
    /// Deepest level of the 16-tree (the scene's, else 6): finer boxes, finer steps.
    #[arg(long, allow_hyphen_values = true)]
    pub max_level: Option<u32>,
    /// Level down to which every box is split (the scene's, else 4; at most --max-level).
    #[arg(long, allow_hyphen_values = true)]
    pub min_level: Option<u32>,
    /// Background colour, RRGGBB.
    #[arg(long)]
    pub background: Option<String>,
    /// random (the chapter's) or stratified.
    #[arg(long)]
    pub sampling: Option<String>,
    /// Steps m of the composite interval method per leaf span, 1 to 256 (the scene's, else
    /// 8): more find roots closer together.
    #[arg(long, allow_hyphen_values = true)]
    pub steps: Option<u32>,
    /// Most bisection iterations per root, 1 to 256 (the scene's, else 24).
    #[arg(long, allow_hyphen_values = true)]
    pub bisection_iters: Option<u32>,
    /// The bisection stops once |F| is below this, ≥ 0 (the scene's, else 1e-6).
    #[arg(long, allow_hyphen_values = true)]
    pub approximation: Option<f64>,
    /// Seed of the random rays and of the stratified offsets (the scene's, else 1).
    #[arg(long, allow_hyphen_values = true)]
    pub seed: Option<u32>,
    /// Weight of the nearer hit when blending, 0 to 1 (the scene's, else 0.7).
    #[arg(long, allow_hyphen_values = true)]
    pub alpha: Option<f64>,
    /// Magnification, above 0 (1: the whole domain fits the shorter side).
    #[arg(long, allow_hyphen_values = true)]
    pub zoom: Option<f64>,
    /// No highlight on the silhouette (where ∇F is almost perpendicular to both observer
    /// directions n1 and n2).
    #[arg(long)]
    pub no_silhouette: bool,
    /// March every ray across the whole domain (finest leaves' step) instead of the tree's
    /// boxes: the same picture, faster on some scenes and shallow trees.
    #[arg(long)]
    pub brute_force: bool,
    /// Certify every pixel (docs/method.md §5.9): prove it shows M (hit) or not (empty),
    /// or mark it undecided, and print the counts.
    #[arg(long)]
    pub certified: bool,
    /// Certified pixels: the most cells of a pixel's observer plane to enclose F over, 1 to
    /// 8192 (the scene's, else 2048); more decide more pixels, slower.
    #[arg(long, allow_hyphen_values = true)]
    pub cert_budget: Option<u32>,
    /// How undecided certified pixels are drawn: marker (magenta) or hatch (magenta stripes).
    #[arg(long)]
    pub undecided: Option<String>,
    /// No highlight near the faces of the domain.
    #[arg(long)]
    pub no_border: bool,
    /// Flat colour instead of Phong lighting.
    #[arg(long)]
    pub no_lighting: bool,
    /// Render on the CPU with the reference ray caster instead of the GPU.
    #[arg(long)]
    pub cpu: bool,
    /// Zoom and centre on the manifold (the tree's boxes at these angles) instead of the
    /// scene's zoom and pan, as the viewer does when it opens a scene.
    #[arg(long)]
    pub fit: bool,
    /// Only the slab of the observer planes whose coordinate along n2, from the domain's
    /// centre, is within H of C, as C,H (H ≥ 0; a slab wider than the domain is the whole
    /// projection, one outside it draws nothing).
    #[arg(long, value_name = "C,H", allow_hyphen_values = true)]
    pub slab: Option<String>,
    /// The cut of M by the hyperplane at C along n2 (from the domain's centre), a surface
    /// seen along n1 (one ray per pixel); one outside the domain draws nothing.
    #[arg(
        long,
        value_name = "C",
        allow_hyphen_values = true,
        conflicts_with = "slab"
    )]
    pub slice: Option<f64>,
    /// What colours a hit: surface (the lighting's colour) or hidden (its place along the
    /// hidden direction n2, from dark blue at -R to yellow at +R, R the domain's half
    /// diagonal: the viridis map).
    #[arg(long, visible_alias = "color-by", value_name = "surface|hidden")]
    pub colour_by: Option<String>,
}

#[derive(Debug, Clone, Args)]
pub struct AnimateArgs {
    /// The picture's settings, as for `render`; OUT (-o) names a .gif, an animated .png,
    /// or a folder for numbered PNGs.
    #[command(flatten)]
    pub render: RenderArgs,
    /// Turn the manifold in a plane, as PLANE[:TURNS]: xy, yz, zw, xz, xw or yw (or
    /// θ1..θ6, also t1..t6, one of the view's angles), TURNS full turns (default 1).
    #[arg(long, allow_hyphen_values = true)]
    pub turn: Option<String>,
    /// Move a parameter from A to B, as NAME=A..B (the tree is rebuilt for each frame).
    #[arg(long, allow_hyphen_values = true)]
    pub sweep: Option<String>,
    /// Move a slice (the cut by the hyperplane at C along n2) from A to B, as A..B.
    #[arg(long, value_name = "A..B", allow_hyphen_values = true)]
    pub slice_sweep: Option<String>,
    /// Frames, 1 to 10000.
    #[arg(long, default_value_t = 60, allow_hyphen_values = true)]
    pub frames: u32,
    /// Frames per second of the file, above 0 and at most 100.
    #[arg(long, default_value_t = 24.0, allow_hyphen_values = true)]
    pub fps: f64,
}

#[derive(Debug, Clone, Args, Default)]
pub struct ViewArgs {
    /// A formula, a scene file, or a share link of the web page (`…/index.html#formula=…`).
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
        scene.params.insert(name.trim().to_string(), value);
    }
    if let Some(domain) = &input.domain {
        scene.domain = Domain::parse_list(domain)
            .map_err(|e| Failure::usage(format!("--domain {domain}: {e}")))?;
    }
    checked(scene)
}

/// The scene, if the flags applied to it left every value in range (the scene file's own
/// values were checked when it was read): else the problem, naming the flag.
fn checked(scene: Scene) -> Result<Scene, Failure> {
    match scene.check() {
        Ok(()) => Ok(scene),
        Err(problem) => Err(Failure::usage(problem.message(Speaker::Flag))),
    }
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
        "ok: F = {}\n{} graph nodes ({} evaluated for F, {} for F and its gradient, {} with the second derivatives); parameters: {}",
        formula.f_text(),
        formula.graph.len(),
        formula.tape_f.len(),
        formula.tape_all.len(),
        formula.tape_second.len(),
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

/// Sets the tree levels and node budget given on the command line. A lower max level alone
/// takes the min level down with it, so `--max-level 3` works on a scene whose min level is 4.
fn override_tree(
    scene: &mut Scene,
    max_level: Option<u32>,
    min_level: Option<u32>,
    node_budget: Option<u32>,
) {
    let t = &mut scene.tree;
    if let Some(v) = max_level {
        t.max_level = v;
        if min_level.is_none() {
            t.min_level = t.min_level.min(v);
        }
    }
    if let Some(v) = min_level {
        t.min_level = v;
    }
    if let Some(v) = node_budget {
        t.node_budget = v;
    }
}

/// `fourfold tree`.
pub fn tree(args: &TreeArgs) -> Result<String, Failure> {
    let mut scene = load_scene(&args.input)?;
    override_tree(&mut scene, args.max_level, args.min_level, args.node_budget);
    let scene = checked(scene)?;
    let formula = compile(&scene)?;
    for w in parameter_warnings(&scene, &formula) {
        eprintln!("{w}");
    }
    let settings: BuildSettings = scene.tree.into();
    let build = || Prepared::new(&formula, &scene);
    let Prepared {
        tree, hierarchy, ..
    } = if args.single_thread {
        rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .map_err(|e| Failure::runtime(format!("cannot start a thread pool: {e}")))?
            .install(build)
    } else {
        build()
    }
    .map_err(|e| Failure::runtime(e.to_string()))?;
    let s = &tree.stats;
    if args.json {
        let mut value = serde_json::to_value(s).expect("stats serialise");
        value["tree_bytes"] = value["bytes"].clone();
        value["bytes"] = hierarchy.bytes().into();
        value["march_level"] = hierarchy.march_level.into();
        value["gpu_nodes"] = hierarchy.nodes.len().into();
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
        "\nnodes {}, leaves {}, hierarchy for the GPU {} bytes ({} nodes, marched as {}), {} interval evaluations, built in {:.1} ms\n",
        s.nodes,
        s.leaves,
        hierarchy.bytes(),
        hierarchy.nodes.len(),
        hierarchy.march_summary(),
        s.interval_evaluations,
        s.build_ms
    ));
    if s.mean_value_discarded > 0 {
        out.push_str(&format!(
            "discarded by the mean-value form of F (the natural interval extension held 0): {}\n",
            s.mean_value_discarded
        ));
    }
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

/// `fourfold wgsl`.
pub fn wgsl(args: &WgslArgs) -> Result<String, Failure> {
    let scene = load_scene(&args.input)?;
    let formula = compile(&scene)?;
    let shader =
        crate::render::codegen::generate(&formula).map_err(|e| Failure::runtime(e.to_string()))?;
    let params = formula
        .params
        .iter()
        .enumerate()
        .map(|(i, p)| format!("{i} = {}", p.name))
        .collect::<Vec<_>>()
        .join(", ");
    let header = format!(
        "// Generated by fourfold for F = {}\n// Parameters (uniform params[i/4][i%4]): {}\n",
        formula.f_text(),
        if params.is_empty() { "none" } else { &params }
    );
    let text = header + &shader.source;
    match &args.output {
        Some(path) => {
            std::fs::write(path, &text)
                .map_err(|e| Failure::runtime(format!("cannot write {}: {e}", path.display())))?;
            Ok(format!(
                "wrote {} ({} bytes, validated by naga)",
                path.display(),
                text.len()
            ))
        }
        None => Ok(text),
    }
}

fn parse_size(text: &str) -> Result<(u32, u32), Failure> {
    let bad = || {
        Failure::usage(format!(
            "--size {text}: expected WIDTHxHEIGHT, as in 512x512"
        ))
    };
    let (w, h) = text.split_once(['x', 'X']).ok_or_else(bad)?;
    let (w, h): (u32, u32) = (
        w.trim().parse().map_err(|_| bad())?,
        h.trim().parse().map_err(|_| bad())?,
    );
    if !(1..=MAX_PICTURE_SIDE).contains(&w) || !(1..=MAX_PICTURE_SIDE).contains(&h) {
        return Err(Failure::usage(format!(
            "--size {text}: each side must be between 1 and {MAX_PICTURE_SIDE}"
        )));
    }
    Ok((w, h))
}

/// The scene of a `render` command, with every flag applied and checked.
pub fn render_scene_of(args: &RenderArgs) -> Result<Scene, Failure> {
    let mut scene = load_scene(&args.input)?;
    override_tree(&mut scene, args.max_level, args.min_level, None);
    if let Some(text) = &args.angles {
        scene.view.angles = parse_angles(text)?;
    }
    if let Some(z) = args.zoom {
        scene.view.zoom = z;
    }
    if let Some(text) = &args.slab {
        let values: Vec<f64> = text
            .split(',')
            .map(|v| v.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| Failure::usage(format!("--slab {text}: expected two numbers C,H")))?;
        let [c, h] = values[..] else {
            return Err(Failure::usage(format!(
                "--slab {text}: expected two numbers C,H, got {}",
                values.len()
            )));
        };
        scene.view.slab = Some([c, h]);
        scene.view.slice = None;
    }
    if let Some(c) = args.slice {
        scene.view.slice = Some(c);
        scene.view.slab = None;
    }
    let r = &mut scene.render;
    if let Some(bg) = &args.background {
        r.background =
            Color::parse(bg).map_err(|e| Failure::usage(format!("--background: {e}")))?;
    }
    if let Some(word) = &args.sampling {
        let choices = [
            ("random", Sampling::Random),
            ("stratified", Sampling::Stratified),
        ];
        r.sampling = choice("sampling", word, choices)?;
    }
    let counts = [
        (args.rays, &mut r.rays),
        (args.hits, &mut r.hits),
        (args.steps, &mut r.steps),
        (args.bisection_iters, &mut r.bisection_iters),
        (args.seed, &mut r.seed),
        (args.cert_budget, &mut r.cert_budget),
    ];
    for (flag, field) in counts {
        if let Some(v) = flag {
            *field = v;
        }
    }
    for (flag, field) in [
        (args.approximation, &mut r.approximation),
        (args.alpha, &mut r.alpha),
    ] {
        if let Some(v) = flag {
            *field = v;
        }
    }
    if let Some(word) = &args.colour_by {
        let choices = [("surface", ColorBy::Surface), ("hidden", ColorBy::Hidden)];
        r.color_by = choice("colour-by", word, choices)?;
    }
    if let Some(word) = &args.undecided {
        let choices = [("marker", Undecided::Marker), ("hatch", Undecided::Hatch)];
        r.undecided = choice("undecided", word, choices)?;
    }
    r.certified |= args.certified;
    r.brute_force |= args.brute_force;
    r.silhouette.enabled &= !args.no_silhouette;
    r.border.enabled &= !args.no_border;
    r.lighting.enabled &= !args.no_lighting;
    checked(scene)
}

/// `--angles a,b,c,d,e,f`.
fn parse_angles(text: &str) -> Result<[f64; 6], Failure> {
    let values: Vec<f64> = text
        .split(',')
        .map(|v| v.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| {
            Failure::usage(format!("--angles {text}: expected six numbers a,b,c,d,e,f"))
        })?;
    values.try_into().map_err(|v: Vec<f64>| {
        Failure::usage(format!(
            "--angles {text}: expected six numbers, got {}",
            v.len()
        ))
    })
}

/// `fourfold render`.
pub fn render(args: &RenderArgs) -> Result<String, Failure> {
    use crate::render::pipeline::{Device, render_prepared};
    let mut scene = render_scene_of(args)?;
    let (width, height) = parse_size(&args.size)?;
    let t = std::time::Instant::now();
    let formula = compile(&scene)?;
    let parse_ms = t.elapsed().as_secs_f64() * 1e3;
    for w in parameter_warnings(&scene, &formula) {
        eprintln!("{w}");
    }
    let device = if args.cpu {
        Device::Cpu
    } else {
        Device::NewGpu
    };
    let prepared = Prepared::new(&formula, &scene).map_err(|e| Failure::runtime(e.to_string()))?;
    if args.fit {
        fit_scene(&mut scene, &prepared.hierarchy, width, height);
    }
    let picture = render_prepared(
        &scene,
        &formula,
        &prepared,
        width,
        height,
        device,
        Default::default(),
    );
    let mut picture = picture.map_err(|e| Failure::runtime(e.to_string()))?;
    picture.times.parse_ms = parse_ms;
    let cut = picture.cut_pixels.len();
    let verdicts = picture.verdict_counts();
    let image = image::RgbaImage::from_raw(width, height, picture.rgba)
        .ok_or_else(|| Failure::runtime("internal error: wrong image size"))?;
    image
        .save(&args.output)
        .map_err(|e| Failure::runtime(format!("cannot write {}: {e}", args.output.display())))?;
    let t = &picture.times;
    let mut out = format!(
        "adapter: {}\ntree: {} nodes, {} leaves{}{}\ntimes (ms): parse {:.1}, tree {:.1}, codegen+validate {:.1}, pipeline {:.1}, frame {:.1}{}\nwrote {} ({width}x{height})",
        picture.adapter,
        picture.tree.nodes,
        picture.tree.leaves,
        if picture.tree.budget_hit {
            " (node budget hit)"
        } else {
            ""
        },
        match picture.marched {
            Some(cut) => format!("; marched as {cut}"),
            None if picture.tree.nodes > 0 => {
                "; brute force: every ray marched across the domain".to_string()
            }
            None => String::new(),
        },
        t.parse_ms,
        t.tree_ms,
        t.codegen_ms,
        t.pipeline_ms,
        t.frame_ms,
        t.gpu_ms
            .map(|g| format!(" (of which the GPU's pass {g:.1})"))
            .unwrap_or_default(),
        args.output.display()
    );
    if scene.render.color_by == ColorBy::Hidden {
        let camera = crate::render::Camera::new(&scene.domain, &scene.view, width, height);
        let [lo, hi] =
            crate::render::uniforms::hidden_range(&prepared.hierarchy, &scene.domain, &camera);
        out.push_str(&format!(
            "\ncolour by the hidden direction: n2 = {lo:.3} (dark blue) to {hi:.3} (yellow), \
             from the domain's centre"
        ));
    }
    if let Some(counts) = verdicts {
        out.push_str(&format!(
            "\ncertified pixels (budget {} cells): {counts}",
            scene.render.cert_budget
        ));
        if counts.undecided > 0 {
            out.push_str(&format!(
                "\nundecided pixels are drawn {} where no ray found a hit; {}",
                match scene.render.undecided {
                    Undecided::Marker => "magenta",
                    Undecided::Hatch => "in magenta stripes",
                },
                crate::render::certify::undecided_advice(
                    prepared.hierarchy.continuous,
                    "--cert-budget"
                )
            ));
        }
    }
    if picture.tree.nodes == 0 {
        out.push_str("\nno surface in this domain: the picture shows only the background");
    }
    if cut > 0 {
        out.push_str(&cut_warning(&format!(
            "{cut} pixels ({:.1}% of the picture)",
            100.0 * cut as f64 / (f64::from(width) * f64::from(height))
        )));
    }
    Ok(out)
}

/// The animation an `animate` command asks for, checked.
pub fn animation_of(args: &AnimateArgs, formula: &CompiledFormula) -> Result<Animation, Failure> {
    let turn = args
        .turn
        .as_deref()
        .map(Turn::parse)
        .transpose()
        .map_err(|e| Failure::usage(format!("--turn: {e}")))?;
    let sweep = args
        .sweep
        .as_deref()
        .map(Sweep::parse)
        .transpose()
        .map_err(|e| Failure::usage(format!("--sweep: {e}")))?;
    if let Some(s) = &sweep
        && !formula.params.iter().any(|p| p.name == s.name)
    {
        let names = formula.param_names();
        return Err(Failure::usage(format!(
            "--sweep {}: the formula has no parameter {} (its parameters: {})",
            s.name,
            s.name,
            if names.is_empty() {
                "none".to_string()
            } else {
                names.join(", ")
            }
        )));
    }
    if !(1..=MAX_FRAMES).contains(&args.frames) {
        return Err(Failure::usage(format!(
            "--frames {}: between 1 and {MAX_FRAMES}",
            args.frames
        )));
    }
    if !(args.fps > 0.0 && args.fps <= 100.0) {
        return Err(Failure::usage(format!(
            "--fps {}: above 0 and at most 100",
            args.fps
        )));
    }
    let slice_sweep = args
        .slice_sweep
        .as_deref()
        .map(parse_range)
        .transpose()
        .map_err(|e| Failure::usage(format!("--slice-sweep: {e}")))?;
    if turn.is_none() && sweep.is_none() && slice_sweep.is_none() {
        return Err(Failure::usage(
            "nothing moves: give --turn PLANE (as in --turn xw), --sweep NAME=A..B or \
             --slice-sweep A..B",
        ));
    }
    Ok(Animation {
        turn,
        sweep,
        slice_sweep,
        frames: args.frames,
        fps: args.fps,
    })
}

/// The value `word` of `--flag`, one of two `choices`; else a usage error naming them.
fn choice<T: Copy>(flag: &str, word: &str, choices: [(&str, T); 2]) -> Result<T, Failure> {
    let [(a, _), (b, _)] = choices;
    choices
        .iter()
        .find(|(name, _)| *name == word)
        .map(|&(_, value)| value)
        .ok_or_else(|| Failure::usage(format!("--{flag} {word}: use {a} or {b}")))
}

/// The warning for pixels whose work the GPU driver cut short (`which`: how many, of what).
fn cut_warning(which: &str) -> String {
    format!(
        "\nwarning: the GPU driver cut the work of {which} short (llvmpipe stops a shader's \
         loops after 65535 iterations), so they may miss parts of the manifold. Lower --rays, \
         the scene's steps or --max-level, or render with --cpu."
    )
}

/// `fourfold animate`.
pub fn animate(args: &AnimateArgs) -> Result<String, Failure> {
    use std::io::IsTerminal;
    use std::sync::Arc;
    use std::sync::atomic::AtomicBool;
    let scene = render_scene_of(&args.render)?;
    let (width, height) = parse_size(&args.render.size)?;
    let formula = compile(&scene)?;
    for w in parameter_warnings(&scene, &formula) {
        eprintln!("{w}");
    }
    let animation = animation_of(args, &formula)?;
    let output = Output::from_path(&args.render.output).map_err(Failure::usage)?;
    let mut writer = output
        .open(width, height, animation.fps, animation.frames)
        .map_err(Failure::usage)?;
    // Ctrl-C stops after the frame being drawn and finishes the file with the frames so far.
    let stop = Arc::new(AtomicBool::new(false));
    {
        let stop = stop.clone();
        let _ = ctrlc::set_handler(move || stop.store(true, std::sync::atomic::Ordering::Relaxed));
    }
    let gpu = if args.render.cpu {
        None
    } else {
        Some(Gpu::new().map_err(|e| Failure::runtime(e.to_string()))?)
    };
    let device = match &gpu {
        Some(gpu) => FrameDevice::Gpu(gpu),
        None => FrameDevice::Cpu,
    };
    let terminal = std::io::stderr().is_terminal();
    let bar = indicatif::ProgressBar::new(u64::from(animation.frames));
    if terminal {
        bar.set_style(
            indicatif::ProgressStyle::with_template(
                "{bar:40} {pos}/{len} frames, {elapsed} so far, {eta} left",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
    } else {
        bar.set_draw_target(indicatif::ProgressDrawTarget::hidden());
    }
    let started = std::time::Instant::now();
    let drawn = draw(
        &scene,
        &formula,
        &animation,
        width,
        height,
        args.render.fit,
        device,
        &stop,
        |k, rgba| {
            writer.add(rgba)?;
            bar.inc(1);
            if !terminal {
                eprintln!("frame {}/{}", k + 1, animation.frames);
            }
            Ok(())
        },
    );
    bar.finish_and_clear();
    // The frames drawn so far are written whatever stopped the drawing.
    let wrote = writer.finish().map_err(Failure::runtime)?;
    let Drawn {
        frames: drawn,
        verdicts,
        cut,
    } = drawn.map_err(Failure::runtime)?;
    let seconds = started.elapsed().as_secs_f64();
    let adapter = gpu
        .as_ref()
        .map_or("CPU reference renderer", |g| g.adapter.as_str());
    let mut out = format!(
        "adapter: {adapter}
wrote {wrote}, {width}x{height} at {} fps
drew {drawn} frames in {seconds:.1} s ({:.1} frames per second)",
        animation.fps,
        f64::from(drawn) / seconds.max(1e-9)
    );
    if let Some(counts) = verdicts {
        out.push_str(&format!(
            "\ncertified pixels over {drawn} frames (budget {} cells): {counts}",
            scene.render.cert_budget
        ));
    }
    if cut > 0 {
        out.push_str(&cut_warning(&format!("{cut} pixels over {drawn} frames")));
    }
    if drawn < animation.frames {
        out.push_str(&format!(
            "
stopped after {drawn} of {} frames",
            animation.frames
        ));
    }
    Ok(out)
}

/// `fourfold` / `fourfold view [FORMULA_OR_SCENE]`: opens the viewer window.
pub fn view(args: &ViewArgs) -> Result<String, Failure> {
    let linked = args
        .formula_or_scene
        .as_deref()
        .is_some_and(crate::scene::link::is_link);
    let scene = match &args.formula_or_scene {
        None => None,
        Some(text) if text.ends_with(".toml") || Path::new(text).is_file() => {
            Some(Scene::load(Path::new(text)).map_err(|e| Failure::usage(e.to_string()))?)
        }
        Some(text) if crate::scene::link::is_link(text) => {
            let (scene, problems) = Scene::from_link(text, &crate::viewer::app::default_scene());
            // As the web page does: open what the link says, and tell what it left out.
            for problem in problems {
                eprintln!("{problem} (left at its default)");
            }
            Some(scene)
        }
        Some(text) => Some(Scene::from_formula(text)),
    };
    crate::viewer::run(scene, !linked).map_err(Failure::runtime)?;
    Ok(String::new())
}
