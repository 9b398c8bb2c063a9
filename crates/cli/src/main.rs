use clap::Parser;
use fourfold_cli::Cli;

fn main() {
    let cli = Cli::parse();
    match fourfold_cli::run(&cli, &mut |warning| eprintln!("{warning}")) {
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
