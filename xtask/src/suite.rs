//! `cargo xtask test [ARGS...]`: the README's test command. It does the set-up the tests need
//! on a fresh machine, then runs `cargo test --workspace ARGS...` and exits with its status.
//!
//! Set-up: the browser tests open the reports in headless Chromium, whose layout depends on
//! the installed fonts; the reports and fixtures name `DejaVu Sans` and `Liberation Sans`
//! first. So the command
//! - finds Chromium as browser-check does (`$CHROMIUM`, `/usr/lib/chromium/chromium`,
//!   `/usr/bin/chromium`, ..., `PATH`); a `$CHROMIUM` that names no executable stops it at once;
//! - checks that both font families are installed (`fonts-dejavu-core`, `fonts-liberation`);
//! - when something is missing and it runs as root with `apt-get`, installs the missing
//!   packages (`chromium chromium-driver` for the browser, the font packages) with
//!   `apt-get install -y --no-install-recommends`; otherwise it fails at once (exit 1) with the
//!   exact command to run.
//!
//! Nothing is skipped: a browser test that cannot start its browser fails with the same
//! instruction.
//!
//! Then the Python package ([`crate::python`]): its wheel is built, installed in a fresh
//! virtual environment and tested with pytest after the Rust suite passes; a machine without
//! Python 3 and its `venv` module is told what to install before anything runs.

use anyhow::{Context, Result, bail};
use browser_check::locate;
use clap::Parser;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};

/// Arguments of `test`.
#[derive(Debug, Parser)]
pub(crate) struct Args {
    /// Arguments passed on to `cargo test --workspace` (e.g. `-p study`, a test name, the test
    /// binaries' own flags after `--`).
    #[arg(
        trailing_var_arg = true,
        allow_hyphen_values = true,
        value_name = "ARGS"
    )]
    pub cargo_args: Vec<String>,
}

/// What the set-up has to do.
#[derive(Debug, PartialEq, Eq)]
enum Plan {
    /// Everything is there.
    Ready,
    /// Install these packages (as root, with apt-get).
    Install(Vec<&'static str>),
    /// Stop and tell the user this.
    Instruct(String),
}

/// What the machine has.
#[derive(Debug)]
struct Machine {
    /// Chromium found, or why not.
    chromium: Result<PathBuf, String>,
    /// Whether `$CHROMIUM` is set (then a missing browser is the variable's fault).
    chromium_from_env: bool,
    /// The font packages whose files are missing.
    missing_fonts: Vec<&'static str>,
    /// Running as root.
    root: bool,
    /// `apt-get` on `PATH`.
    apt_get: bool,
}

fn plan(m: &Machine) -> Plan {
    let mut missing: Vec<&'static str> = Vec::new();
    if let Err(why) = &m.chromium {
        if m.chromium_from_env {
            return Plan::Instruct(format!(
                "{why}\n(unset CHROMIUM to use the system's Chromium, installed by this command when missing)"
            ));
        }
        missing.extend(locate::BROWSER_PACKAGES);
    }
    missing.extend(&m.missing_fonts);
    if missing.is_empty() {
        return Plan::Ready;
    }
    if m.root && m.apt_get {
        return Plan::Install(missing);
    }
    let what = missing.join(" ");
    let command = if m.apt_get {
        format!(
            "sudo {}",
            locate::install_command(&missing).replace("&& apt-get", "&& sudo apt-get")
        )
    } else {
        format!(
            "install the Debian packages {what} (or your system's Chromium and the DejaVu and Liberation fonts), then run `cargo xtask test` again"
        )
    };
    Plan::Instruct(format!(
        "the browser tests need {what}, which {} not installed; run:\n  {command}\n(or run `cargo xtask test` as root: it installs them)",
        if missing.len() == 1 { "is" } else { "are" }
    ))
}

fn on_path(name: &str) -> bool {
    std::env::var_os("PATH")
        .is_some_and(|p| std::env::split_paths(&p).any(|d| d.join(name).is_file()))
}

fn machine() -> Machine {
    Machine {
        chromium: locate::find_chromium(None).map_err(|e| format!("{e:#}")),
        chromium_from_env: std::env::var_os("CHROMIUM").is_some_and(|v| !v.is_empty()),
        missing_fonts: locate::FONT_FILES
            .iter()
            .filter(|(_, file)| !Path::new(file).is_file())
            .map(|(pkg, _)| *pkg)
            .collect(),
        root: rustix::process::geteuid().is_root(),
        apt_get: on_path("apt-get"),
    }
}

fn apt_get(args: &[&str]) -> Result<()> {
    eprintln!("cargo xtask test: apt-get {}", args.join(" "));
    let status = Command::new("apt-get")
        .args(args)
        .env("DEBIAN_FRONTEND", "noninteractive")
        .status()
        .context("running apt-get")?;
    if !status.success() {
        bail!("`apt-get {}` failed ({status})", args.join(" "));
    }
    Ok(())
}

/// Run the command: set up, then `cargo test --workspace ARGS...`, then the Python package's
/// tests.
///
/// # Errors
/// When the set-up cannot be done (with the command to run), or cargo cannot be started.
pub(crate) fn run(args: &Args) -> Result<ExitCode> {
    let python = crate::python::interpreter();
    crate::python::check(&python)?;
    let before = machine();
    match plan(&before) {
        Plan::Ready => {}
        Plan::Instruct(text) => bail!("{text}"),
        Plan::Install(packages) => {
            apt_get(&["update"])?;
            let mut a = vec!["install", "-y", "--no-install-recommends"];
            a.extend(&packages);
            apt_get(&a)?;
            let after = machine();
            if let Err(why) = &after.chromium {
                bail!("after installing {}: {why}", packages.join(" "));
            }
            if !after.missing_fonts.is_empty() {
                bail!(
                    "after installing {}: the fonts of {} are still missing",
                    packages.join(" "),
                    after.missing_fonts.join(" ")
                );
            }
        }
    }
    let chromium = locate::find_chromium(None)?;
    let root = ttalloc::paths::workspace_root()?;
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    eprintln!(
        "cargo xtask test: Chromium {}, fonts DejaVu and Liberation; cargo test --workspace {}",
        chromium.display(),
        args.cargo_args.join(" ")
    );
    let status = Command::new(&cargo)
        .arg("test")
        .arg("--workspace")
        .args(&args.cargo_args)
        .current_dir(&root)
        .status()
        .with_context(|| format!("starting {}", Path::new(&cargo).display()))?;
    match status.code() {
        Some(0) => {}
        Some(c) => return Ok(ExitCode::from(u8::try_from(c).unwrap_or(1))),
        None => return Ok(ExitCode::FAILURE),
    }
    crate::python::run(&root, &python)?;
    Ok(ExitCode::SUCCESS)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn m(chromium: bool, env: bool, fonts: &[&'static str], root: bool, apt: bool) -> Machine {
        Machine {
            chromium: if chromium {
                Ok("/usr/bin/chromium".into())
            } else {
                Err("Chromium is not installed".into())
            },
            chromium_from_env: env,
            missing_fonts: fonts.to_vec(),
            root,
            apt_get: apt,
        }
    }

    /// The set-up of `cargo xtask test`: nothing to do when all is there; as root with apt-get,
    /// install exactly what is missing (the browser with its driver, the font packages);
    /// otherwise the exact command to run; a `$CHROMIUM` that names nothing is never "fixed"
    /// by installing another browser.
    #[test]
    fn test_command_installs_what_is_missing_as_root_and_says_the_command_otherwise() {
        assert_eq!(plan(&m(true, false, &[], false, true)), Plan::Ready);
        assert_eq!(
            plan(&m(false, false, &["fonts-liberation"], true, true)),
            Plan::Install(vec!["chromium", "chromium-driver", "fonts-liberation"])
        );
        assert_eq!(
            plan(&m(true, false, &["fonts-dejavu-core"], true, true)),
            Plan::Install(vec!["fonts-dejavu-core"])
        );
        let Plan::Instruct(t) = plan(&m(false, false, &["fonts-dejavu-core"], false, true)) else {
            panic!("a user who is not root is told what to run");
        };
        assert!(
            t.contains("sudo apt-get update && sudo apt-get install -y --no-install-recommends chromium chromium-driver fonts-dejavu-core"),
            "{t}"
        );
        let Plan::Instruct(t) = plan(&m(false, true, &[], true, true)) else {
            panic!("a wrong $CHROMIUM is the user's to fix");
        };
        assert!(t.contains("unset CHROMIUM"), "{t}");
        let Plan::Instruct(t) = plan(&m(true, false, &["fonts-liberation"], true, false)) else {
            panic!("no apt-get: say what to install");
        };
        assert!(t.contains("fonts-liberation"), "{t}");
    }
}
