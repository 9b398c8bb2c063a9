//! `fourfold animate`: the manifold turning, a parameter sweeping or a slice moving, drawn
//! frame after frame into a GIF, an animated PNG or a folder, with a progress bar; Ctrl-C
//! stops and keeps the frames drawn so far.

use clap::Args;

use fourfold::critical::sweep::{place_frames, straddle_lines};
use fourfold::formula::CompiledFormula;
use fourfold::headless::{Drawn, FrameDevice, Output, draw};
use fourfold::render::Gpu;
use fourfold::render::animation::{
    Animation, Sweep, Turn, fps_problem, frames_problem, parse_range,
};

use crate::failure::Failure;
use crate::input::{Warn, compile_warning};
use crate::render::{RenderArgs, cut_warning, parse_size, render_scene_of};

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
    if let Some(s) = &sweep {
        formula
            .check_param(&s.name)
            .map_err(|e| Failure::usage(format!("--sweep {}: {e}", s.name)))?;
    }
    if let Some(problem) = frames_problem(args.frames) {
        return Err(Failure::usage(format!(
            "--frames {}: {problem}",
            args.frames
        )));
    }
    if let Some(problem) = fps_problem(args.fps) {
        return Err(Failure::usage(format!("--fps {}: {problem}", args.fps)));
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
        slice_places: Vec::new(),
        frames: args.frames,
        fps: args.fps,
    })
}

/// `fourfold animate`.
pub fn animate(args: &AnimateArgs, warn: Warn) -> Result<String, Failure> {
    use std::io::IsTerminal;
    use std::sync::Arc;
    use std::sync::atomic::AtomicBool;
    let mut scene = render_scene_of(&args.render)?;
    // The swept parameter has a value in every frame: no warning that it has none.
    if let Some(Ok(sweep)) = args.sweep.as_deref().map(Sweep::parse) {
        scene.params.entry(sweep.name).or_insert(sweep.from);
    }
    let (width, height) = parse_size(&args.render.size)?;
    let formula = compile_warning(&scene, warn)?;
    let mut animation = animation_of(args, &formula)?;
    let critical = place_frames(&mut animation, &formula, &scene);
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
    if let Some(report) = critical {
        let lines = straddle_lines(&animation.slice_places, &report);
        if lines.is_empty() {
            out.push_str(
                "\nno critical value within the sweep: every frame's slice has the same topology",
            );
        }
        for line in lines {
            out.push_str(&format!("\n{line}"));
        }
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
