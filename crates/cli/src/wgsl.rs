//! `fourfold wgsl`: print or write the generated, validated shader.

use std::path::PathBuf;

use clap::Args;

use crate::failure::Failure;
use crate::input::{Input, compile, load_scene};

#[derive(Debug, Clone, Args)]
pub struct WgslArgs {
    #[command(flatten)]
    pub input: Input,
    /// Write to this file instead of standard output.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
}

/// `fourfold wgsl`.
pub fn wgsl(args: &WgslArgs) -> Result<String, Failure> {
    let scene = load_scene(&args.input)?;
    let formula = compile(&scene)?;
    let text =
        fourfold::render::shader::listing(&formula).map_err(|e| Failure::runtime(e.to_string()))?;
    match &args.output {
        Some(path) => {
            std::fs::write(path, &text)
                .map_err(|e| Failure::runtime(format!("cannot write {}: {e}", path.display())))?;
            Ok(format!(
                "wrote {} ({} bytes, validated by naga)",
                path.display(),
                text.len()
            ))
        }
        None => Ok(text),
    }
}
