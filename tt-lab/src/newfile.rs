//! A new file the user names (`design-schedule --write-study OUT`, `allan --figure`, `allan --write-noise`): checked before the work
//! (it must not exist, its directory must exist and be writable: exit 2 naming the path
//! otherwise), then written atomically, never replacing anything, with the permissions any
//! other program gives a new file (`0666` less the umask).

use crate::error::{Context, InputError, LabError, Result};
use crate::paths::visible;
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
pub(crate) fn create_temporary(dir: &Path) -> std::io::Result<(std::path::PathBuf, std::fs::File)> {
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
    let shown = visible(out);
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
            visible(dir),
            format!("{flag} {shown}: cannot create a file in this directory ({e})"),
        )),
    }
}

/// Where `out` (whose directory exists) is, spelled one way: its directory resolved
/// (`.`, `..` and symbolic links), then its name; `None` when the directory cannot be resolved.
fn where_is(out: &Path) -> Option<std::path::PathBuf> {
    Some(
        std::fs::canonicalize(dir_of(out))
            .ok()?
            .join(out.file_name()?),
    )
}

/// [`check`] each of a command's new files (flag, path), after refusing two flags that name the
/// same file however spelled (`s.svg` and `./s.svg`, a path through a link to the same
/// directory): all before any work, so that nothing is written when one is refused.
///
/// # Errors
/// An [`InputError`] naming both flags and paths, or [`check`]'s.
pub fn check_all(outputs: &[(&str, &Path)]) -> Result<(), InputError> {
    for (i, (flag_a, a)) in outputs.iter().enumerate() {
        for (flag_b, b) in &outputs[i + 1..] {
            if a == b || where_is(a).is_some_and(|w| Some(w) == where_is(b)) {
                return Err(InputError::new(
                    format!("{flag_b} {}", visible(b)),
                    format!(
                        "names the same file as {flag_a} {}: give each output its own path (nothing was written)",
                        visible(a)
                    ),
                ));
            }
        }
    }
    for (flag, p) in outputs {
        check(p, flag)?;
    }
    Ok(())
}

/// Move `tmp` to `out` unless `out` exists (`renameat2(RENAME_NOREPLACE)`, or a hard link
/// where the file system cannot do that). Returns whether the name `tmp` still exists (the
/// hard-link case).
pub(crate) fn link_new(tmp: &Path, out: &Path) -> std::io::Result<bool> {
    use rustix::fs::{CWD, RenameFlags, renameat_with};
    match renameat_with(CWD, tmp, CWD, out, RenameFlags::NOREPLACE) {
        Ok(()) => Ok(false),
        Err(e) if e == rustix::io::Errno::INVAL || e == rustix::io::Errno::NOSYS => {
            std::fs::hard_link(tmp, out).map(|()| true)
        }
        Err(e) => Err(e.into()),
    }
}

/// A complete temporary file beside its destination, not yet in place; its temporary name is
/// removed when dropped unless [`Staged::commit`] renamed it into place. Staging every output first and committing them last
/// means a failure while producing one leaves none of them behind.
#[derive(Debug)]
pub struct Staged {
    tmp: std::path::PathBuf,
    out: std::path::PathBuf,
    linked: bool,
}

/// Write `bytes` to a temporary file beside `out` (mode `0666` less the umask), flushed to
/// disk, for [`Staged::commit`].
///
/// # Errors
/// I/O errors creating or writing the temporary file (it is removed).
pub fn stage(out: &Path, bytes: &[u8]) -> Result<Staged> {
    let dir = dir_of(out);
    let (tmp, mut f) = create_temporary(dir)
        .with_context(|| format!("creating a temporary file in {}", visible(dir)))?;
    let staged = Staged {
        tmp,
        out: out.to_path_buf(),
        linked: false,
    };
    f.write_all(bytes)
        .and_then(|()| f.sync_all())
        .with_context(|| format!("writing {}", visible(&staged.tmp)))?;
    Ok(staged)
}

impl Staged {
    /// Link the file into place only if its destination still does not exist (never
    /// replacing anything).
    ///
    /// # Errors
    /// An [`InputError`] naming the destination and `flag` if it appeared meanwhile (it is not
    /// touched); I/O errors otherwise. The temporary file is removed either way.
    pub fn commit(mut self, flag: &str) -> Result<()> {
        let tmp_remains = link_new(&self.tmp, &self.out).map_err(|e| {
            if e.kind() == std::io::ErrorKind::AlreadyExists {
                LabError::from(InputError::new(
                    visible(&self.out),
                    format!("{flag}: the file appeared meanwhile; not overwritten"),
                ))
            } else {
                LabError::Io {
                    what: format!("writing {}", visible(&self.out)),
                    source: e,
                }
            }
        })?;
        // After a rename the temporary name is gone (and may not be removed: it could be
        // someone else's by now); after a hard link it is a second name of the committed file.
        self.linked = !tmp_remains;
        Ok(())
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        if !self.linked {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}
