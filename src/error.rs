//! The one library error type and its mapping to the exit codes listed in the README.
//!
//! Errors are split by who is at fault (the lyon habit): [`Error::Input`] is the user's file or
//! config, [`Error::Usage`] is the command line, [`Error::Internal`] is ours ("please file an
//! issue"). Every input error carries the file, the place in it (line or element) where known,
//! what is wrong and what to do about it, so the CLI can print one self-contained message.
//!
//! Decision: the exit-code mapping lives here as data ([`Error::exit_code`]) but only `main.rs`
//! calls `std::process::exit`; library code never exits.

use std::fmt;
use std::path::{Path, PathBuf};

/// Where in a file a problem sits.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum Location {
    /// 1-based line number of a text file.
    Line(usize),
    /// A named element, e.g. `"triangle 17"`, `"vertex 3"`, `"material 'hull'"`.
    Element(String),
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Location::Line(n) => write!(f, "line {n}"),
            Location::Element(e) => f.write_str(&cut(e, QUOTE_CHARS * 2)),
        }
    }
}

/// Everything that can go wrong in lodeval.
#[derive(Debug)]
#[non_exhaustive]
pub enum Error {
    /// A bad input file (mesh, texture, config, image): exit code 2.
    Input {
        /// The file at fault.
        path: PathBuf,
        /// Line or element, where known.
        location: Option<Location>,
        /// What is wrong, in one sentence.
        problem: String,
        /// What the user can do about it.
        fix: String,
    },
    /// A bad command line or an unsupported request: exit code 2.
    Usage(String),
    /// A regression or golden mismatch found by a gate: exit code 1.
    Regression(String),
    /// A bug or an environment failure that is not the input's fault: exit code 3.
    Internal(String),
}

/// `Result` with [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    /// An input error without a location.
    pub fn input(path: &Path, problem: impl Into<String>, fix: impl Into<String>) -> Self {
        Error::Input {
            path: path.to_path_buf(),
            location: None,
            problem: problem.into(),
            fix: fix.into(),
        }
    }

    /// An input error at a line or element.
    pub fn input_at(
        path: &Path,
        location: Location,
        problem: impl Into<String>,
        fix: impl Into<String>,
    ) -> Self {
        Error::Input {
            path: path.to_path_buf(),
            location: Some(location),
            problem: problem.into(),
            fix: fix.into(),
        }
    }

    /// The process exit code the README assigns to this error:
    /// 1 regression/mismatch, 2 bad input or usage, 3 internal error.
    pub fn exit_code(&self) -> u8 {
        match self {
            Error::Regression(_) => 1,
            Error::Input { .. } | Error::Usage(_) => 2,
            Error::Internal(_) => 3,
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Input {
                path,
                location,
                problem,
                fix,
            } => {
                write!(f, "{}", path.display())?;
                if let Some(loc) = location {
                    write!(f, ", {loc}")?;
                }
                write!(f, ": {}", one_line(problem, MESSAGE_CHARS))?;
                if !fix.is_empty() {
                    write!(f, "; {}", one_line(fix, MESSAGE_CHARS))?;
                }
                Ok(())
            }
            Error::Usage(msg) => f.write_str(&one_line(msg, MESSAGE_CHARS)),
            Error::Regression(msg) => f.write_str(msg),
            Error::Internal(msg) => write!(
                f,
                "internal error: {msg} (this is a lodeval bug; please file an issue with the input)"
            ),
        }
    }
}

impl std::error::Error for Error {}

/// The most characters of one part of a message (the problem, the fix): a message quoting an
/// input never grows with the input.
const MESSAGE_CHARS: usize = 2000;

/// The most characters of input text [`quote`] shows.
const QUOTE_CHARS: usize = 120;

/// `text` on one line (runs of white space, line breaks included, become one space), cut to
/// `max` characters with a note of how much was left out.
fn one_line(text: &str, max: usize) -> String {
    let joined: String = text.split_whitespace().collect::<Vec<_>>().join(" ");
    cut(&joined, max)
}

fn cut(text: &str, max: usize) -> String {
    match text.char_indices().nth(max) {
        None => text.to_string(),
        Some((at, _)) => format!("{}… ({} more bytes)", &text[..at], text.len() - at),
    }
}

/// Input text as a message quotes it: control characters escaped (a newline is `\n`), at most
/// a short line long. Every message that repeats what a file or a flag said goes through this.
pub fn quote(text: &str) -> String {
    let escaped: String = text
        .chars()
        .take(QUOTE_CHARS + 1)
        .flat_map(|c| {
            if c.is_control() {
                c.escape_default().collect::<Vec<_>>()
            } else {
                vec![c]
            }
        })
        .collect();
    if text.chars().nth(QUOTE_CHARS).is_some() {
        let shown: String = escaped.chars().take(QUOTE_CHARS).collect();
        format!("{shown}…")
    } else {
        escaped
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn input_message_names_file_place_problem_and_fix() {
        let e = Error::input_at(
            Path::new("a/b.obj"),
            Location::Line(7),
            "face index 9 is out of range (8 vertices)",
            "fix the face or add the missing vertex",
        );
        assert_eq!(
            e.to_string(),
            "a/b.obj, line 7: face index 9 is out of range (8 vertices); fix the face or add the missing vertex"
        );
        assert_eq!(e.exit_code(), 2);
    }

    #[test]
    fn exit_codes_follow_design() {
        assert_eq!(Error::Usage("x".into()).exit_code(), 2);
        assert_eq!(Error::Regression("x".into()).exit_code(), 1);
        assert_eq!(Error::Internal("x".into()).exit_code(), 3);
    }
}
