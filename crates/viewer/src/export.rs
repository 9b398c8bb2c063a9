//! What both platforms export the same way (the desktop writes a file, the page downloads
//! one): what a PNG export says when it is done, and the slice's mesh.

use std::sync::Arc;

use fourfold::CompiledFormula;
use fourfold::mesh::{MeshFormat, MeshSettings, mesh_slice};
use fourfold::render::Picture;
use fourfold::render::verdict::VerdictCounts;
use fourfold::scene::Scene;

use crate::notice::Notice;
use crate::session::Session;

/// The notice for `picture`, exported as `what` ("saved fourfold.png"): its size and time,
/// its certified pixels' counts, and a warning where the GPU driver cut pixels short.
pub fn exported(picture: &Picture, what: &str) -> Notice {
    let (w, h) = (picture.width, picture.height);
    let cut = picture.cut_pixels.len();
    let mut made = format!(
        "{what} ({w}x{h}, frame {:.0} ms on {})",
        picture.times.frame_ms, picture.adapter
    );
    made.push_str(&certified_note(picture.verdict_counts()));
    if cut > 0 {
        Notice::error(format!(
            "{made}; the GPU cut {cut} pixels short: lower the rays or steps"
        ))
    } else {
        Notice::done(made)
    }
}

/// How an export's notice ends where its pictures were certified: the verdicts' counts
/// (summed over an animation's frames); nothing otherwise.
pub fn certified_note(counts: Option<VerdictCounts>) -> String {
    counts
        .map(|c| format!("; certified pixels: {c}"))
        .unwrap_or_default()
}

/// What "Export mesh" meshes: the session's formula and scene, when a slice is shown.
pub fn mesh_job(session: &Session) -> Result<(Arc<CompiledFormula>, Scene), String> {
    if session.scene.view.slice.is_none() {
        return Err("Export mesh writes a slice: choose \"slice\" in the view first".into());
    }
    let program = session
        .program
        .as_ref()
        .ok_or("no valid formula yet: the editor shows why")?;
    Ok((program.formula.clone(), session.scene.clone()))
}

/// The slice of `scene` as a mesh file in `format`, in the slice's own units (as
/// `fourfold mesh` writes it, `max_level` levels deep), and what it is, in words.
pub fn slice_mesh(
    formula: &CompiledFormula,
    scene: &Scene,
    max_level: u32,
    format: MeshFormat,
) -> Result<(Vec<u8>, String), String> {
    let offset = scene.view.slice.ok_or("no slice is shown")?;
    let settings = MeshSettings {
        max_level,
        ..MeshSettings::new(offset)
    };
    let mesh = mesh_slice(formula, scene, &settings).map_err(|e| e.to_string())?;
    let mut bytes = Vec::new();
    let comment = format!(
        "fourfold: the slice at {offset} along n2 of {}",
        scene.formula
    );
    mesh.write(format, 1.0, &comment, &mut bytes)
        .map_err(|e| format!("cannot write the mesh: {e}"))?;
    let said = format!(
        "the slice at {offset:.3}, {} triangles, volume {:.4} (the slice's units)",
        mesh.triangles.len(),
        mesh.volume()
    );
    Ok((bytes, said))
}
