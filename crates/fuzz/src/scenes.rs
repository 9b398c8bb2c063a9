//! Random scene files and share links: a real scene (a random formula, random settings)
//! written out, then broken a few ways at once — real keys given values of the wrong type or
//! out of range, keys duplicated, unknown keys and tables, broken escapes, lines dropped,
//! text cut short. A scene file must be read or refused with a line and a caret (exit 2);
//! a link must open, each bad key left out with a reason, as a scene the rules accept.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;

use fastrand::Rng;
use fourfold::CompiledFormula;
use fourfold::scene::Scene;

use crate::check::cli;
use crate::formulas::FormulaMaker;

/// Values of the wrong type or out of range, for any key.
const BAD_VALUES: &[&str] = &[
    "\"text\"",
    "true",
    "[1, 2]",
    "1e999",
    "-1",
    "0",
    "nan",
    "inf",
    "-inf",
    "1e30",
    "4294967296",
    "{ a = 1 }",
    "\"\"",
    "\"\\q\"",
    "\"\\u12\"",
    "'''multi'''",
    "2026-11-25",
    "0.5",
    "-0.0",
    "1000000",
    "[]",
    "\"ff00zz\"",
    "[0, 0, 0, 0, 0, 0]",
];

/// Values for a link's keys: wrong types, edges, broken escapes, resource hogs.
const BAD_LINK_VALUES: &[&str] = &[
    "abc",
    "",
    "nan",
    "inf",
    "1e999",
    "-1",
    "0",
    "1,2",
    "1,,2",
    "%zz",
    "%e2%82",
    "%",
    "true",
    "1e30",
    "4294967296",
    "0,0,0,0,0,0",
    "1,1,1,1,1,1,1",
    "%c3%28",
    "-0",
    "0.5",
    "100000000",
];

/// Keys a link spells, with and without meaning.
const LINK_KEYS: &[&str] = &[
    "formula",
    "angles",
    "zoom",
    "pan",
    "slab",
    "slice",
    "domain",
    "a",
    "R",
    "render.rays",
    "render.hits",
    "tree.max_level",
    "tree.min_level",
    "tree.node_budget",
    "render.background",
    "render.lighting.ambient",
    "render.cert_budget",
    "render.certified",
    "render.steps",
    "render.colour_by",
    "camera",
    "render.fov",
    "domain.q",
    "view.zoom",
    "params.a",
];

/// A random valid scene: a random formula and settings, as the scene file writes them.
fn random_scene(rng: &mut Rng) -> Scene {
    let formula = FormulaMaker::new(rng).formula().to_string();
    let mut scene = Scene::from_formula(&formula);
    scene.render.rays = 1 + rng.u32(..64);
    scene.tree.max_level = 3 + rng.u32(..6);
    scene.tree.min_level = rng.u32(..=scene.tree.max_level);
    scene.render.certified = rng.bool();
    scene.view.zoom = 0.1 + rng.f64() * 5.0;
    scene
}

/// A random broken scene file's text, from a valid scene's.
pub fn broken_scene_file(rng: &mut Rng) -> String {
    let mut lines: Vec<String> = random_scene(rng)
        .to_toml()
        .lines()
        .map(String::from)
        .collect();
    for _ in 0..1 + rng.usize(..3) {
        let at = rng.usize(..lines.len().max(1));
        let line = lines.get(at).cloned().unwrap_or_default();
        match rng.u32(..9) {
            0..=2 => {
                if let Some((key, _)) = line.split_once('=') {
                    let value = BAD_VALUES[rng.usize(..BAD_VALUES.len())];
                    lines[at] = format!("{}= {value}", key);
                }
            }
            3 => lines.insert(at, line),
            4 => lines.insert(at, "colour = 3".into()),
            5 => lines.insert(at, "[camera]\nfov = 1".into()),
            6 => {
                if !lines.is_empty() {
                    lines.remove(at);
                }
            }
            7 => {
                let noise = ["[", "]", "=", "\"", "'", "#", "{", "\\", "\u{0}"][rng.usize(..9)];
                let mut l = line;
                let cut = floor_char_boundary(&l, rng.usize(..=l.len()));
                l.insert_str(cut, noise);
                if at < lines.len() {
                    lines[at] = l;
                }
            }
            _ => {
                let mut text = lines.join("\n");
                text.truncate(floor_char_boundary(&text, rng.usize(..=text.len())));
                lines = text.lines().map(String::from).collect();
            }
        }
    }
    lines.join("\n")
}

/// A random broken share link's fragment, from a valid scene's.
pub fn broken_link(rng: &mut Rng) -> String {
    let link = random_scene(rng).to_link();
    let mut pairs: Vec<String> = link.split('&').map(String::from).collect();
    for _ in 0..1 + rng.usize(..4) {
        let at = rng.usize(..pairs.len().max(1));
        let key = LINK_KEYS[rng.usize(..LINK_KEYS.len())];
        let value = BAD_LINK_VALUES[rng.usize(..BAD_LINK_VALUES.len())];
        match rng.u32(..7) {
            0..=2 => pairs.push(format!("{key}={value}")),
            3 => {
                let copy = pairs[at.min(pairs.len() - 1)].clone();
                pairs.push(copy);
            }
            4 => {
                if pairs.len() > 1 {
                    pairs.remove(at);
                }
            }
            5 => pairs.push(format!("formula={}", "x%2B".repeat(rng.usize(..30_000)))),
            _ => {
                let last = pairs.len() - 1;
                let p = &mut pairs[at.min(last)];
                let cut = floor_char_boundary(p, rng.usize(..=p.len()));
                p.insert_str(cut, ["%", "%g", "&", "=", "#", "%00"][rng.usize(..6)]);
            }
        }
    }
    pairs.join("&")
}

fn floor_char_boundary(s: &str, mut i: usize) -> usize {
    while !s.is_char_boundary(i) {
        i -= 1;
    }
    i
}

/// A scene file: `fourfold check` reads it or refuses it with its place (exit 2); a scene it
/// reads, `fourfold render --cpu` draws or refuses.
pub fn check_scene_file(text: &str, dir: &Path) -> Result<(), String> {
    let path = dir.join("scene.toml");
    std::fs::write(&path, text).map_err(|e| format!("writing {}: {e}", path.display()))?;
    let file = path.display().to_string();
    let (code, said) = cli(&["check".into(), file.clone()]);
    if code == 2 {
        // The place: in the file, or in its formula (whose own line and caret are shown).
        let placed = said.contains("┌─") && said.contains('^');
        if !placed {
            return Err(format!("refused without a line and caret:\n{said}"));
        }
        return Ok(());
    }
    if code != 0 || said.contains("panicked") {
        return Err(format!("check exits {code}:\n{said}"));
    }
    let out = dir.join("scene.png").display().to_string();
    let render = [
        "render",
        &file,
        "-o",
        &out,
        "--cpu",
        "--size",
        "6x5",
        "--max-level",
        "3",
    ];
    let (code, said) = cli(&render.map(String::from));
    if code != 0 && code != 2 || said.contains("panicked") || said.contains("internal error") {
        return Err(format!(
            "render --cpu of a checked scene exits {code}:\n{said}"
        ));
    }
    Ok(())
}

/// A link: it opens as a scene the rules accept, each key left out named with a reason,
/// and its formula compiles or is refused with a place in it.
pub fn check_link(link: &str) -> Result<(), String> {
    let opened = catch_unwind(AssertUnwindSafe(|| {
        Scene::from_link(link, &Scene::from_formula("x^2 + y^2 + z^2 + w^2 = 1"))
    }));
    let (scene, problems) = opened.map_err(|_| "opening the link panicked".to_string())?;
    if let Err(invalid) = scene.check() {
        return Err(format!(
            "the link opened as a scene the rules refuse: {invalid:?}"
        ));
    }
    if let Some(p) = problems.iter().find(|p| p.message.trim().is_empty()) {
        return Err(format!("a problem without a reason: {p:?}"));
    }
    let compiled = catch_unwind(|| CompiledFormula::compile(&scene.formula).err());
    match compiled {
        Err(_) => return Err("compiling the link's formula panicked".into()),
        Ok(Some(e)) if e.span.end > scene.formula.len() => {
            return Err(format!("an error placed past the formula's end: {e:?}"));
        }
        Ok(_) => {}
    }
    let (_, again) = Scene::from_link(&scene.to_link(), &scene);
    if !again.is_empty() {
        return Err(format!(
            "the opened scene's own link has problems: {again:?}"
        ));
    }
    Ok(())
}
