//! The Python package's step of `cargo xtask test` (issue 37): build the wheel of `python/`
//! (maturin, release), install it in a fresh virtual environment under `target/` with the
//! pinned test requirements (`python/requirements-test.txt`), run pytest on `python/tests`
//! (which also runs the code of `docs/python.md`).
//!
//! The interpreter is `$PYTHON`, else `python3` on `PATH`; [`check`] runs before anything
//! else, so a machine without Python 3 or its `venv` module is told what to install at once
//! (not after the Rust suite). The environment is a temporary directory under `target/`
//! (removed afterwards: only what this step wrote); pip's own cache makes the second run fast.

use anyhow::{Context, Result, bail};
use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The interpreter: `$PYTHON` when set and not empty, else `python3`.
#[must_use]
pub(crate) fn interpreter() -> OsString {
    std::env::var_os("PYTHON")
        .filter(|p| !p.is_empty())
        .unwrap_or_else(|| "python3".into())
}

/// Check that the interpreter runs and has `venv` and `ensurepip` (Debian splits them into
/// `python3-venv`).
///
/// # Errors
/// What is missing and what to install.
pub(crate) fn check(python: &OsString) -> Result<()> {
    let shown = Path::new(python).display().to_string();
    let out = Command::new(python)
        .args([
            "-c",
            "import sys, venv, ensurepip; print(sys.version_info >= (3, 9))",
        ])
        .output();
    match out {
        Err(e) => bail!(
            "the Python package's tests need Python 3.9 or later: `{shown}` cannot be run ({e}); install python3 and python3-venv (Debian: apt-get install -y python3 python3-venv), or set PYTHON to an interpreter"
        ),
        Ok(o) if !o.status.success() => bail!(
            "the Python package's tests need Python's venv and ensurepip modules, which `{shown}` lacks ({}); install python3-venv (Debian: apt-get install -y python3-venv), or set PYTHON to an interpreter that has them",
            String::from_utf8_lossy(&o.stderr).trim()
        ),
        Ok(o) if String::from_utf8_lossy(&o.stdout).trim() != "True" => bail!(
            "the Python package's tests need Python 3.9 or later; `{shown}` is older: set PYTHON to a newer interpreter"
        ),
        Ok(_) => Ok(()),
    }
}

/// The commands of the step, in order, with `venv` the fresh environment and `wheels` the
/// (empty) directory the wheel is built into; the wheel's own installation follows the build.
#[must_use]
pub(crate) fn commands(root: &Path, python: &OsString, venv: &Path) -> Vec<Vec<OsString>> {
    let bin = venv.join("bin");
    let py: OsString = bin.join("python").into();
    let os = |s: &str| OsString::from(s);
    vec![
        vec![python.clone(), os("-m"), os("venv"), venv.into()],
        vec![
            py.clone(),
            os("-m"),
            os("pip"),
            os("install"),
            os("--quiet"),
            os("-r"),
            root.join("python/requirements-test.txt").into(),
        ],
        vec![
            bin.join("maturin").into(),
            os("build"),
            os("--release"),
            os("-m"),
            root.join("python/Cargo.toml").into(),
            os("-o"),
            venv.join("wheels").into(),
        ],
    ]
}

fn run_one(argv: &[OsString], root: &Path) -> Result<()> {
    let shown: Vec<String> = argv
        .iter()
        .map(|a| Path::new(a).display().to_string())
        .collect();
    eprintln!("cargo xtask test: {}", shown.join(" "));
    let status = Command::new(&argv[0])
        .args(&argv[1..])
        .current_dir(root)
        .status()
        .with_context(|| format!("starting {}", shown[0]))?;
    if !status.success() {
        bail!("`{}` failed ({status})", shown.join(" "));
    }
    Ok(())
}

/// The one wheel maturin wrote into `dir`.
fn the_wheel(dir: &Path) -> Result<PathBuf> {
    let wheels: Vec<PathBuf> = std::fs::read_dir(dir)
        .with_context(|| format!("reading {}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "whl"))
        .collect();
    match wheels.as_slice() {
        [one] => Ok(one.clone()),
        _ => bail!(
            "maturin wrote {} wheels into {}, expected one",
            wheels.len(),
            dir.display()
        ),
    }
}

/// Run the step: a fresh environment, the wheel built and installed, pytest.
///
/// # Errors
/// The first command that fails (named, with its status).
pub(crate) fn run(root: &Path, python: &OsString) -> Result<()> {
    let target = root.join("target");
    std::fs::create_dir_all(&target).with_context(|| format!("creating {}", target.display()))?;
    let scratch = tempfile::Builder::new()
        .prefix("python-test-")
        .tempdir_in(&target)
        .with_context(|| format!("creating a directory in {}", target.display()))?;
    let venv = scratch.path().join("venv");
    let t0 = std::time::Instant::now();
    for argv in commands(root, python, &venv) {
        run_one(&argv, root)?;
    }
    let wheel = the_wheel(&venv.join("wheels"))?;
    let py: OsString = venv.join("bin/python").into();
    run_one(
        &[
            py.clone(),
            "-m".into(),
            "pip".into(),
            "install".into(),
            "--quiet".into(),
            wheel.into(),
        ],
        root,
    )?;
    run_one(
        &[
            py,
            "-m".into(),
            "pytest".into(),
            "-q".into(),
            "-p".into(),
            "no:cacheprovider".into(),
            root.join("python/tests").into(),
        ],
        root,
    )?;
    eprintln!(
        "cargo xtask test: the Python package built, installed and tested in {:.0} s",
        t0.elapsed().as_secs_f64()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The step builds the release wheel of `python/` with maturin into the fresh environment,
    /// after installing the pinned requirements there.
    #[test]
    fn python_step_builds_the_release_wheel_in_a_fresh_environment() {
        let c = commands(
            Path::new("/r"),
            &"python3".into(),
            Path::new("/r/target/x/venv"),
        );
        let line = |i: usize| -> String {
            c[i].iter()
                .map(|a| a.to_string_lossy().into_owned())
                .collect::<Vec<_>>()
                .join(" ")
        };
        assert_eq!(line(0), "python3 -m venv /r/target/x/venv");
        assert_eq!(
            line(1),
            "/r/target/x/venv/bin/python -m pip install --quiet -r /r/python/requirements-test.txt"
        );
        assert_eq!(
            line(2),
            "/r/target/x/venv/bin/maturin build --release -m /r/python/Cargo.toml -o /r/target/x/venv/wheels"
        );
    }
}
