//! Where the browser and the fonts of the checks come from: finding Chromium (`$CHROMIUM`, the
//! usual Debian paths, `PATH`) and the Debian packages the set-up installs (Chromium, its
//! driver, and the two font families every report and fixture names first).
//!
//! Public for `cargo xtask test`, which does this set-up before the tests (xtask depends on
//! this crate for it).

use std::fs;
use std::path::{Path, PathBuf};

use anyhow::{Result, bail};

/// The Debian packages of the browser: Chromium and its driver (for WebDriver tools).
pub const BROWSER_PACKAGES: &[&str] = &["chromium", "chromium-driver"];

/// The Debian packages of the fonts the reports and fixtures name first (`DejaVu Sans`,
/// `Liberation Sans`, their monospace faces), each with a file it installs (present =
/// installed).
pub const FONT_FILES: &[(&str, &str)] = &[
    (
        "fonts-dejavu-core",
        "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    ),
    (
        "fonts-liberation",
        "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
    ),
];

/// The command that installs `packages` (as root).
#[must_use]
pub fn install_command(packages: &[&str]) -> String {
    format!(
        "apt-get update && apt-get install -y --no-install-recommends {}",
        packages.join(" ")
    )
}

/// Advice printed whenever the browser cannot be found or started.
pub const INSTALL_HINT: &str = "install chromium and chromium-driver with apt-get: run \
     `cargo xtask test` as root (it installs them and the fonts, then runs the tests), or \
     `sudo apt-get update && sudo apt-get install -y --no-install-recommends chromium \
     chromium-driver fonts-dejavu-core fonts-liberation`; or point the CHROMIUM environment \
     variable at a Chromium or Chrome binary";

/// Where Chromium is looked for when neither the caller nor `CHROMIUM` names it.
/// Debian's `/usr/bin/chromium` is a shell wrapper that `exec`s
/// `/usr/lib/chromium/chromium`; the real binary is preferred because the
/// wrapper adds flags from /etc/chromium.d and prints shell noise.
const CANDIDATES: &[&str] = &[
    "/usr/lib/chromium/chromium",
    "/usr/bin/chromium",
    "/usr/bin/chromium-browser",
    "/usr/bin/google-chrome",
    "/usr/bin/google-chrome-stable",
];

/// Finds the Chromium binary: `explicit`, else `$CHROMIUM`, else the usual
/// Debian paths, else `chromium`/`chromium-browser`/`google-chrome` on `PATH`.
///
/// # Errors
/// When none is executable, with [`INSTALL_HINT`].
pub fn find_chromium(explicit: Option<&Path>) -> Result<PathBuf> {
    if let Some(p) = explicit {
        return check_executable(p, "the path given by the caller");
    }
    if let Some(p) = std::env::var_os("CHROMIUM").filter(|v| !v.is_empty()) {
        return check_executable(Path::new(&p), "the CHROMIUM environment variable");
    }
    for c in CANDIDATES {
        if is_executable(Path::new(c)) {
            return Ok(PathBuf::from(c));
        }
    }
    if let Some(path) = std::env::var_os("PATH") {
        for dir in std::env::split_paths(&path) {
            for name in ["chromium", "chromium-browser", "google-chrome"] {
                let p = dir.join(name);
                if is_executable(&p) {
                    return Ok(p);
                }
            }
        }
    }
    bail!(
        "Chromium is not installed (looked at $CHROMIUM, {} and on PATH): {INSTALL_HINT}",
        CANDIDATES.join(", ")
    )
}

fn check_executable(p: &Path, origin: &str) -> Result<PathBuf> {
    if is_executable(p) {
        Ok(p.to_path_buf())
    } else {
        bail!(
            "no executable Chromium at {} (from {origin}): {INSTALL_HINT}",
            p.display()
        )
    }
}

fn is_executable(p: &Path) -> bool {
    use std::os::unix::fs::PermissionsExt;
    fs::metadata(p).is_ok_and(|m| m.is_file() && m.permissions().mode() & 0o111 != 0)
}
