//! What a scene holds: the formula, parameter values, the domain, the view, the tree's and
//! the renderer's settings, each with its default (serde types: the scene file's schema).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::eval::{Box4, Interval};
use crate::tree::BuildSettings;

use super::limits::DEFAULT_CERT_BUDGET;

/// A whole scene, as stored in a `.toml` file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// F(x, y, z, w), or an equation `lhs = rhs`.
    pub formula: String,
    /// One line on what the manifold is (shown by the viewer's presets).
    #[serde(default)]
    pub description: String,
    /// Parameter values by name; a parameter not listed here is 1.0.
    #[serde(default)]
    pub params: BTreeMap<String, f64>,
    #[serde(default)]
    pub domain: Domain,
    #[serde(default)]
    pub view: View,
    #[serde(default)]
    pub tree: TreeSettings,
    #[serde(default)]
    pub render: RenderSettings,
}

/// One axis of the domain: lo < hi, both finite.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "[f64; 2]", into = "[f64; 2]")]
pub struct AxisRange {
    pub lo: f64,
    pub hi: f64,
}

impl TryFrom<[f64; 2]> for AxisRange {
    type Error = String;
    fn try_from([lo, hi]: [f64; 2]) -> Result<Self, String> {
        if !lo.is_finite() || !hi.is_finite() {
            return Err(format!(
                "domain bounds must be finite numbers, got [{lo}, {hi}]"
            ));
        }
        if lo >= hi {
            return Err(format!(
                "domain bounds [{lo}, {hi}] are reversed or empty: write them as [low, high] with low < high"
            ));
        }
        Ok(Self { lo, hi })
    }
}

impl From<AxisRange> for [f64; 2] {
    fn from(r: AxisRange) -> Self {
        [r.lo, r.hi]
    }
}

impl AxisRange {
    pub fn new(lo: f64, hi: f64) -> Result<Self, String> {
        Self::try_from([lo, hi])
    }
}

/// The hyperbox H in which M is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Domain {
    pub x: AxisRange,
    pub y: AxisRange,
    pub z: AxisRange,
    pub w: AxisRange,
}

impl Default for Domain {
    fn default() -> Self {
        let r = AxisRange { lo: -2.0, hi: 2.0 };
        Self {
            x: r,
            y: r,
            z: r,
            w: r,
        }
    }
}

impl Domain {
    pub fn axes(&self) -> [AxisRange; 4] {
        [self.x, self.y, self.z, self.w]
    }

    pub fn from_axes(a: [AxisRange; 4]) -> Self {
        Self {
            x: a[0],
            y: a[1],
            z: a[2],
            w: a[3],
        }
    }

    /// Parses `x0,x1,y0,y1,z0,z1,w0,w1` (the CLI's `--domain`).
    pub fn parse_list(text: &str) -> Result<Self, String> {
        let values = text
            .split(',')
            .map(|v| {
                v.trim()
                    .parse::<f64>()
                    .map_err(|_| format!("'{}' is not a number", v.trim()))
            })
            .collect::<Result<Vec<_>, _>>()?;
        if values.len() != 8 {
            return Err(format!(
                "expected 8 numbers x0,x1,y0,y1,z0,z1,w0,w1, got {}",
                values.len()
            ));
        }
        let names = ["x", "y", "z", "w"];
        let mut axes = [AxisRange { lo: 0.0, hi: 1.0 }; 4];
        for (i, axis) in axes.iter_mut().enumerate() {
            *axis = AxisRange::new(values[2 * i], values[2 * i + 1])
                .map_err(|e| format!("axis {}: {e}", names[i]))?;
        }
        Ok(Self::from_axes(axes))
    }

    pub fn center(&self) -> [f64; 4] {
        self.axes().map(|a| 0.5 * (a.lo + a.hi))
    }

    /// The domain as the box the 16-tree refines.
    pub fn to_box(&self) -> Box4 {
        self.axes().map(|a| Interval::new(a.lo, a.hi))
    }

    /// Half the length of the main diagonal: the radius of the sphere around H.
    pub fn half_diagonal(&self) -> f64 {
        0.5 * self
            .axes()
            .iter()
            .map(|a| (a.hi - a.lo).powi(2))
            .sum::<f64>()
            .sqrt()
    }
}

/// The view: the six rotation angles (radians), a zoom factor and where the picture's centre
/// lies.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct View {
    /// θ1..θ6 of docs/method.md §4.
    pub angles: [f64; 6],
    /// 1 shows the whole domain; 2 shows half as much, twice as large.
    pub zoom: f64,
    /// The picture's centre, from the domain's centre, along v1 and v2 (world units).
    pub pan: [f64; 2],
    /// A slab [c, h]: only the part of M whose coordinate along n2, from the domain's
    /// centre, is within h of c (docs/method.md §5.8).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub slab: Option<[f64; 2]>,
    /// A slice at c: the cut of M by the hyperplane at c along n2 from the domain's centre,
    /// seen along n1 (docs/method.md §5.8).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub slice: Option<f64>,
    /// In a projection: the place along n2 whose hits are marked (where the viewer's slice
    /// beside it cuts). Not part of a scene file.
    #[serde(skip)]
    pub mark: Option<f64>,
}

impl Default for View {
    fn default() -> Self {
        Self {
            angles: [0.0; 6],
            zoom: 1.0,
            pan: [0.0; 2],
            slab: None,
            slice: None,
            mark: None,
        }
    }
}

/// The 16-tree's criteria.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TreeSettings {
    pub max_level: u32,
    pub min_level: u32,
    /// At most this many nodes are kept; refinement stops level by level past it.
    pub node_budget: u32,
}

impl TreeSettings {
    /// Sets the levels a user gave (either or both). A lower max level alone takes the min
    /// level down with it, so that `max_level = 3` works on a scene whose min level is 4.
    pub fn set_levels(&mut self, max_level: Option<u32>, min_level: Option<u32>) {
        if let Some(v) = max_level {
            self.max_level = v;
            if min_level.is_none() {
                self.min_level = self.min_level.min(v);
            }
        }
        if let Some(v) = min_level {
            self.min_level = v;
        }
    }
}

impl From<TreeSettings> for BuildSettings {
    fn from(t: TreeSettings) -> Self {
        Self {
            max_level: t.max_level,
            min_level: t.min_level,
            node_budget: t.node_budget,
        }
    }
}

impl Default for TreeSettings {
    fn default() -> Self {
        Self {
            max_level: 6,
            min_level: 4,
            node_budget: 2_000_000,
        }
    }
}

/// How rays are spread in the observer plane (docs/method.md §5.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Sampling {
    /// The chapter's: directions from two uniform random numbers.
    Random,
    /// Evenly spread angles with a per-pixel offset (default).
    #[default]
    Stratified,
}

/// An sRGB colour, written `"#rrggbb"` in scene files.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub struct Color(pub [u8; 3]);

impl TryFrom<String> for Color {
    type Error = String;
    fn try_from(text: String) -> Result<Self, String> {
        Color::parse(&text)
    }
}

impl From<Color> for String {
    fn from(c: Color) -> Self {
        c.to_hex()
    }
}

impl Color {
    /// Parses `#rrggbb` or `rrggbb`.
    pub fn parse(text: &str) -> Result<Self, String> {
        let hex = text.trim().trim_start_matches('#');
        if hex.len() != 6 || !hex.chars().all(|c| c.is_ascii_hexdigit()) {
            return Err(format!(
                "'{text}' is not a colour: write six hex digits, as in \"#1a2b3c\""
            ));
        }
        let byte = |i: usize| u8::from_str_radix(&hex[i..i + 2], 16).expect("checked hex");
        Ok(Self([byte(0), byte(2), byte(4)]))
    }

    pub fn to_hex(self) -> String {
        format!("#{:02x}{:02x}{:02x}", self.0[0], self.0[1], self.0[2])
    }

    /// Linear-free 0..1 components, as the shader takes them.
    pub fn to_f32(self) -> [f32; 3] {
        self.0.map(|c| f32::from(c) / 255.0)
    }
}

/// Phong lighting (docs/method.md §5.6).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Lighting {
    /// Off: flat surface colour, so the highlights can be seen alone (fig. 3.12's panels).
    pub enabled: bool,
    /// Light direction in the camera frame: coefficients of v1, v2, n1, n2.
    pub direction: [f64; 4],
    pub ambient: f64,
    pub diffuse: f64,
    pub specular: f64,
    pub shininess: f64,
    pub color: Color,
}

impl Default for Lighting {
    fn default() -> Self {
        Self {
            enabled: true,
            direction: [0.4, 0.6, -0.6, -0.35],
            ambient: 0.12,
            diffuse: 0.75,
            specular: 0.35,
            shininess: 24.0,
            color: Color([222, 178, 92]),
        }
    }
}

/// A switchable highlight with a tolerance (silhouette: ε_s; border: τ, in domain units).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Highlight {
    pub enabled: bool,
    pub tolerance: f64,
    pub color: Color,
}

/// How the ray caster runs and shades (docs/method.md §5).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RenderSettings {
    /// Rays per pixel, n.
    pub rays: u32,
    /// Hits kept per pixel, K.
    pub hits: u32,
    /// Blending weight of the nearer hit.
    pub alpha: f64,
    pub sampling: Sampling,
    /// Steps m of the composite interval method per leaf span.
    pub steps: u32,
    /// Bisection iterations per sign change.
    pub bisection_iters: u32,
    /// Bisection stops once |F| is below this.
    pub approximation: f64,
    pub background: Color,
    pub lighting: Lighting,
    pub silhouette: Highlight,
    pub border: Highlight,
    /// Seed of the random sampling (and of the stratified offsets).
    pub seed: u32,
    /// March every ray across the whole domain, with the finest leaves' step count per unit
    /// length, instead of marching the tree's boxes (the same picture, many times slower:
    /// the baseline of `cargo bench --bench frame`).
    pub brute_force: bool,
    /// What gives a hit its colour: the surface colour, or its place along the hidden n2.
    #[serde(alias = "colour_by")]
    pub color_by: ColorBy,
    /// Certify every pixel: prove it hit (F changes sign on its observer plane), empty (F
    /// has no zero there), or leave it undecided once `cert_budget` cells are spent
    /// (docs/method.md §5.9). On by default: what fourfold writes and settles on is proved;
    /// off draws the chapter's plain ray pencil.
    pub certified: bool,
    /// Certified pixels: the most cells of a pixel's observer plane F is enclosed over.
    pub cert_budget: u32,
    /// How certified pixels that stay undecided are drawn.
    pub undecided: Undecided,
}

/// How an undecided pixel (certified mode) is drawn where no ray found a hit: never as the
/// background.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Undecided {
    /// Filled with magenta (#ff00ff).
    #[default]
    Marker,
    /// Magenta diagonal stripes over the background.
    Hatch,
}

/// What gives a hit its colour before lighting.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum ColorBy {
    /// The lighting's surface colour.
    #[default]
    Surface,
    /// The hit's coordinate along n2 (from the domain's centre, over the domain's half
    /// diagonal either way), through the viridis colour map: depth in the fourth direction.
    Hidden,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            rays: 16,
            hits: 4,
            alpha: 0.7,
            sampling: Sampling::Stratified,
            steps: 8,
            bisection_iters: 24,
            approximation: 1e-6,
            background: Color([20, 22, 30]),
            lighting: Lighting::default(),
            silhouette: Highlight {
                enabled: true,
                tolerance: 0.12,
                color: Color([250, 250, 250]),
            },
            border: Highlight {
                enabled: true,
                tolerance: 0.02,
                color: Color([70, 160, 255]),
            },
            seed: 1,
            brute_force: false,
            color_by: ColorBy::Surface,
            certified: true,
            cert_budget: DEFAULT_CERT_BUDGET,
            undecided: Undecided::Marker,
        }
    }
}

impl Scene {
    /// A scene with default settings around `formula`.
    pub fn from_formula(formula: &str) -> Self {
        Self {
            formula: formula.to_string(),
            description: String::new(),
            params: BTreeMap::new(),
            domain: Domain::default(),
            view: View::default(),
            tree: TreeSettings::default(),
            render: RenderSettings::default(),
        }
    }

    /// Parameter values in the order of `names` (1.0 where the scene has none).
    pub fn param_values(&self, names: &[&str]) -> Vec<f64> {
        names
            .iter()
            .map(|n| self.params.get(*n).copied().unwrap_or(1.0))
            .collect()
    }
}
