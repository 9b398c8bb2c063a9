//! Scenes the certified search was not tuned for (tests/data/unseen: a thin shell, a
//! tube around a helix, sqrt and ln of arguments that turn negative inside the domain,
//! kinks of abs and max, saddles, trigonometric lattices, parameters), for the certified
//! tests, the tree's and the certified bench (each includes this file with `#[path]`).
//! FOURFOLD_UNSEEN_DIR names another folder of scene files to take instead: scenes of your
//! own, to check the certified pixels' soundness and decisiveness on. The hard ones
//! (tests/data/unseen-hard) are those on which a bound of issue 34 is not met
//! (docs/benchmarks.md, "Twelve more unseen scenes"): a jump, cusps, a very thin tube.

use fourfold::scene::Scene;

/// The unseen scenes by name, in name order.
pub fn unseen_scenes() -> Vec<(String, Scene)> {
    let dir = std::env::var("FOURFOLD_UNSEEN_DIR")
        .unwrap_or_else(|_| concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/unseen").into());
    scenes_in(&dir)
}

/// The hard unseen scenes by name, in name order.
pub fn hard_scenes() -> Vec<(String, Scene)> {
    scenes_in(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/unseen-hard"
    ))
}

fn scenes_in(dir: &str) -> Vec<(String, Scene)> {
    let mut paths: Vec<_> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("the scenes' folder {dir}: {e}"))
        .map(|e| e.expect("a file").path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    paths.sort();
    paths
        .iter()
        .map(|p| {
            let name = p
                .file_stem()
                .expect("a name")
                .to_string_lossy()
                .into_owned();
            let scene = Scene::load(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            (name, scene)
        })
        .collect()
}
