//! `photonmap`: renders the built-in TNCG15 room, or a scene file, with
//! photon mapping; `photonmap compare` scores an image against a reference.
//! A thin layer over the library: each command parses and checks its
//! options, runs, and returns an exit code; errors are printed, never
//! panicked.

mod compare;
mod export;
mod render;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// Photon-mapping renderer (Jensen: caustic and global photon maps, final
/// gathering) for the TNCG15 hexagonal room with a glass sphere's caustic.
#[derive(Parser, Debug)]
#[command(
    version,
    about,
    allow_negative_numbers = true,
    args_conflicts_with_subcommands = true,
    after_help = "Examples: photonmap --photons 1e6 out.exr -o out.png\n          photonmap --scene scenes/tncg15.toml out.exr\n          photonmap compare out.exr ref.exr"
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    #[command(flatten)]
    render: render::RenderArgs,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Score an image against a reference (RMSE, relMSE, bias, windows, speckles).
    Compare(compare::Args),
    /// Write the scene for another renderer (Mitsuba 3).
    Export(export::Args),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Some(Command::Compare(args)) => compare::run(args),
        Some(Command::Export(args)) => export::run(args),
        None => render::run(cli.render),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("photonmap: error: {e}");
            ExitCode::FAILURE
        }
    }
}
