//! Scenes the certified search was not tuned for (tests/data/unseen: a thin shell, a
//! tube around a helix, sqrt and ln of arguments that turn negative inside the domain,
//! kinks of abs and max, saddles, trigonometric lattices, parameters), for the certified
//! tests, the tree's and the certified bench (each includes this file with `#[path]`).

use fourfold::scene::Scene;

/// The scenes by name, in name order.
pub fn unseen_scenes() -> Vec<(String, Scene)> {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/unseen");
    let mut paths: Vec<_> = std::fs::read_dir(dir)
        .expect("tests/data/unseen")
        .map(|e| e.expect("a file").path())
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
            (name, Scene::load(p).expect("the unseen scenes parse"))
        })
        .collect()
}
