//! How a command fails: a bad command line, a message for stderr, or a closed pipe; and the
//! messages for files that cannot be read or written.

use std::io;

/// How a command failed.
#[derive(Debug)]
pub(crate) enum Failure {
    /// A bad command line: clap's message, with the usage line.
    Usage(String),
    /// Anything else: the complete text for stderr.
    Failed(String),
    /// Standard output was closed by the reader (`mechgen solve … | head`): stop quietly.
    BrokenPipe,
}

pub(crate) fn failed(message: impl core::fmt::Display) -> Failure {
    Failure::Failed(format!("error: {message}"))
}

pub(crate) fn write_failure(error: &io::Error, destination: &str) -> Failure {
    if error.kind() == io::ErrorKind::BrokenPipe && destination == "stdout" {
        Failure::BrokenPipe
    } else {
        failed(format_args!("cannot write to {destination}: {error}"))
    }
}

pub(crate) fn read_failure(name: &str, error: &io::Error) -> Failure {
    let hint = match error.kind() {
        io::ErrorKind::NotFound => "check the path (it is relative to the current directory)",
        io::ErrorKind::InvalidData => "the file must be UTF-8 text: re-save it as UTF-8",
        io::ErrorKind::PermissionDenied => "check the file's permissions",
        io::ErrorKind::IsADirectory => "give a .mech file, not a directory",
        _ => "give a readable .mech file",
    };
    failed(format_args!(
        "cannot read `{name}`: {error}\n  hint: {hint}"
    ))
}
