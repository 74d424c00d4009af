//! A new file the user names (`design-schedule --write-study OUT`): checked before the work
//! (it must not exist, its directory must exist and be writable: exit 2 naming the path
//! otherwise), then written atomically, never replacing anything, with the permissions any
//! other program gives a new file (`0666` less the umask).

use crate::InputError;
use anyhow::{Context, Result};
use std::io::Write;
use std::os::unix::fs::OpenOptionsExt;
use std::path::Path;

fn dir_of(out: &Path) -> &Path {
    out.parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}

/// A free temporary name beside `out`, short whatever `out`'s length, created empty with
/// mode `0666` (the umask applies).
fn create_temporary(dir: &Path) -> std::io::Result<(std::path::PathBuf, std::fs::File)> {
    let mut last = None;
    for n in 0..100 {
        let p = dir.join(format!(".xtask-{}-{n}.tmp", std::process::id()));
        match std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .mode(0o666)
            .open(&p)
        {
            Ok(f) => return Ok((p, f)),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => last = Some(e),
            Err(e) => return Err(e),
        }
    }
    Err(last.unwrap_or_else(|| std::io::Error::other("no free temporary name")))
}

/// Refuse `out` (for `flag`) before any work: it exists (any kind of entry), it has no file
/// name, its directory does not exist, or nothing can be created there (permissions, a
/// read-only file system: found by creating and removing a temporary file).
///
/// # Errors
/// An [`InputError`] naming `out` (or its directory) and `flag`.
pub fn check(out: &Path, flag: &str) -> Result<(), InputError> {
    let shown = out.display().to_string();
    if out.symlink_metadata().is_ok() {
        return Err(InputError::new(
            &shown,
            format!(
                "{flag}: the file exists; choose a new name (an existing file is never overwritten)"
            ),
        ));
    }
    if out.file_name().is_none() {
        return Err(InputError::new(&shown, format!("{flag} needs a file name")));
    }
    let dir = dir_of(out);
    if !dir.is_dir() {
        return Err(InputError::new(
            &shown,
            format!("{flag}: its directory does not exist"),
        ));
    }
    match create_temporary(dir) {
        Ok((p, _)) => {
            let _ = std::fs::remove_file(p);
            Ok(())
        }
        Err(e) => Err(InputError::new(
            dir.display().to_string(),
            format!("{flag} {shown}: cannot create a file in this directory ({e})"),
        )),
    }
}

/// Move `tmp` to `out` unless `out` exists (`renameat2(RENAME_NOREPLACE)`, or a hard link
/// where the file system cannot do that).
fn link_new(tmp: &Path, out: &Path) -> std::io::Result<()> {
    use rustix::fs::{CWD, RenameFlags, renameat_with};
    match renameat_with(CWD, tmp, CWD, out, RenameFlags::NOREPLACE) {
        Ok(()) => Ok(()),
        Err(e) if e == rustix::io::Errno::INVAL || e == rustix::io::Errno::NOSYS => {
            std::fs::hard_link(tmp, out)
        }
        Err(e) => Err(e.into()),
    }
}

/// Write `bytes` to the new file `out`: a temporary file beside it, flushed, then linked into
/// place only if `out` still does not exist (never replacing anything).
///
/// # Errors
/// An [`InputError`] if `out` appeared meanwhile (it is not touched); I/O errors otherwise
/// (the temporary file is removed).
pub fn write(out: &Path, bytes: &[u8], flag: &str) -> Result<()> {
    let dir = dir_of(out);
    let (tmp, mut f) = create_temporary(dir)
        .with_context(|| format!("creating a temporary file in {}", dir.display()))?;
    let result = f
        .write_all(bytes)
        .and_then(|()| f.sync_all())
        .with_context(|| format!("writing {}", tmp.display()))
        .and_then(|()| {
            link_new(&tmp, out).map_err(|e| {
                if e.kind() == std::io::ErrorKind::AlreadyExists {
                    anyhow::Error::new(InputError::new(
                        out.display().to_string(),
                        format!("{flag}: the file appeared meanwhile; not overwritten"),
                    ))
                } else {
                    anyhow::Error::new(e).context(format!("writing {}", out.display()))
                }
            })
        });
    let _ = std::fs::remove_file(&tmp);
    result
}
