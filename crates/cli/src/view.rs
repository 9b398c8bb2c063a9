//! `fourfold` and `fourfold view`: the viewer window, on a formula, a scene file or a share
//! link.

use std::path::Path;

use clap::Args;

use fourfold::scene::Scene;

use crate::failure::Failure;
use crate::input::Warn;

#[derive(Debug, Clone, Args, Default)]
pub struct ViewArgs {
    /// A formula, a scene file, or a share link of the web page (`…/index.html#formula=…`).
    pub formula_or_scene: Option<String>,
}

/// `fourfold` / `fourfold view [FORMULA_OR_SCENE]`: opens the viewer window.
pub fn view(args: &ViewArgs, warn: Warn) -> Result<String, Failure> {
    let linked = args
        .formula_or_scene
        .as_deref()
        .is_some_and(fourfold::scene::link::is_link);
    let scene = match &args.formula_or_scene {
        None => None,
        Some(text) if text.ends_with(".toml") || Path::new(text).is_file() => {
            Some(Scene::load(Path::new(text)).map_err(|e| Failure::usage(e.to_string()))?)
        }
        Some(text) if fourfold::scene::link::is_link(text) => {
            let (scene, problems) = Scene::from_link(text, &fourfold_viewer::app::default_scene());
            // As the web page does: open what the link says, and tell what it left out.
            for problem in problems {
                warn(&format!("{problem} (left at its default)"));
            }
            Some(scene)
        }
        Some(text) => Some(Scene::from_formula(text)),
    };
    fourfold_viewer::platform::run(scene, !linked).map_err(Failure::runtime)?;
    Ok(String::new())
}
