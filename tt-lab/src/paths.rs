//! Where a study comes from, resolved at run time, never at compile time: a user's path resolves against the
//! current directory; the defaults (the paper's study) against the workspace root found by
//! walking up from the current directory, then from the executable, and outside a clone (an
//! installed `ttalloc`) the paper's study compiled into the program. (`CARGO_MANIFEST_DIR`
//! is fixed at compile time and points at the wrong clone when a target directory is shared.)

use crate::error::InputError;
use std::path::{Path, PathBuf};

/// The paper's study, relative to the workspace root.
pub const PAPER_STUDY: &str = "studies/gyrowheel-2017.toml";

/// Whether `dir` is this project's workspace root: a `Cargo.toml` with a `[workspace]`
/// table and the paper's study beside it.
fn is_root(dir: &Path) -> bool {
    dir.join(PAPER_STUDY).is_file()
        && std::fs::read_to_string(dir.join("Cargo.toml")).is_ok_and(|t| t.contains("[workspace]"))
}

/// The workspace root: the first ancestor of the current directory (then of the executable)
/// that is the project's root.
///
/// # Errors
/// An [`InputError`] when neither is inside a clone of the project.
pub fn workspace_root() -> Result<PathBuf, InputError> {
    let starts = [
        std::env::current_dir().ok(),
        std::env::current_exe()
            .ok()
            .and_then(|e| e.parent().map(Path::to_path_buf)),
    ];
    for start in starts.into_iter().flatten() {
        if let Some(root) = start.ancestors().find(|d| is_root(d)) {
            return Ok(root.to_path_buf());
        }
    }
    Err(InputError::new(
        "--study",
        format!(
            "no study given and no project workspace (with {PAPER_STUDY}) found above the current directory; pass --study FILE"
        ),
    ))
}

/// The paper's study as compiled into the program: the default study of an installed
/// `ttalloc` run outside a clone of the project (the same file as [`PAPER_STUDY`]).
pub const PAPER_STUDY_TEXT: &str = include_str!("../../studies/gyrowheel-2017.toml");

/// Where the study comes from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum StudySource {
    /// A file: the user's (as given), or the paper's in the workspace root.
    File(PathBuf),
    /// No study given and no workspace around: the paper's study compiled in
    /// ([`PAPER_STUDY_TEXT`]).
    BuiltIn,
}

/// The study to read: the user's file (as given), the paper's in the workspace root found
/// from the current directory (or the executable), else the paper's compiled in.
#[must_use]
pub fn study_source(given: Option<&Path>) -> StudySource {
    match given {
        Some(p) => StudySource::File(p.to_path_buf()),
        None => workspace_root().map_or(StudySource::BuiltIn, |r| {
            StudySource::File(r.join(PAPER_STUDY))
        }),
    }
}

/// A path as a message or the terminal shows it: as given, every character of
/// [`tt_core::human::is_unsafe_char`] (a line feed too) escaped by [`tt_core::human::visible`], so that
/// a path always prints as one visible line.
#[must_use]
pub fn visible(p: &Path) -> String {
    tt_core::human::visible(&p.display().to_string()).into_owned()
}

/// `s` as one word of a POSIX shell command line, to copy and paste: as is when it holds only
/// `A-Z a-z 0-9 _ - . / : = @ % + ,`; in single quotes otherwise (`'my study;echo x.toml'`,
/// a quote as `'\''`); with a control character, in bash's `$'...'` form so that the line stays
/// one visible line (`$'a\nb'`).
#[must_use]
pub fn shell_quote(s: &str) -> String {
    let safe = |c: char| c.is_ascii_alphanumeric() || "_-./:=@%+,".contains(c);
    if !s.is_empty() && s.chars().all(safe) {
        return s.to_string();
    }
    if s.chars().any(tt_core::human::is_unsafe_char) {
        let mut out = String::from("$'");
        for c in s.chars() {
            match c {
                '\\' => out.push_str("\\\\"),
                '\'' => out.push_str("\\'"),
                c if tt_core::human::is_unsafe_char(c) => {
                    out.push_str(&format!("\\U{:08x}", u32::from(c)));
                }
                c => out.push(c),
            }
        }
        out.push('\'');
        return out;
    }
    format!("'{}'", s.replace('\'', "'\\''"))
}
