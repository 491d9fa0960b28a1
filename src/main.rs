//! The `prism` command line: argument parsing only; the work is done in `prism::cli`.

use clap::{Parser, Subcommand};

/// Prism: a spectral Monte Carlo path tracer for Mitsuba 3 XML scenes.
#[derive(Parser)]
#[command(name = "prism", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene to an OpenEXR image (linear) and a PNG (sRGB) beside it.
    Render(prism::cli::render::RenderArgs),
}

fn main() {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(args) => prism::cli::render::run(&args),
    };
    if let Err(error) = result {
        eprintln!("error: {error}");
        std::process::exit(error.kind.exit_code());
    }
}
