//! The example scenes shipped with fourfold (`examples/scenes/`), embedded in the library.

use super::settings::Scene;

/// The example scenes shipped with fourfold (also embedded in the viewer).
pub const EXAMPLES: &[(&str, &str)] = &[
    (
        "glome",
        include_str!("../../../../examples/scenes/glome.toml"),
    ),
    (
        "fig-3-9-left",
        include_str!("../../../../examples/scenes/fig-3-9-left.toml"),
    ),
    (
        "fig-3-9-right",
        include_str!("../../../../examples/scenes/fig-3-9-right.toml"),
    ),
    (
        "fig-3-11",
        include_str!("../../../../examples/scenes/fig-3-11.toml"),
    ),
    (
        "fig-3-12",
        include_str!("../../../../examples/scenes/fig-3-12.toml"),
    ),
    (
        "spheritorus",
        include_str!("../../../../examples/scenes/spheritorus.toml"),
    ),
    (
        "tiger",
        include_str!("../../../../examples/scenes/tiger.toml"),
    ),
    (
        "fermat-quartic",
        include_str!("../../../../examples/scenes/fermat-quartic.toml"),
    ),
    (
        "hyperplane",
        include_str!("../../../../examples/scenes/hyperplane.toml"),
    ),
    (
        "duocylinder",
        include_str!("../../../../examples/scenes/duocylinder.toml"),
    ),
];

impl Scene {
    /// The embedded example scene called `name` (see [`EXAMPLES`]), if there is one.
    pub fn example(name: &str) -> Option<Scene> {
        EXAMPLES
            .iter()
            .find(|(n, _)| *n == name)
            .and_then(|(n, text)| Scene::parse(text, n).ok())
    }
}
