//! `learn`: the command-line shell over the workspace's libraries. Each subcommand lives in its own
//! module under `commands/` and only parses arguments, calls library functions and prints.

/// Prints a line to standard output. A failed write (a closed or full output) is ignored: what
/// is printed never changes the exit code nor stops a file from being written.
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($arg)*);
    }};
}

/// As [`say!`], without the line end.
macro_rules! say_part {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = write!(std::io::stdout(), $($arg)*);
    }};
}

/// Prints a line to standard error (progress, notes), ignoring a failed write as [`say!`] does.
macro_rules! note {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}

mod commands;
#[cfg(test)]
mod help_agreement;

use std::process::ExitCode;

use clap::Parser;
use clap::error::ErrorKind;

fn main() -> ExitCode {
    restore_default_sigpipe();
    report_output_failures();
    let cli = commands::Cli::try_parse()
        .and_then(commands::Cli::validated)
        .unwrap_or_else(|error| exit_on_usage_error(error));
    match commands::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            // An error caused by an interrupt's removal of the staging is not reported: the
            // interrupt ends the process once the staging is gone.
            output_set::wait_if_interrupted();
            // Writers are given staging paths: every error names the final paths instead.
            note!("error: {}", output_set::in_final_terms(&one_line(&error)));
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
        if message.starts_with("failed printing to std") {
            note!("error: {message}");
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
    note!("{}", one_line_usage(&error.render().to_string()));
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
    short_numbers(&message.replace("\r\n", " ").replace(['\n', '\r'], " "))
}

/// `message` with every decimal number longer than [`LONG_NUMBER`] characters (an `f64` printed
/// in full: `1e-300` as 300 digits) written in short scientific notation.
fn short_numbers(message: &str) -> String {
    let mut out = String::with_capacity(message.len());
    let mut rest = message;
    while let Some(start) = rest.find(|c: char| c.is_ascii_digit()) {
        out.push_str(&rest[..start]);
        let after = &rest[start..];
        let end = after
            .find(|c: char| !(c.is_ascii_digit() || c == '.'))
            .unwrap_or(after.len());
        let number = &after[..end];
        match number.parse::<f64>() {
            Ok(value) if number.len() > LONG_NUMBER => out.push_str(&format!("{value:e}")),
            _ => out.push_str(number),
        }
        rest = &after[end..];
    }
    out.push_str(rest);
    out
}

/// Numbers in messages longer than this are shortened (an `f64` has 17 significant digits).
const LONG_NUMBER: usize = 24;

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
            let error = commands::Cli::try_parse_from(args)
                .and_then(commands::Cli::validated)
                .unwrap_err();
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
    fn long_numbers_are_printed_short() {
        let tiny = format!("{}", -1e-300);
        assert!(tiny.len() > 300);
        let error = anyhow::anyhow!("threshold {tiny} must be ≥ 0; cell {} at 1.5", 1e308);
        assert_eq!(
            one_line(&error),
            "threshold -1e-300 must be ≥ 0; cell 1e308 at 1.5"
        );
        let error = anyhow::anyhow!("x.csv:12:v: 0.1 then 0.25, version 1.2.3");
        assert_eq!(one_line(&error), "x.csv:12:v: 0.1 then 0.25, version 1.2.3");
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
