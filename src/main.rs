//! `gi-studio` with no arguments opens the studio; subcommands run headless.

use std::process::ExitCode;

use clap::Parser;
use gi_studio::cli::{Cli, Command};

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        Some(Command::Render(args)) => gi_studio::cli::render::run(args),
        Some(Command::Photons(args)) => gi_studio::cli::photons::run(args),
        Some(Command::Reference(args)) => gi_studio::cli::reference::run(args),
        Some(Command::Bench(args)) => gi_studio::cli::bench::run(args),
        None => gi_studio::app::run(cli.studio.clone()),
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
