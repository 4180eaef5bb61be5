//! `gi-studio` with no arguments opens the studio; subcommands run headless.

use std::process::ExitCode;

use clap::Parser;
use gi_studio::app::StudioArgs;
use gi_studio::cli::Command;

#[derive(Debug, Parser)]
#[command(
    name = "gi-studio",
    version,
    about = "A studio for global illumination: Whitted ray tracing, path tracing, photon mapping, progressive photon mapping, light tracing, bidirectional path tracing, bidirectional photon mapping and vertex connection and merging, side by side."
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    #[command(flatten)]
    studio: StudioArgs,
}

fn main() -> ExitCode {
    gi_studio::render::engine::keep_freed_memory();
    let cli = Cli::parse();
    let result = match &cli.command {
        Some(Command::Render(args)) => gi_studio::cli::render::run(args),
        Some(Command::Photons(args)) => gi_studio::cli::photons::run(args),
        Some(Command::Reference(args)) => gi_studio::cli::reference::run(args),
        Some(Command::Bench(args)) => gi_studio::cli::bench::run(args),
        Some(Command::Merge(args)) => gi_studio::cli::merge::run(args),
        Some(Command::Compare(args)) => gi_studio::cli::merge::compare(args),
        Some(Command::Farm(args)) => gi_studio::cli::farm::run(args),
        None => gi_studio::app::run(cli.studio),
    };
    // Errors are reported once, here, as a user reads them (no backtrace)
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("error: {error:#}");
            ExitCode::FAILURE
        }
    }
}
