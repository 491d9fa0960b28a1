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
    #[command(after_help = prism::cli::render::EXAMPLES)]
    Render(prism::cli::render::RenderArgs),
    /// Compare two EXR images: means, MSE, relative MSE, a z-test, a difference image.
    Compare(prism::cli::compare::CompareArgs),
    /// Render at 1, 2, 4, ... samples per pixel and plot the relative MSE against a reference.
    Converge(prism::cli::converge::ConvergeArgs),
    /// Combine render states of disjoint sample ranges into one image.
    Merge(prism::cli::merge::MergeArgs),
    /// Run the benchmark suite: BVH build, memory, rays/s, samples/s and efficiency per scene.
    Bench(prism::cli::bench::BenchArgs),
    /// List the plugins scene files may use, and their parameters.
    Plugins(prism::cli::plugins::PluginsArgs),
}

fn main() {
    restore_default_sigpipe();
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(args) => prism::cli::render::run(&args),
        Command::Compare(args) => prism::cli::compare::run(&args),
        Command::Converge(args) => prism::cli::converge::run(&args),
        Command::Merge(args) => prism::cli::merge::run(&args),
        Command::Bench(args) => prism::cli::bench::run(&args),
        Command::Plugins(args) => prism::cli::plugins::run(&args),
    };
    if let Err(error) = result {
        eprintln!("error: {error}");
        std::process::exit(error.kind.exit_code());
    }
}

/// Lets a closed pipe end the program quietly, as it ends other Unix tools: Rust ignores
/// SIGPIPE, so `prism compare a.exr b.exr | head -1` would otherwise panic on its next write.
fn restore_default_sigpipe() {
    #[cfg(unix)]
    // SAFETY: called first in `main`, before any other thread exists; SIG_DFL is a valid handler.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}
