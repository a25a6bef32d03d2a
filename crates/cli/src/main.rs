//! `learn`: the command-line shell over the workspace's libraries. Each subcommand lives in its own
//! module under `commands/` and only parses arguments, calls library functions and prints.

mod commands;

use std::process::ExitCode;

use clap::Parser;
use clap::error::ErrorKind;

fn main() -> ExitCode {
    restore_default_sigpipe();
    report_output_failures();
    let cli = commands::Cli::try_parse().unwrap_or_else(|error| exit_on_usage_error(error));
    match commands::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("error: {}", one_line(&error));
            ExitCode::FAILURE
        }
    }
}

/// Lets the process end quietly when the reader of its output goes away (`learn … | head`), as
/// Unix tools do: Rust ignores SIGPIPE, so `println!` would otherwise panic on the failed write.
fn restore_default_sigpipe() {
    #[cfg(unix)]
    // SAFETY: called first thing in `main`, before any other thread exists; SIG_DFL is a valid
    // disposition for SIGPIPE.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

/// `println!` panics when standard output cannot be written (a full disk, a closed file); that is
/// reported as the one-line error every other failure gets, with the usual exit code.
fn report_output_failures() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let payload = info.payload();
        let message = payload
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| payload.downcast_ref::<&str>().copied())
            .unwrap_or("");
        if message.starts_with("failed printing to stdout") {
            eprintln!("error: {message}");
            std::process::exit(1);
        }
        default(info);
    }));
}

/// Ends the process on what clap could not parse: help and version as clap prints them, a usage
/// error (a bad value, a missing or unknown argument, arguments that cannot be combined) as one
/// line, like every other error, with clap's exit code (2).
fn exit_on_usage_error(error: clap::Error) -> ! {
    if !error.use_stderr() || error.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand {
        error.exit();
    }
    eprintln!("{}", one_line_usage(&error.render().to_string()));
    std::process::exit(error.exit_code());
}

/// A rendered clap error on one line: its message and tips, without the usage and help hint.
fn one_line_usage(rendered: &str) -> String {
    rendered
        .lines()
        .map(str::trim)
        .take_while(|line| !line.starts_with("Usage:"))
        .filter(|line| !line.is_empty() && !line.starts_with("For more information"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// The chain of causes joined by ": " on one line, without repeating a cause whose text the
/// message already shows (library errors often print their source themselves).
fn one_line(error: &anyhow::Error) -> String {
    let mut message = String::new();
    for cause in error.chain() {
        let text = cause.to_string();
        if message.contains(&text) {
            continue;
        }
        if !message.is_empty() {
            message.push_str(": ");
        }
        message.push_str(&text);
    }
    message.replace("\r\n", " ").replace(['\n', '\r'], " ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn usage_errors_are_one_line() {
        for args in [
            &["learn", "meta-train", "--seed-spread", "--out", "x.json"][..],
            &["learn", "sindy"],
            &["learn", "nope"],
        ] {
            let error = commands::Cli::try_parse_from(args).unwrap_err();
            let line = one_line_usage(&error.render().to_string());
            assert!(line.starts_with("error: "), "{args:?}: {line}");
            assert!(!line.contains('\n') && !line.contains("Usage:"), "{line}");
        }
        let error = commands::Cli::try_parse_from(["learn", "sindy"]).unwrap_err();
        let line = one_line_usage(&error.render().to_string());
        assert!(
            line.contains("--csv"),
            "the missing arguments are named: {line}"
        );
    }

    #[test]
    fn causes_are_not_repeated() {
        let io = std::io::Error::new(std::io::ErrorKind::NotFound, "No such file");
        let error = anyhow::Error::new(io).context("x.csv: No such file");
        assert_eq!(one_line(&error), "x.csv: No such file");
        let error = anyhow::anyhow!("inner\nline").context("outer");
        assert_eq!(one_line(&error), "outer: inner line");
        let error = anyhow::anyhow!("cell \"a\r\nb\" and \"c\rd\"");
        assert_eq!(one_line(&error), "cell \"a b\" and \"c d\"");
    }
}
