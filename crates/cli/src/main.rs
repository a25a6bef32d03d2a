//! `learn`: the command-line shell over the workspace's libraries. Each subcommand lives in its own
//! module under `commands/` and only parses arguments, calls library functions and prints.

mod commands;

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    let cli = commands::Cli::parse();
    match commands::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            // One line, no backtrace: the chain of causes joined by ": ".
            eprintln!("error: {}", format!("{error:#}").replace('\n', " "));
            ExitCode::FAILURE
        }
    }
}
