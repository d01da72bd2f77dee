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
        /// The EXR files to describe.
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

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    /// Options with nothing to default to (an input, an extra output, a
    /// mode that is off unless given): a new option either says its
    /// default in its help or is named here.
    const NO_DEFAULT: &[&str] = &[
        "output",
        "passes",
        "time",
        "target-error",
        "window",
        "pass-range",
        "partial",
        "resume",
        "error-map",
        "fail-map",
        "diff",
    ];

    /// Every argument of the command and of each subcommand, read from
    /// their declarations (not a list kept by hand): its flag is in the
    /// help, it has a help text, and an option that takes a value says its
    /// default, whether clap prints it or the text does.
    #[test]
    fn help_documents_every_option_with_its_default() {
        let mut root = Cli::command();
        let mut commands = vec![root.clone()];
        commands.extend(root.get_subcommands_mut().map(|c| c.clone()));
        let mut checked = 0;
        let mut wrong = Vec::new();
        for mut command in commands {
            let name = command.get_name().to_string();
            let help = command.render_long_help().to_string();
            for arg in command.get_arguments() {
                let id = arg.get_id().as_str();
                if matches!(id, "help" | "version") {
                    continue;
                }
                checked += 1;
                let text = arg.get_long_help().or(arg.get_help()).map(|h| h.to_string()).unwrap_or_default();
                let shown = match arg.get_long() {
                    Some(long) => help.contains(&format!("--{long}")),
                    None => arg.get_value_names().into_iter().flatten().all(|v| help.contains(v.as_str())),
                };
                if !shown {
                    wrong.push(format!("{name}: {id} is not in the help"));
                }
                if text.trim().is_empty() {
                    wrong.push(format!("{name}: {id} has no help text"));
                }
                let takes_value = arg.get_action().takes_values() && arg.get_long().is_some();
                let says_default =
                    !arg.get_default_values().is_empty() || text.contains("default") || text.contains("Default");
                if takes_value && !says_default && !NO_DEFAULT.contains(&arg.get_long().unwrap_or("")) {
                    wrong.push(format!("{name}: --{} does not say its default", arg.get_long().unwrap_or(id)));
                }
            }
        }
        assert!(wrong.is_empty(), "{}", wrong.join("\n"));
        // The render flags, the four subcommands' and more: not a short list.
        assert!(checked > 50, "{checked} arguments");
        let help = root.render_long_help().to_string();
        assert!(help.contains("[default: 1e6; 2.5e5 for progressive renders]"));
    }
}
