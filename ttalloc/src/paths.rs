//! Paths as the command line shows them, and (re-exported from [`tt_lab::paths`]) where the
//! study comes from: a user's path resolves against the current directory; the defaults (the
//! paper's study) against the workspace root, and outside a clone the copy compiled in.

use std::path::Path;
pub use tt_lab::paths::{
    PAPER_STUDY, PAPER_STUDY_TEXT, StudySource, shell_quote, study_source, visible, workspace_root,
};

/// How to show a path in reports: as the user gave it; the default study as its workspace
/// path (never an absolute path of the machine).
#[must_use]
pub(crate) fn shown(given: Option<&Path>) -> String {
    given.map_or_else(|| PAPER_STUDY.to_string(), |p| p.display().to_string())
}

#[cfg(test)]
mod tests {
    use super::shell_quote;

    #[test]
    fn shell_quote_keeps_one_word_and_shows_no_raw_control_character() {
        assert_eq!(
            shell_quote("studies/gyrowheel-2017.toml"),
            "studies/gyrowheel-2017.toml"
        );
        assert_eq!(
            shell_quote("my study;echo PWNED;.toml"),
            "'my study;echo PWNED;.toml'"
        );
        assert_eq!(shell_quote("it's"), "'it'\\''s'");
        assert_eq!(shell_quote(""), "''");
        assert_eq!(shell_quote("a\nb\u{1b}'"), "$'a\\U0000000ab\\U0000001b\\''");
        assert_eq!(shell_quote("$(rm -rf ~)`x`"), "'$(rm -rf ~)`x`'");
    }
}
