//! The command line: argument types and the glue from them to the library, a file per
//! command (with that command's flags). No maths here: every check of a value is the
//! library's scene rules, every picture the library's picture API.

mod animate;
mod check;
mod critical;
mod failure;
mod input;
mod mesh;
mod render;
mod tree;
mod view;
mod wgsl;

use clap::{Parser, Subcommand};

pub use animate::{AnimateArgs, animate, animation_of};
pub use check::{check, grad};
pub use critical::{CriticalArgs, critical};
pub use failure::Failure;
pub use input::{Input, Warn};
pub use mesh::{MeshArgs, mesh};
pub use render::{CUT_WARNING, RenderArgs, render, render_scene_of};
pub use tree::{TreeArgs, tree};
pub use view::{ViewArgs, view};
pub use wgsl::{WgslArgs, wgsl};

#[derive(Debug, Parser)]
#[command(
    name = "fourfold",
    version,
    about = "See the 3-manifold F(x,y,z,w) = 0 in four dimensions"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Parse a formula and report problems (exit 0 if fine, 2 if not).
    Check(Input),
    /// Print F and its four partial derivatives.
    Grad(Input),
    /// Build the 16-tree and print its statistics.
    Tree(TreeArgs),
    /// Print or write the generated, validated WGSL shader.
    Wgsl(WgslArgs),
    /// Render a picture to a PNG file.
    Render(RenderArgs),
    /// Render an animation (the manifold turning, or a parameter sweeping) to a GIF, an
    /// animated PNG or a folder of PNGs.
    Animate(AnimateArgs),
    /// Write the mesh of a slice (the cut of M by the hyperplane at --slice C along n2) to
    /// an STL, OBJ, PLY or GLB file, for printing or for other programs.
    Mesh(MeshArgs),
    /// Print the proved critical values of the slice sweep: the places along n2 where the
    /// slice's topology can change, with each point's Morse index.
    Critical(CriticalArgs),
    /// Open the interactive viewer (the default with no command).
    View(ViewArgs),
}

/// Runs the command `cli` names (the viewer without one): the text to print, or the failure.
/// Warnings go to `warn` as they arise.
pub fn run(cli: &Cli, warn: Warn) -> Result<String, Failure> {
    match &cli.command {
        Some(Command::Check(input)) => check(input, warn),
        Some(Command::Grad(input)) => grad(input, warn),
        Some(Command::Tree(args)) => tree(args, warn),
        Some(Command::Wgsl(args)) => wgsl(args),
        Some(Command::Render(args)) => render(args, warn),
        Some(Command::Animate(args)) => animate(args, warn),
        Some(Command::Mesh(args)) => mesh(args, warn),
        Some(Command::Critical(args)) => critical(args, warn),
        Some(Command::View(args)) => view(args, warn),
        None => view(&ViewArgs::default(), warn),
    }
}
