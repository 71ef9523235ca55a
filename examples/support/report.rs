//! How every example ends: `fn main() -> ExitCode { report(run()) }`. Returning a `Result`
//! from `main` would print the error's `Debug` dump (`GridDoesNotDivide { axis: "x", .. }`,
//! `Os { code: 2, .. }` without the file); this prints its message and its causes and
//! exits with status 1.
#![allow(dead_code)] // each example uses its own part

use std::error::Error;
use std::fmt;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// What an example's `run` returns.
pub type Outcome = Result<(), Box<dyn Error>>;

/// Prints `error: <message>` and one `caused by: <message>` per source to stderr and
/// fails; succeeds quietly on `Ok`. The crate's errors leave their cause out of their
/// message (`Error::Io` says "reading scene file <path>", its source the system's
/// message); a cause whose message already ends the one before it (another library's
/// error that repeats its own) is not printed twice.
pub fn report(outcome: Outcome) -> ExitCode {
    match outcome {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            let mut previous = e.to_string();
            let mut source = e.source();
            while let Some(cause) = source {
                let text = cause.to_string();
                if !previous.ends_with(&text) {
                    eprintln!("  caused by: {text}");
                }
                previous = text;
                source = cause.source();
            }
            ExitCode::FAILURE
        }
    }
}

/// A failure on a file, with the file's path: `std::io::Error` does not carry it.
#[derive(Debug)]
pub struct FileError {
    action: &'static str,
    path: PathBuf,
    source: Box<dyn Error + Send + Sync>,
}

impl fmt::Display for FileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "could not {} {}", self.action, self.path.display())
    }
}

impl Error for FileError {
    fn source(&self) -> Option<&(dyn Error + 'static)> {
        Some(&*self.source)
    }
}

/// `.at("create", &path)?` on the result of a file operation names the file in the error.
pub trait AtPath<T> {
    /// Wraps the error with `action` ("create", "read", ...) and `path`.
    fn at(self, action: &'static str, path: impl AsRef<Path>) -> Result<T, FileError>;
}

impl<T, E: Into<Box<dyn Error + Send + Sync>>> AtPath<T> for Result<T, E> {
    fn at(self, action: &'static str, path: impl AsRef<Path>) -> Result<T, FileError> {
        self.map_err(|e| FileError {
            action,
            path: path.as_ref().to_path_buf(),
            source: e.into(),
        })
    }
}

/// Creates the output directory `dir` (and its parents) if needed and checks that a file
/// can be written there, so a run fails before computing rather than after.
pub fn writable_dir(dir: impl AsRef<Path>) -> Result<(), FileError> {
    let dir = dir.as_ref();
    std::fs::create_dir_all(dir).at("create the output directory", dir)?;
    let probe = dir.join(".precursors-write-check");
    std::fs::write(&probe, b"").at("write in the output directory", dir)?;
    std::fs::remove_file(&probe).at("remove", &probe)
}
