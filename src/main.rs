//! `gi-studio` with no arguments opens the studio; subcommands run headless.

use clap::Parser;
use gi_studio::cli::{Cli, Command};

fn main() -> anyhow::Result<()> {
    let cli = Cli::parse();
    match &cli.command {
        Some(Command::Render(args)) => gi_studio::cli::render::run(args),
        None => {
            println!("The studio window arrives with issue #4; until then use `gi-studio render --help`.");
            Ok(())
        }
    }
}
