//! What every command reads first: a formula or a scene file, with parameter and domain
//! overrides, checked by the library's scene rules; and the compiled formula with its
//! warnings.

use std::path::Path;

use clap::Args;

use fourfold::formula::CompiledFormula;
use fourfold::scene::{Domain, Scene, Speaker};

use crate::failure::Failure;

/// A formula or a scene file, with parameter overrides.
#[derive(Debug, Clone, Args)]
pub struct Input {
    /// A formula such as "x^2 + y^2 + z^2 + w^2 = 1", or the path of a .toml scene file.
    #[arg(allow_hyphen_values = true)]
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
pub fn checked(scene: Scene) -> Result<Scene, Failure> {
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

/// Where a command's warnings go as they arise: the binary prints them on stderr, the fuzzer
/// reads them with the rest of what a case says.
pub type Warn<'a> = &'a mut dyn FnMut(&str);

/// Compiles the scene's formula as [`compile`] does, and warns of parameters the formula
/// uses but the scene does not set, or the reverse.
pub fn compile_warning(scene: &Scene, warn: Warn) -> Result<CompiledFormula, Failure> {
    let formula = compile(scene)?;
    let (missing, unused) = formula.param_mismatch(&scene.params);
    for name in missing {
        warn(&format!(
            "warning: parameter {name} has no value; using 1.0 (set it with --param {name}=VALUE)"
        ));
    }
    for name in unused {
        warn(&format!(
            "warning: parameter {name} is set but the formula does not use it"
        ));
    }
    Ok(formula)
}

/// Sets the tree levels and node budget given on the command line (`TreeSettings::set_levels`).
pub fn override_tree(
    scene: &mut Scene,
    max_level: Option<u32>,
    min_level: Option<u32>,
    node_budget: Option<u32>,
) {
    scene.tree.set_levels(max_level, min_level);
    if let Some(v) = node_budget {
        scene.tree.node_budget = v;
    }
}

/// Whether the folder a file named by `flag` goes in exists: said before anything is
/// computed, so that a long computation is not lost to a mistyped folder.
pub fn folder_exists(flag: &str, path: &std::path::Path) -> Result<(), Failure> {
    match path.parent() {
        Some(folder) if !folder.as_os_str().is_empty() && !folder.is_dir() => {
            Err(Failure::usage(format!(
                "{flag} {}: there is no folder {}",
                path.display(),
                folder.display()
            )))
        }
        _ => Ok(()),
    }
}
