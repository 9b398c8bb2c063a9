use clap::Parser;
use fourfold::cli::{self, Cli, Command};

fn main() {
    let cli = Cli::parse();
    let result = match &cli.command {
        Some(Command::Check(input)) => cli::check(input),
        Some(Command::Grad(input)) => cli::grad(input),
        Some(Command::Tree(args)) => cli::tree(args),
        Some(Command::Wgsl(args)) => cli::wgsl(args),
        Some(Command::Render(args)) => cli::render(args),
        Some(Command::Animate(args)) => cli::animate(args),
        Some(Command::View(args)) => cli::view(args),
        None => cli::view(&cli::ViewArgs::default()),
    };
    match result {
        Ok(text) => {
            // A reader that stops early (`fourfold wgsl scene.toml | head`) is not an error.
            use std::io::Write as _;
            let mut out = std::io::stdout().lock();
            if let Err(e) = writeln!(out, "{text}").and_then(|()| out.flush())
                && e.kind() != std::io::ErrorKind::BrokenPipe
            {
                eprintln!("could not write the output: {e}");
                std::process::exit(1);
            }
        }
        Err(failure) => {
            eprintln!("{}", failure.message);
            std::process::exit(failure.code);
        }
    }
}
