//! `photonmap`: renders the built-in TNCG15 room, or a scene file, with
//! photon mapping; `photonmap compare` scores an image against a reference.
//! A thin layer over the library: each command parses and checks its
//! options, runs, and returns an exit code; errors are printed, never
//! panicked.

mod args;
mod compare;
mod count;
mod export;
mod merge;
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
    /// Add partial renders (--partial) into one image.
    Merge(merge::Args),
    /// Print how an EXR was made (its header) and a partial's parts.
    Info {
        #[arg(required = true, value_name = "FILE.exr")]
        files: Vec<std::path::PathBuf>,
    },
}

/// Ctrl-C (SIGINT), SIGTERM or SIGHUP (the ctrlc crate's `termination`
/// feature): `photonmap::interrupt::on_signal` decides.
fn handle_signals() {
    let _ = ctrlc::set_handler(photonmap::interrupt::on_signal);
}

/// The command line, negative numbers taken as values in every subcommand
/// as in rendering (`export --scale -1` is then refused for its value, not
/// taken for a flag): clap's setting is per command.
fn parse_cli() -> Cli {
    use clap::{CommandFactory, FromArgMatches};
    let mut command = Cli::command();
    let names: Vec<String> = command.get_subcommands().map(|c| c.get_name().to_string()).collect();
    for name in names {
        command = command.mut_subcommand(name, |c| c.allow_negative_numbers(true));
    }
    Cli::from_arg_matches(&command.get_matches()).unwrap_or_else(|e| e.exit())
}

fn main() -> ExitCode {
    let cli = parse_cli();
    handle_signals();
    let result = match cli.command {
        Some(Command::Compare(args)) => compare::run(args),
        Some(Command::Export(args)) => export::run(args),
        Some(Command::Merge(args)) => merge::run(args),
        Some(Command::Info { files }) => photonmap::command::info::run(&files),
        None => render::run(cli.render).map(|outcome| {
            if outcome == photonmap::command::render::Outcome::Interrupted {
                std::process::exit(130)
            }
        }),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("photonmap: error: {e}");
            ExitCode::FAILURE
        }
    }
}
