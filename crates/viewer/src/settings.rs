//! What the viewer remembers besides the scene, across restarts (eframe's storage): slider
//! ranges, auto-rotation, file paths, export sizes, the animation last asked for.

use std::collections::BTreeMap;

use eframe::egui;

use fourfold::scene::limits::PICTURE_SIDE;

/// Storage keys (eframe persistence).
pub const KEY_SCENE: &str = "fourfold.scene";
pub const KEY_UI: &str = "fourfold.ui";

/// UI settings that survive a restart besides the scene.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct UiSettings {
    /// Slider range of each parameter.
    pub ranges: BTreeMap<String, (f64, f64)>,
    pub auto_rotate: bool,
    /// Which angles auto-rotation turns.
    pub rotate_angles: [bool; 6],
    /// Radians per second.
    pub rotate_speed: f64,
    pub scene_path: String,
    pub png_path: String,
    pub mesh_path: String,
    pub wgsl_path: String,
    pub export_size: [u32; 2],
    pub animation: AnimationChoice,
    /// Show a slice beside the projection, with the slice's place marked there.
    pub side_by_side: bool,
    /// Draw a new formula's first frames with the interpreting shader while its own
    /// compiles, as set (None: the default, on a GPU's adapter only).
    pub interpret: Option<bool>,
}

impl Default for UiSettings {
    fn default() -> Self {
        Self {
            ranges: BTreeMap::new(),
            auto_rotate: false,
            rotate_angles: [false, false, true, false, false, false],
            rotate_speed: 0.3,
            scene_path: "scene.toml".into(),
            png_path: "fourfold.png".into(),
            mesh_path: "fourfold-slice.stl".into(),
            wgsl_path: "fourfold.wgsl".into(),
            export_size: [1024, 1024],
            animation: AnimationChoice::default(),
            side_by_side: true,
            interpret: None,
        }
    }
}

/// What "Export animation" makes, as the user last set it.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct AnimationChoice {
    pub path: String,
    pub motion: Motion,
    /// The plane or angle that turns (as `animate --turn` takes it), and how many turns.
    pub plane: String,
    pub turns: f64,
    /// The parameter swept, from and to.
    pub param: String,
    pub range: (f64, f64),
    /// Where the moving slice starts and ends along n2.
    pub slice_range: (f64, f64),
    pub frames: u32,
    pub fps: f64,
    pub fit: bool,
}

impl Default for AnimationChoice {
    fn default() -> Self {
        Self {
            path: "fourfold.gif".into(),
            motion: Motion::Turn,
            plane: "xw".into(),
            turns: 1.0,
            param: String::new(),
            range: (0.5, 1.5),
            slice_range: (-1.0, 1.0),
            frames: 60,
            fps: 24.0,
            fit: true,
        }
    }
}

/// What moves in an exported animation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Motion {
    /// The manifold turns in a plane.
    Turn,
    /// A parameter sweeps.
    Sweep,
    /// A slice moves along n2.
    Slice,
}

/// The planes and angles "Export animation" offers.
pub const TURN_PLANES: [&str; 12] = [
    "xy", "yz", "zw", "xz", "xw", "yw", "θ1", "θ2", "θ3", "θ4", "θ5", "θ6",
];

/// The exported picture's width and height, as two fields.
pub fn export_size_fields(ui: &mut egui::Ui, size: &mut [u32; 2]) {
    for (side, suffix) in size.iter_mut().zip([" w", " h"]) {
        ui.add(
            egui::DragValue::new(side)
                .range(PICTURE_SIDE)
                .suffix(suffix),
        );
    }
}
