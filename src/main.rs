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
        Some(Command::View(args)) => cli::view(args),
        None => cli::view(&cli::ViewArgs::default()),
    };
    match result {
        Ok(text) => println!("{text}"),
        Err(failure) => {
            eprintln!("{}", failure.message);
            std::process::exit(failure.code);
        }
    }
}
