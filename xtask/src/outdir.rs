//! Writing a report directory safely: nothing the program did not write is ever deleted or
//! replaced, a failed run leaves nothing behind, and the directory always holds one complete
//! report.
//!
//! - `--out DIR` that does not exist, or is empty: the report is built in a temporary sibling
//!   and renamed into place at once.
//! - `DIR` holding a previous report of ours (every entry listed in its [`MANIFEST`]): it is
//!   replaced the same way, and the old report removed file by file (only files it lists).
//! - `DIR` holding anything else, or `DIR` naming a file: refused with exit code 2, nothing
//!   touched.
//! - Two runs into one `DIR` at once: the second finds the lock file `.DIR.lock` (with the
//!   first's process id) and fails with a clear message; a lock left by a run that died is
//!   recognised (its process is gone) and taken over.

use crate::InputError;
use anyhow::{Context, Result};
use std::path::{Path, PathBuf};

/// The manifest file of a report directory: a signature line, then one written file per line.
pub const MANIFEST: &str = ".report-manifest";

/// The manifest's first line.
const SIGNATURE: &str =
    "# files written by `cargo xtask` (gyrowheel turntable project); safe to replace as a whole";

/// Removes a path it created when dropped, unless disarmed.
struct Cleanup {
    path: Option<PathBuf>,
    dir: bool,
}

impl Cleanup {
    fn disarm(&mut self) {
        self.path = None;
    }
}

impl Drop for Cleanup {
    fn drop(&mut self) {
        if let Some(p) = self.path.take() {
            let _ = if self.dir {
                std::fs::remove_dir_all(&p)
            } else {
                std::fs::remove_file(&p)
            };
        }
    }
}

fn parent_and_name(out: &Path) -> Result<(PathBuf, String), InputError> {
    let parent = out
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .map_or_else(|| PathBuf::from("."), Path::to_path_buf);
    let name = out
        .file_name()
        .ok_or_else(|| InputError::new(out.display().to_string(), "--out needs a directory name"))?
        .to_string_lossy()
        .to_string();
    Ok((parent, name))
}

/// The files of a previous report in `dir`, if `dir` is one; `Ok(None)` for an empty
/// directory; an [`InputError`] naming foreign entries otherwise.
fn previous_report(dir: &Path) -> Result<Option<Vec<String>>, InputError> {
    let shown = dir.display().to_string();
    let entries: Vec<String> = std::fs::read_dir(dir)
        .map_err(|e| InputError::new(&shown, format!("cannot read the output directory: {e}")))?
        .filter_map(|e| e.ok().map(|e| e.file_name().to_string_lossy().to_string()))
        .collect();
    if entries.is_empty() {
        return Ok(None);
    }
    let listed: Option<Vec<String>> = std::fs::read_to_string(dir.join(MANIFEST))
        .ok()
        .filter(|t| t.lines().next() == Some(SIGNATURE))
        .map(|t| t.lines().skip(1).map(String::from).collect());
    let refuse = |foreign: Vec<&String>| {
        let mut some: Vec<&str> = foreign.iter().map(|s| s.as_str()).take(3).collect();
        if foreign.len() > 3 {
            some.push("...");
        }
        InputError::new(
            &shown,
            format!(
                "refusing to write a report here: the directory holds files this program did not write ({}); choose a new or empty directory with --out, or move them away yourself",
                some.join(", ")
            ),
        )
    };
    match listed {
        None => Err(refuse(entries.iter().collect())),
        Some(listed) => {
            let foreign: Vec<&String> = entries
                .iter()
                .filter(|e| *e != MANIFEST && !listed.contains(e))
                .collect();
            if foreign.is_empty() {
                Ok(Some(listed))
            } else {
                Err(refuse(foreign))
            }
        }
    }
}

/// Take the lock `.NAME.lock` in `parent` (exclusive create), taking over a stale one.
fn lock(parent: &Path, name: &str, out: &Path) -> Result<Cleanup> {
    let path = parent.join(format!(".{name}.lock"));
    for _ in 0..2 {
        match std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&path)
        {
            Ok(mut f) => {
                use std::io::Write;
                writeln!(f, "{}", std::process::id())?;
                return Ok(Cleanup {
                    path: Some(path),
                    dir: false,
                });
            }
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                let pid = std::fs::read_to_string(&path)
                    .ok()
                    .and_then(|t| t.trim().parse::<u32>().ok());
                let alive = pid.is_some_and(|p| Path::new(&format!("/proc/{p}")).exists());
                if alive || pid.is_none() {
                    return Err(InputError::new(
                        out.display().to_string(),
                        format!(
                            "another run is writing this report (lock file {}{}); wait for it to finish",
                            path.display(),
                            pid.map_or(String::new(), |p| format!(", process {p}"))
                        ),
                    )
                    .into());
                }
                // a lock of ours whose process is gone: stale
                std::fs::remove_file(&path)
                    .with_context(|| format!("removing the stale lock {}", path.display()))?;
            }
            Err(e) => {
                return Err(
                    anyhow::Error::new(e).context(format!("creating the lock {}", path.display()))
                );
            }
        }
    }
    Err(InputError::new(out.display().to_string(), "could not take the output lock").into())
}

/// Write `files` (name, bytes) as the report directory `out` (see the [module](self)).
///
/// # Errors
/// An [`InputError`] (exit code 2) when `out` is a file or holds foreign files, or another run
/// holds the lock; I/O errors otherwise. On every error nothing is left behind and nothing
/// of the user's is touched.
pub fn write_report_dir(out: &Path, files: &[(String, Vec<u8>)]) -> Result<()> {
    for (name, _) in files {
        anyhow::ensure!(
            !name.contains('/') && !name.starts_with('.') && !name.is_empty(),
            "internal: bad report file name {name}"
        );
    }
    let shown = out.display().to_string();
    let (parent, name) = parent_and_name(out)?;
    if let Ok(meta) = std::fs::symlink_metadata(out) {
        if !meta.is_dir() {
            return Err(InputError::new(
                &shown,
                "exists and is not a directory; choose another --out",
            )
            .into());
        }
        previous_report(out)?;
    }
    std::fs::create_dir_all(&parent).map_err(|e| {
        InputError::new(
            parent.display().to_string(),
            format!("cannot create the output's parent directory: {e}"),
        )
    })?;
    let _lock = lock(&parent, &name, out)?;
    // Re-check under the lock: another run may have written meanwhile.
    let previous = if out.exists() {
        previous_report(out)?
    } else {
        None
    };
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.subsec_nanos());
    let tmp = parent.join(format!(".{name}.tmp-{}-{nanos}", std::process::id()));
    std::fs::create_dir(&tmp).with_context(|| format!("creating {}", tmp.display()))?;
    let mut tmp_guard = Cleanup {
        path: Some(tmp.clone()),
        dir: true,
    };
    let mut manifest = format!("{SIGNATURE}\n");
    for (file, bytes) in files {
        std::fs::write(tmp.join(file), bytes).with_context(|| format!("writing {file}"))?;
        manifest.push_str(file);
        manifest.push('\n');
    }
    std::fs::write(tmp.join(MANIFEST), manifest)?;
    match previous {
        Some(listed) => {
            let old = parent.join(format!(".{name}.old-{}-{nanos}", std::process::id()));
            std::fs::rename(out, &old)
                .with_context(|| format!("moving the previous report {shown} aside"))?;
            if let Err(e) = std::fs::rename(&tmp, out) {
                let _ = std::fs::rename(&old, out);
                return Err(
                    anyhow::Error::new(e).context(format!("moving the new report into {shown}"))
                );
            }
            tmp_guard.disarm();
            // remove the previous report: only the files it lists, then the directory
            for f in listed.iter().map(String::as_str).chain([MANIFEST]) {
                let _ = std::fs::remove_file(old.join(f));
            }
            std::fs::remove_dir(&old)
                .with_context(|| format!("removing the previous report {}", old.display()))?;
        }
        None => {
            // a missing or empty directory (an empty one is replaced atomically)
            std::fs::rename(&tmp, out)
                .with_context(|| format!("moving the report into {shown}"))?;
            tmp_guard.disarm();
        }
    }
    Ok(())
}
