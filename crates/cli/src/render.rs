//! `fourfold render`: one picture to a PNG file, with the flags that override the scene's
//! settings (each checked by the library's scene rules, so a flag and a scene key share
//! their ranges and messages), and what the picture's making says.

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use clap::Args;

use fourfold::headless::render_fitted;
use fourfold::render::gpu::CacheUse;
use fourfold::render::view::{Section, scene_hidden_range};
use fourfold::render::{
    CPU_SLICE_PIXELS_PER_THREAD, Device, Gpu, Prepared, cpu_slice_pixels, sooner_on_cpu,
};
use fourfold::scene::{Color, ColorBy, MAX_PICTURE_SIDE, Sampling, Scene, Undecided};
use fourfold::tree::TreeStats;

use crate::failure::Failure;
use crate::input::{
    Input, Warn, checked, compile_warning, folder_exists, load_scene, override_tree,
};

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
    /// or mark it undecided, and print the counts. The default; overrides a scene file's
    /// `certified = false`.
    #[arg(long, conflicts_with = "uncertified")]
    pub certified: bool,
    /// Draw the plain ray pencil without proving pixels (faster; a single pass may miss thin
    /// parts of M): the scene key `certified = false`.
    #[arg(long)]
    pub uncertified: bool,
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
    /// Render on the CPU with the reference ray caster instead of the GPU. The default
    /// for a slice of at most 2^17 pixels per thread of this machine, which the CPU draws
    /// sooner than a GPU can be opened for it.
    #[arg(long, conflicts_with = "gpu")]
    pub cpu: bool,
    /// Render on the GPU, a small slice too.
    #[arg(long)]
    pub gpu: bool,
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

pub fn parse_size(text: &str) -> Result<(u32, u32), Failure> {
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

/// Checks `--output` before anything is drawn, so that a long render is not lost to a name
/// it cannot be written under: a PNG file (any name but another picture kind's) in a
/// folder that exists.
pub fn check_output(path: &Path) -> Result<(), Failure> {
    let shown = path.display();
    if path.as_os_str().is_empty() || path.to_string_lossy().ends_with('/') || path.is_dir() {
        return Err(Failure::usage(format!(
            "--output {shown}: name a file to write the PNG to, as in {}",
            path.join("picture.png").display()
        )));
    }
    if let Some(e) = path.extension().and_then(|e| e.to_str())
        && !e.eq_ignore_ascii_case("png")
    {
        return Err(Failure::usage(format!(
            "--output {shown}: fourfold writes PNG pictures, not '.{e}': name it {}",
            path.with_extension("png").display()
        )));
    }
    folder_exists("--output", path)
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
    r.certified = (r.certified || args.certified) && !args.uncertified;
    r.brute_force |= args.brute_force;
    r.silhouette.enabled &= !args.no_silhouette;
    r.border.enabled &= !args.no_border;
    r.lighting.enabled &= !args.no_lighting;
    checked(scene)
}

/// `--angles a,b,c,d,e,f`.
pub(crate) fn parse_angles(text: &str) -> Result<[f64; 6], Failure> {
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

/// What `render` says of the tree it drew from: its size, whether it was built within the
/// slice's hyperplane or the slab's band (`within`), and the cut the rays march.
fn tree_line(tree: &TreeStats, marched: Option<&str>, within: Option<Section>) -> String {
    format!(
        "tree: {} nodes, {} leaves{}{}{}",
        tree.nodes,
        tree.leaves,
        match within {
            None | Some(Section::Plane) => "",
            Some(Section::Slab { .. }) => " (within the slab)",
            Some(Section::Slice { .. }) => " (within the slice's hyperplane)",
        },
        if tree.budget_hit {
            " (node budget hit)"
        } else {
            ""
        },
        match marched {
            Some(cut) => format!("; marched as {cut}"),
            None if tree.nodes > 0 => {
                "; brute force: every ray marched across the domain".to_string()
            }
            None => String::new(),
        },
    )
}

/// `fourfold render`.
pub fn render(args: &RenderArgs, warn: Warn) -> Result<String, Failure> {
    check_output(&args.output)?;
    let scene = render_scene_of(args)?;
    let (width, height) = parse_size(&args.size)?;
    let t = std::time::Instant::now();
    let formula = compile_warning(&scene, warn)?;
    let parse_ms = t.elapsed().as_secs_f64() * 1e3;
    let t = std::time::Instant::now();
    let chosen = !args.cpu && !args.gpu && sooner_on_cpu(&scene, width, height);
    let gpu = if args.cpu || chosen {
        None
    } else {
        Some(Gpu::new().map_err(|e| Failure::runtime(e.to_string()))?)
    };
    let open_ms = t.elapsed().as_secs_f64() * 1e3;
    let device = gpu.as_ref().map_or(Device::Cpu, Device::Gpu);
    let prepared = Prepared::for_picture(&formula, &scene, args.fit, &AtomicBool::new(false))
        .map_err(|e| Failure::runtime(e.to_string()))?;
    let (mut picture, scene) =
        render_fitted(scene, &formula, &prepared, width, height, device, args.fit)
            .map_err(|e| Failure::runtime(e.to_string()))?;
    picture.times.parse_ms = parse_ms;
    let cut = picture.cut_pixels.len();
    let verdicts = picture.verdict_counts();
    let t = std::time::Instant::now();
    let png = picture.to_png().map_err(Failure::runtime)?;
    std::fs::write(&args.output, png)
        .map_err(|e| Failure::runtime(format!("cannot write {}: {e}", args.output.display())))?;
    let png_ms = t.elapsed().as_secs_f64() * 1e3;
    let t = &picture.times;
    // The slice or slab the tree was built within, if any.
    let within = prepared.region.map(|_| Section::of(&scene.view));
    let mut out = format!(
        "adapter: {}\n{}\ntimes (ms): {}parse {:.1}, tree {:.1}, codegen+validate {:.1}, pipeline {:.1}{}, frame {:.1}{}, PNG {png_ms:.1}\nwrote {} ({width}x{height})",
        picture.adapter,
        tree_line(&picture.tree, picture.marched.as_deref(), within),
        if gpu.is_some() {
            format!("GPU opened {open_ms:.1}, ")
        } else {
            String::new()
        },
        t.parse_ms,
        t.tree_ms,
        t.codegen_ms,
        t.pipeline_ms,
        cache_note(&t.pipeline_cache),
        t.frame_ms,
        t.gpu_ms
            .map(|g| format!(" (of which the GPU's pass {g:.1})"))
            .unwrap_or_default(),
        args.output.display()
    );
    if let Some(warning) = t.pipeline_cache.warning() {
        out.push_str(&format!("\nwarning: {warning}"));
    }
    if chosen {
        out.push_str(&format!(
            "\ndrawn on the CPU: a slice of up to {} pixels ({CPU_SLICE_PIXELS_PER_THREAD} a \
             thread) is done there before a GPU could be opened for it (--gpu draws it on the \
             GPU)",
            cpu_slice_pixels()
        ));
    }
    if scene.render.color_by == ColorBy::Hidden {
        let [lo, hi] = scene_hidden_range(&prepared.hierarchy, &scene);
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
                fourfold::render::verdict::undecided_advice(
                    prepared.hierarchy.continuous,
                    picture.tree.touching(),
                    "--cert-budget"
                )
            ));
        }
    }
    if picture.tree.nodes == 0 {
        let part = match within {
            Some(Section::Slice { .. }) => Some("slice"),
            Some(Section::Slab { .. }) => Some("slab"),
            _ => None,
        };
        out.push_str(&match part {
            Some(part) => format!(
                "\nno surface in this {part} of the domain: the picture shows only the \
                 background (the projection, without --{part}, shows where M lies along n2)"
            ),
            None => "\nno surface in this domain: the picture shows only the background".into(),
        });
    }
    if let Some(note) = fourfold::render::verdict::touching_note(&picture.tree) {
        out.push_str(&format!("\nnote: {note}"));
    }
    if cut > 0 {
        out.push_str(&cut_warning(&format!(
            "{cut} pixels ({:.1}% of the picture)",
            100.0 * cut as f64 / (f64::from(width) * f64::from(height))
        )));
    }
    Ok(out)
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

/// What the pipeline stage made of the cache kept between runs, for the times line.
fn cache_note(cache: &CacheUse) -> String {
    match cache {
        CacheUse::Off => String::new(),
        CacheUse::New => " (pipeline cache: new)".into(),
        CacheUse::Loaded { bytes } => format!(" (pipeline cache: {bytes} bytes loaded)"),
        CacheUse::Ignored { .. } | CacheUse::Unwritable { .. } => {
            " (pipeline cache: see the warning)".into()
        }
    }
}

/// How the warning for pixels cut short begins (what a program reading the output may look
/// for).
pub const CUT_WARNING: &str = "warning: the GPU driver cut the work of";

/// The warning for pixels whose work the GPU driver cut short (`which`: how many, of what).
pub fn cut_warning(which: &str) -> String {
    format!(
        "\n{CUT_WARNING} {which} short (llvmpipe stops a shader's \
         loops after 65535 iterations), so they may miss parts of the manifold. Lower --rays, \
         the scene's steps or --max-level, or render with --cpu."
    )
}
