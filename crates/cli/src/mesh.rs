//! `fourfold mesh`: the slice's mesh to an STL, OBJ, PLY or GLB file, in the slice's own units or
//! scaled to millimetres for a printer, and what the mesher found.

use std::path::PathBuf;

use clap::Args;

use fourfold::mesh::{MeshError, MeshFormat, MeshSettings, describe_slice, mesh_slice};
use fourfold::scene::limits::DEFAULT_MESH_LEVEL;

use crate::failure::Failure;
use crate::input::{Input, Warn, checked, compile_warning, folder_exists, load_scene};
use crate::render::parse_angles;

/// The largest print side --size takes, in millimetres.
const MAX_PRINT_MM: f64 = 10_000.0;

#[derive(Debug, Clone, Args)]
pub struct MeshArgs {
    #[command(flatten)]
    pub input: Input,
    /// The mesh file to write: .stl (binary), .obj, .ply (binary) or .glb (binary glTF).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Where the hyperplane cuts, along n2 from the domain's centre (the scene's slice if
    /// it has one).
    #[arg(long, value_name = "C", allow_hyphen_values = true)]
    pub slice: Option<f64>,
    /// The six rotation angles θ1..θ6 in radians: n2 is the fourth row of the rotation.
    #[arg(long, allow_hyphen_values = true)]
    pub angles: Option<String>,
    /// Levels of the octree, 1 to 10: the finest cells are the slice's extent / 2^level.
    #[arg(long, default_value_t = DEFAULT_MESH_LEVEL, allow_hyphen_values = true)]
    pub max_level: u32,
    /// How far a vertex may lie from the surface (|F|/|∇F| in the slice's units) before it
    /// is moved onto it (default: a hundredth of a finest cell).
    #[arg(long, allow_hyphen_values = true)]
    pub tolerance: Option<f64>,
    /// Leave the cut open where M leaves the domain, instead of closing the solid with the
    /// domain's faces.
    #[arg(long)]
    pub open: bool,
    /// model (the slice's own units: lengths and volumes are R⁴'s) or mm (scaled so the
    /// longest side is --size millimetres).
    #[arg(long, default_value = "model")]
    pub units: String,
    /// With --units mm: the longest side of the print, in millimetres (default 100).
    #[arg(long, allow_hyphen_values = true)]
    pub size: Option<f64>,
}

/// `fourfold mesh`.
pub fn mesh(args: &MeshArgs, warn: Warn) -> Result<String, Failure> {
    let format =
        MeshFormat::from_path(&args.output).map_err(|e| Failure::usage(format!("-o: {e}")))?;
    folder_exists("-o", &args.output)?;
    let mm = print_size(args)?;
    let mut scene = load_scene(&args.input)?;
    if let Some(text) = &args.angles {
        scene.view.angles = parse_angles(text)?;
    }
    if let Some(c) = args.slice {
        scene.view.slice = Some(c);
        scene.view.slab = None;
    }
    let scene = checked(scene)?;
    let offset = scene.view.slice.ok_or_else(|| {
        Failure::usage(
            "a mesh is of a slice: give --slice C (where the hyperplane cuts along n2, from \
             the domain's centre), or a scene with a slice",
        )
    })?;
    let formula = compile_warning(&scene, warn)?;
    let settings = MeshSettings {
        offset,
        max_level: args.max_level,
        tolerance: args.tolerance,
        caps: !args.open,
    };
    let t = std::time::Instant::now();
    let mesh = mesh_slice(&formula, &scene, &settings).map_err(|e| {
        Failure::usage(match e {
            MeshError::Level { level, lo, hi } => {
                format!("--max-level {level}: the mesh's octree takes {lo} to {hi} levels")
            }
            MeshError::Tolerance(t) => {
                format!("--tolerance {t}: a distance above 0, in the slice's units")
            }
            e => e.to_string(),
        })
    })?;
    let ms = t.elapsed().as_secs_f64() * 1e3;
    let (lo, hi) = mesh.bounds();
    let sides: [f64; 3] = std::array::from_fn(|a| hi[a] - lo[a]);
    let longest = sides.iter().cloned().fold(0.0, f64::max);
    let (scale, unit) = match mm {
        Some(size) if longest > 0.0 => (size / longest, "mm"),
        _ => (1.0, "units"),
    };
    let mut comment = describe_slice(&formula, &scene, offset);
    if unit == "mm" {
        comment.push_str(&format!(", scaled by {scale} to millimetres"));
    }
    // glTF's unit is the metre: a print's millimetres are written as such.
    let file_scale = if format == MeshFormat::Glb && unit == "mm" {
        scale / 1000.0
    } else {
        scale
    };
    let mut bytes = Vec::new();
    mesh.write(format, file_scale, &comment, &mut bytes)
        .and_then(|()| std::fs::write(&args.output, &bytes))
        .map_err(|e| Failure::runtime(format!("cannot write {}: {e}", args.output.display())))?;
    let s = &mesh.stats;
    let mut out = format!(
        "wrote {}: {} triangles, {} vertices, {}\nsize {:.4} × {:.4} × {:.4} {unit}, volume {:.6} {unit}³\n\
         octree: level {}, cells of side {:.4e}, {} of {} cells kept, built in {ms:.0} ms\n\
         largest vertex distance |F|/|∇F| {:.3e} (tolerance {:.3e})",
        args.output.display(),
        mesh.triangles.len(),
        mesh.vertices.len(),
        if args.open {
            "open where M leaves the domain"
        } else {
            "closed (capped by the domain's faces where M leaves it)"
        },
        sides[0] * scale,
        sides[1] * scale,
        sides[2] * scale,
        mesh.volume() * scale.powi(3),
        args.max_level,
        mesh.grid.side,
        s.leaves,
        s.visited,
        s.max_residual,
        s.tolerance,
    );
    if s.over_tolerance > 0 {
        out.push_str(&format!(
            "\n{} vertices stay farther than the tolerance from M (where it bends, meets a cap \
             or stops being defined within their cell): a higher --max-level brings them closer",
            s.over_tolerance
        ));
    }
    Ok(out)
}

/// The print's longest side in millimetres with `--units mm` (100 unless `--size` says),
/// None in the model's units.
fn print_size(args: &MeshArgs) -> Result<Option<f64>, Failure> {
    Ok(match (args.units.as_str(), args.size) {
        ("model", None) => None,
        ("model", Some(_)) => {
            return Err(Failure::usage(
                "--size is the print's size in millimetres: give it with --units mm",
            ));
        }
        ("mm", size) => {
            let size = size.unwrap_or(100.0);
            if !(size > 0.0 && size <= MAX_PRINT_MM) {
                return Err(Failure::usage(format!(
                    "--size {size}: the print's longest side must be above 0 and at most \
                     {MAX_PRINT_MM} mm"
                )));
            }
            Some(size)
        }
        (other, _) => {
            return Err(Failure::usage(format!(
                "--units {other}: expected model or mm"
            )));
        }
    })
}
