//! The desktop's file actions: scene files opened and saved at paths typed in, the shader
//! written out, a PNG drawn on a device of its own off the window's thread (from the
//! program and tree the viewer already has) and the slice's mesh made off it too, each
//! written to a path.

use super::threads;
use std::sync::Arc;
use std::sync::mpsc::{Receiver, TryRecvError, channel};

use eframe::egui;

use fourfold::mesh::MeshFormat;
use fourfold::render::{Device, FrameOptions, Painter, Program, Source};
use fourfold::scene::Scene;
use fourfold::scene::limits::DEFAULT_MESH_LEVEL;
use fourfold::tree::{Hierarchy, TreeStats};

use crate::notice::Notice;
use crate::outcome::{Outcome, Window};
use crate::session::Session;
use crate::settings::export_size_fields;

/// Open, save and export, with paths typed in; `png` and `mesh` are the exports in flight.
pub fn actions(
    png: &mut Option<Export>,
    mesh: &mut Option<Export>,
    ui: &mut egui::Ui,
    window: Window<'_>,
) -> Outcome {
    let Window {
        session, settings, ..
    } = window;
    let mut outcome = Outcome::default();
    ui.separator();
    ui.add(egui::TextEdit::singleline(&mut settings.scene_path).desired_width(140.0))
        .on_hover_text("scene file path (TOML, as for the command line)");
    if ui.button("Open").clicked() {
        let path = &settings.scene_path;
        outcome = match Scene::load(std::path::Path::new(path)) {
            Ok(scene) => Outcome {
                open: Some((scene, true)),
                ..Outcome::said(Notice::done(format!("opened {path}")))
            },
            Err(e) => Outcome::said(Notice::error(e.to_string())),
        };
    }
    if ui.button("Save").clicked() {
        let path = &settings.scene_path;
        outcome = Outcome::said(match std::fs::write(path, session.scene.to_toml()) {
            Ok(()) => Notice::done(format!("saved scene to {path}")),
            Err(e) => Notice::error(format!("cannot write {path}: {e}")),
        });
    }
    ui.separator();
    ui.add(egui::TextEdit::singleline(&mut settings.png_path).desired_width(120.0));
    export_size_fields(ui, &mut settings.export_size);
    if ui
        .add_enabled(png.is_none(), egui::Button::new("Export PNG"))
        .clicked()
    {
        let ([w, h], path) = (settings.export_size, settings.png_path.clone());
        outcome = Outcome::said(match Export::png(session, [w, h], path.clone()) {
            Ok(export) => {
                *png = Some(export);
                Notice::done(format!("rendering {w}x{h} to {path}…"))
            }
            Err(e) => Notice::error(e),
        });
    }
    ui.separator();
    ui.add(egui::TextEdit::singleline(&mut settings.mesh_path).desired_width(120.0))
        .on_hover_text("the slice's mesh file: .stl, .obj, .ply or .glb");
    let slicing = session.scene.view.slice.is_some();
    if ui
        .add_enabled(slicing && mesh.is_none(), egui::Button::new("Export mesh"))
        .on_hover_text("the slice shown, as a closed mesh in the slice's own units (as fourfold mesh writes it)")
        .on_disabled_hover_text("choose \"slice\" in the view to export its mesh")
        .clicked()
    {
        let path = settings.mesh_path.clone();
        outcome = Outcome::said(match Export::mesh(session, path.clone()) {
            Ok(export) => {
                *mesh = Some(export);
                Notice::done(format!("meshing the slice to {path}…"))
            }
            Err(e) => Notice::error(e),
        });
    }
    ui.separator();
    ui.add(egui::TextEdit::singleline(&mut settings.wgsl_path).desired_width(120.0));
    if ui.button("Export WGSL").clicked() {
        let path = &settings.wgsl_path;
        outcome = Outcome::said(match &session.program {
            Some(program) => match std::fs::write(path, &program.shader.source) {
                Ok(()) => Notice::done(format!("saved the shader to {path}")),
                Err(e) => Notice::error(format!("cannot write {path}: {e}")),
            },
            None => Notice::error("no valid shader yet"),
        });
    }
    ui.separator();
    outcome
}

/// An export running in the background: a PNG, or the slice's mesh.
pub struct Export {
    result: Receiver<Result<Notice, String>>,
}

impl Export {
    /// Runs `work` on a thread of its own; its outcome comes back through [`Self::poll`].
    fn spawn(
        work: impl FnOnce() -> Result<Notice, String> + Send + 'static,
    ) -> Result<Self, String> {
        let (tx, rx) = channel();
        threads::spawn("fourfold export", move || {
            let _ = tx.send(work());
        })
        .map_err(|e| format!("could not start the export: {e}"))?;
        Ok(Self { result: rx })
    }

    /// Draws the session's scene at `size` on a GPU device of its own, off the window's
    /// thread, and writes it to `path`.
    pub fn png(s: &Session, size: [u32; 2], path: String) -> Result<Self, String> {
        let (Some(program), Some(hierarchy), Some(stats)) = (&s.program, &s.hierarchy, &s.stats)
        else {
            return Err("no picture yet: wait for the tree to be built".into());
        };
        let job = Job {
            program: program.clone(),
            hierarchy: hierarchy.clone(),
            certifying: s.certifying.clone(),
            params: s.tree_params.clone(),
            stats: stats.clone(),
            scene: s.scene.clone(),
            size,
        };
        Self::spawn(move || job.write(&path))
    }

    /// Meshes the slice shown and writes it to `path` (STL, OBJ, PLY or GLB by its extension).
    pub fn mesh(s: &Session, path: String) -> Result<Self, String> {
        let format = MeshFormat::from_path(std::path::Path::new(&path))?;
        let (formula, scene) = crate::export::mesh_job(s)?;
        Self::spawn(move || {
            let (mesh, said) =
                crate::export::slice_mesh(&formula, &scene, DEFAULT_MESH_LEVEL, format)?;
            std::fs::write(&path, mesh).map_err(|e| format!("cannot write {path}: {e}"))?;
            Ok(Notice::done(format!("saved {path}: {said}")))
        })
    }

    /// The export's outcome once it is done.
    pub fn poll(&self) -> Option<Notice> {
        match self.result.try_recv() {
            Ok(result) => Some(result.unwrap_or_else(Notice::error)),
            Err(TryRecvError::Empty) => None,
            Err(TryRecvError::Disconnected) => {
                Some(Notice::error("the export stopped before writing its file"))
            }
        }
    }
}

/// What an export draws: the viewer's program and tree as they are, shared.
struct Job {
    program: Program,
    hierarchy: Arc<Hierarchy>,
    certifying: Option<Arc<Hierarchy>>,
    params: Vec<f64>,
    stats: TreeStats,
    scene: Scene,
    size: [u32; 2],
}

impl Job {
    /// Draws the picture and writes it to `path`; says what was written.
    fn write(&self, path: &str) -> Result<Notice, String> {
        let gpu = threads::open_gpu()?;
        let source = Source {
            formula: &self.program.formula,
            params: &self.params,
            hierarchy: &self.hierarchy,
            certifying: self.certifying.as_deref(),
            tree: &self.stats,
            build_ms: 0.0,
        };
        let mut painter = Painter::new(
            Device::Gpu(&gpu),
            &self.program.shader,
            &self.hierarchy,
            &self.scene,
        )
        .map_err(|e| e.to_string())?;
        let picture = painter
            .start(source, &self.scene, self.size, FrameOptions::default())
            .and_then(|pending| pending.wait())
            .map_err(|e| e.to_string())?;
        let png = picture.to_png()?;
        std::fs::write(path, png).map_err(|e| format!("cannot write {path}: {e}"))?;
        Ok(crate::export::exported(&picture, &format!("saved {path}")))
    }
}
