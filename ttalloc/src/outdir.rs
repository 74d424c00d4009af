//! Writing a report directory safely: nothing the program did not write is ever deleted,
//! moved or replaced; a failed or killed run never leaves `--out` missing; leftovers of a
//! killed run are recovered or removed by the next one.
//!
//! - `--out DIR` is checked before any work ([`Prepared::new`]): a missing or empty `DIR`, or
//!   one holding exactly a previous report of ours (regular files with the names in its
//!   [`MANIFEST`], every name one this program writes, [`is_report_file`]), is accepted;
//!   anything else (a foreign file, a directory or a symbolic link where `report.md` was, a
//!   manifest listing `../x` or `/etc/x`) is refused with exit code 2 and nothing is touched.
//!   `DIR` naming a file is refused the same way.
//! - A symbolic link to a directory as `DIR` is followed: the report replaces the directory it
//!   points to (which must pass the same check); the link itself is kept. A link to a file or a
//!   dangling link is refused (exit 2, saying what it points to).
//! - The parent of `DIR` must be writable: the lock `.<tag>.lock` (with the process id) is
//!   created there before the work, and its failure (an unwritable or read-only parent) is an
//!   input error (exit 2 naming the directory). A second run into the same `DIR` finds the lock
//!   and stops at once; a lock whose process is gone is taken over.
//! - The report is built in `.<tag>.tmp-<pid>-<n>` beside `DIR`, its manifest written first (so
//!   that even a half-written one is recognisably ours), then swapped with `DIR` in one atomic
//!   `renameat2(RENAME_EXCHANGE)`: there is no moment without `DIR`. Where the file system
//!   cannot exchange, `DIR` is renamed to `.<tag>.old-<pid>-<n>` and the new report into place.
//!   The previous report is then removed file by file (only the names its manifest lists).
//! - `<tag>` is `DIR`'s name when it is at most 64 bytes of printable UTF-8, else `~` and a
//!   64-bit hash of it, so that temporary names stay short for any `DIR`.
//! - Recovery, under the lock, at the start of every run: a `.<tag>.tmp-*` or `.<tag>.old-*`
//!   directory of ours (only our manifest and the files it lists, or empty) is removed; if
//!   `DIR` is missing, the newest complete `.<tag>.old-*` is renamed back to `DIR` first (a run
//!   killed between its two renames). A directory of that name that is not ours is left alone.

use crate::InputError;
use anyhow::{Context, Result};
use std::ffi::OsString;
use std::path::{Path, PathBuf};

/// The manifest file of a report directory: a signature line, then one written file per line.
pub const MANIFEST: &str = ".report-manifest";

/// The manifest's first line.
pub(crate) const SIGNATURE: &str =
    "# files written by `cargo xtask` (gyrowheel turntable project); safe to replace as a whole";

/// The extensions of the files a report holds.
const REPORT_EXTENSIONS: &[&str] = &["md", "html", "svg", "csv", "json"];

/// Longest directory name used as is in temporary names, bytes.
const MAX_TAG_BYTES: usize = 64;

/// Whether `name` is the name of a file this program writes into a report directory:
/// `[a-z0-9][a-z0-9_]*` (at most 100 characters) and one of the extensions `md`, `html`, `svg`,
/// `csv`, `json`. No `/`, no `..`, no NUL, never absolute, never hidden: the only names a
/// manifest may make this program remove.
#[must_use]
pub fn is_report_file(name: &str) -> bool {
    let Some((stem, ext)) = name.rsplit_once('.') else {
        return false;
    };
    REPORT_EXTENSIONS.contains(&ext)
        && (1..=100).contains(&stem.len())
        && stem.as_bytes()[0].is_ascii_alphanumeric()
        && stem
            .bytes()
            .all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'_')
}

/// The text of the manifest of a report made of the files `names`: the [`SIGNATURE`] line, then
/// one name per line (what a report directory's [`MANIFEST`] holds).
pub(crate) fn manifest_text<'a>(names: impl IntoIterator<Item = &'a str>) -> String {
    let mut text = format!("{SIGNATURE}\n");
    for name in names {
        text.push_str(name);
        text.push('\n');
    }
    text
}

/// FNV-1a, 64 bit: a stable short name for a long directory name.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(*b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// The short tag of a directory name in temporary names (see the [module](self)).
fn tag(name: &std::ffi::OsStr) -> String {
    use std::os::unix::ffi::OsStrExt;
    match name.to_str() {
        Some(s) if s.len() <= MAX_TAG_BYTES && !s.chars().any(::study::fmt::is_unsafe_char) => {
            s.to_string()
        }
        _ => format!("~{:016x}", fnv1a(name.as_bytes())),
    }
}

/// What a directory is, as far as this program is concerned.
#[derive(Debug)]
enum Contents {
    /// No entry at all.
    Empty,
    /// A report of ours: the files its manifest lists (those present) and whether every
    /// listed file is present.
    Ours {
        present: Vec<String>,
        complete: bool,
    },
    /// Anything else, with a sentence saying why.
    Foreign(String),
}

/// Classify the directory `dir` (not following a symbolic link at `dir` itself).
fn contents(dir: &Path) -> std::io::Result<Contents> {
    let mut entries: Vec<(String, std::fs::FileType)> = Vec::new();
    for e in std::fs::read_dir(dir)? {
        let e = e?;
        let name = e.file_name();
        let Some(name) = name.to_str().map(str::to_string) else {
            return Ok(Contents::Foreign(format!(
                "it holds {}, a name this program never writes",
                ::study::fmt::visible(&name.to_string_lossy())
            )));
        };
        entries.push((name, e.file_type()?));
    }
    if entries.is_empty() {
        return Ok(Contents::Empty);
    }
    let shown = |names: &[&str]| {
        let mut some: Vec<String> = names
            .iter()
            .take(3)
            .map(|n| ::study::fmt::visible(n).into_owned())
            .collect();
        if names.len() > 3 {
            some.push("...".into());
        }
        some.join(", ")
    };
    let manifest_is_file = entries.iter().any(|(n, t)| n == MANIFEST && t.is_file());
    let listed: Option<Vec<String>> = if manifest_is_file {
        std::fs::read_to_string(dir.join(MANIFEST))
            .ok()
            .filter(|t| t.lines().next() == Some(SIGNATURE))
            .map(|t| t.lines().skip(1).map(String::from).collect())
    } else {
        None
    };
    let Some(listed) = listed else {
        let names: Vec<&str> = entries.iter().map(|(n, _)| n.as_str()).collect();
        return Ok(Contents::Foreign(format!(
            "it holds files this program did not write ({})",
            shown(&names)
        )));
    };
    if let Some(bad) = listed.iter().find(|n| !is_report_file(n)) {
        return Ok(Contents::Foreign(format!(
            "its {MANIFEST} lists `{}`, which is not a file this program writes (a crafted or damaged manifest is never trusted)",
            ::study::fmt::visible(bad)
        )));
    }
    let foreign: Vec<&str> = entries
        .iter()
        .filter(|(n, _)| n != MANIFEST && !listed.contains(n))
        .map(|(n, _)| n.as_str())
        .collect();
    if !foreign.is_empty() {
        return Ok(Contents::Foreign(format!(
            "it holds files this program did not write ({})",
            shown(&foreign)
        )));
    }
    let not_files: Vec<&str> = entries
        .iter()
        .filter(|(_, t)| !t.is_file())
        .map(|(n, _)| n.as_str())
        .collect();
    if !not_files.is_empty() {
        return Ok(Contents::Foreign(format!(
            "{} is not a file this program wrote (a directory or a link; this program writes regular files only)",
            shown(&not_files)
        )));
    }
    let present: Vec<String> = entries
        .into_iter()
        .map(|(n, _)| n)
        .filter(|n| n != MANIFEST)
        .collect();
    let complete = listed.iter().all(|n| present.contains(n));
    Ok(Contents::Ours { present, complete })
}

/// Remove a directory of ours: the files it lists, its manifest, then the directory (which
/// fails, leaving it, if anything else appeared in it).
fn remove_ours(dir: &Path, present: &[String]) -> std::io::Result<()> {
    for f in present {
        debug_assert!(is_report_file(f));
        std::fs::remove_file(dir.join(f))?;
    }
    match std::fs::remove_file(dir.join(MANIFEST)) {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
        Err(e) => return Err(e),
    }
    std::fs::remove_dir(dir)
}

/// The directory a report goes to.
#[derive(Debug)]
struct Target {
    /// `--out` as the user gave it (for messages).
    shown: String,
    /// The directory replaced (a symbolic link at `--out` resolved).
    dir: PathBuf,
    /// Its parent.
    parent: PathBuf,
    /// The tag of its name in temporary names.
    tag: String,
}

fn resolve(out: &Path) -> Result<Target, InputError> {
    let shown = out.display().to_string();
    let refuse = |why: String| InputError::new(&shown, why);
    let dir = match std::fs::symlink_metadata(out) {
        Ok(m) if m.file_type().is_symlink() => {
            let link =
                std::fs::read_link(out).map_or_else(|_| "?".into(), |l| l.display().to_string());
            match std::fs::canonicalize(out) {
                Ok(real) if real.is_dir() => real,
                Ok(real) => {
                    return Err(refuse(format!(
                        "is a symbolic link to {}, which is not a directory; choose another --out",
                        real.display()
                    )));
                }
                Err(e) => {
                    return Err(refuse(format!(
                        "is a symbolic link to {link}, which cannot be followed ({e}); choose another --out"
                    )));
                }
            }
        }
        Ok(m) if m.is_dir() => out.to_path_buf(),
        Ok(_) => {
            return Err(refuse(
                "exists and is not a directory; choose another --out".into(),
            ));
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => out.to_path_buf(),
        Err(e) => return Err(refuse(format!("cannot look at the output directory: {e}"))),
    };
    let name = dir
        .file_name()
        .map(OsString::from)
        .filter(|n| n != "." && n != "..")
        .ok_or_else(|| refuse("--out needs a directory name (not `.`, `..` or `/`)".into()))?;
    let parent = dir
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .map_or_else(|| PathBuf::from("."), Path::to_path_buf);
    Ok(Target {
        shown,
        tag: tag(&name),
        dir,
        parent,
    })
}

/// Check that `dir` may be replaced: missing, empty or a report of ours.
fn check_replaceable(t: &Target) -> Result<(), InputError> {
    let shown = if t.dir.as_os_str() == std::ffi::OsStr::new(&t.shown) {
        t.shown.clone()
    } else {
        format!("{} (a link to {})", t.shown, t.dir.display())
    };
    match std::fs::symlink_metadata(&t.dir) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(e) => {
            return Err(InputError::new(
                shown,
                format!("cannot look at the output directory: {e}"),
            ));
        }
        Ok(m) if !m.is_dir() => {
            return Err(InputError::new(
                shown,
                "exists and is not a directory; choose another --out",
            ));
        }
        Ok(_) => {}
    }
    match contents(&t.dir) {
        Ok(Contents::Empty | Contents::Ours { .. }) => Ok(()),
        Ok(Contents::Foreign(why)) => Err(InputError::new(
            shown,
            format!(
                "refusing to write a report here: {why}; choose a new or empty directory with --out, or move them away yourself (nothing was touched)"
            ),
        )),
        Err(e) => Err(InputError::new(
            shown,
            format!("cannot read the output directory: {e}"),
        )),
    }
}

/// Create `dir` and its missing ancestors, returning those it created (outermost first).
fn create_dirs(dir: &Path) -> std::io::Result<Vec<PathBuf>> {
    let mut missing = Vec::new();
    let mut p = dir;
    while std::fs::symlink_metadata(p).is_err() {
        missing.push(p.to_path_buf());
        match p.parent() {
            Some(q) if !q.as_os_str().is_empty() => p = q,
            _ => break,
        }
    }
    missing.reverse();
    let mut created = Vec::new();
    for m in missing {
        match std::fs::create_dir(&m) {
            Ok(()) => created.push(m),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {}
            Err(e) => {
                for c in created.iter().rev() {
                    let _ = std::fs::remove_dir(c);
                }
                return Err(e);
            }
        }
    }
    Ok(created)
}

/// Whether process `pid` is alive and is this program (not a recycled process id).
fn our_process_alive(pid: u32) -> bool {
    let Ok(cmdline) = std::fs::read(format!("/proc/{pid}/cmdline")) else {
        return false;
    };
    let me = std::fs::read("/proc/self/cmdline").unwrap_or_default();
    let exe = |c: &[u8]| -> Vec<u8> {
        let first = c.split(|b| *b == 0).next().unwrap_or_default();
        first
            .rsplit(|b| *b == b'/')
            .next()
            .unwrap_or_default()
            .to_vec()
    };
    // a zombie or a kernel thread has an empty command line
    !cmdline.is_empty() && (me.is_empty() || exe(&cmdline) == exe(&me))
}

/// The lock file (removed when dropped).
struct Lock(PathBuf);

impl Drop for Lock {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

fn lock(t: &Target) -> Result<Lock> {
    let path = t.parent.join(format!(".{}.lock", t.tag));
    for _ in 0..2 {
        match std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&path)
        {
            Ok(mut f) => {
                use std::io::Write;
                writeln!(f, "{}", std::process::id())
                    .with_context(|| format!("writing the lock {}", path.display()))?;
                return Ok(Lock(path));
            }
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                let pid = std::fs::read_to_string(&path)
                    .ok()
                    .and_then(|t| t.trim().parse::<u32>().ok());
                let alive = pid.is_some_and(our_process_alive);
                if alive || pid.is_none() {
                    return Err(InputError::new(
                        &t.shown,
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
                return Err(InputError::new(
                    t.parent.display().to_string(),
                    format!(
                        "cannot write in the output's parent directory (creating the lock {} failed: {e}); choose another --out",
                        path.display()
                    ),
                )
                .into());
            }
        }
    }
    Err(InputError::new(&t.shown, "could not take the output lock").into())
}

/// The leftovers `.<tag>.tmp-*` and `.<tag>.old-*` in the parent (any kind of entry).
fn leftovers(t: &Target) -> Vec<(PathBuf, bool)> {
    let prefix = format!(".{}.", t.tag);
    let Ok(rd) = std::fs::read_dir(&t.parent) else {
        return Vec::new();
    };
    rd.filter_map(Result::ok)
        .filter_map(|e| {
            let name = e.file_name().into_string().ok()?;
            let rest = name.strip_prefix(&prefix)?;
            let (kind, id) = rest.split_at_checked(4)?;
            let old = match kind {
                "tmp-" => false,
                "old-" => true,
                _ => return None,
            };
            (!id.is_empty() && id.bytes().all(|b| b.is_ascii_digit() || b == b'-'))
                .then(|| (e.path(), old))
        })
        .collect()
}

/// Recover or remove the leftovers of a killed run (under the lock). Returns notes for the
/// user (what was recovered, what was left alone).
fn recover(t: &Target) -> Vec<String> {
    let mut notes = Vec::new();
    let mut ours: Vec<(PathBuf, bool, Vec<String>, bool)> = Vec::new();
    for (path, old) in leftovers(t) {
        let is_dir = std::fs::symlink_metadata(&path).is_ok_and(|m| m.is_dir());
        match is_dir.then(|| contents(&path)) {
            Some(Ok(Contents::Empty)) => ours.push((path, old, Vec::new(), false)),
            Some(Ok(Contents::Ours { present, complete })) => {
                ours.push((path, old, present, complete));
            }
            _ => notes.push(format!(
                "left {} alone: it is named like a leftover of this program but is not one",
                path.display()
            )),
        }
    }
    if std::fs::symlink_metadata(&t.dir).is_err() {
        // killed between moving the previous report aside and moving the new one in
        let newest = ours
            .iter()
            .enumerate()
            .filter(|(_, (_, old, _, complete))| *old && *complete)
            .max_by_key(|(_, (p, ..))| {
                std::fs::metadata(p)
                    .and_then(|m| m.modified())
                    .unwrap_or(std::time::UNIX_EPOCH)
            })
            .map(|(i, _)| i);
        if let Some(i) = newest {
            let (p, ..) = ours.remove(i);
            if std::fs::rename(&p, &t.dir).is_ok() {
                notes.push(format!(
                    "recovered the previous report {} from {} (a run was stopped while replacing it)",
                    t.dir.display(),
                    p.display()
                ));
            }
        }
    }
    for (p, _, present, _) in ours {
        if let Err(e) = remove_ours(&p, &present) {
            notes.push(format!(
                "could not remove the leftover {}: {e}",
                p.display()
            ));
        }
    }
    notes
}

/// An output directory checked and locked before the work; [`Prepared::write`] writes the
/// report. Dropping it without writing removes the lock and the directories it created.
pub struct Prepared {
    target: Target,
    lock: Option<Lock>,
    created: Vec<PathBuf>,
    /// What recovery did (printed by the caller).
    pub notes: Vec<String>,
}

impl Drop for Prepared {
    fn drop(&mut self) {
        self.lock = None;
        for c in self.created.iter().rev() {
            let _ = std::fs::remove_dir(c);
        }
    }
}

impl Prepared {
    /// Check `out` (see the [module](self)), create its parent, take the lock and recover the
    /// leftovers of a killed run: everything that can refuse the output happens here, before
    /// the work.
    ///
    /// # Errors
    /// An [`InputError`] (exit code 2) when `out` is a file, a link to one, holds anything that
    /// is not a report of ours, its parent cannot be created or written, or another run holds
    /// the lock. Nothing is moved or deleted then.
    pub fn new(out: &Path) -> Result<Self> {
        let target = resolve(out)?;
        check_replaceable(&target)?;
        let created = create_dirs(&target.parent).map_err(|e| {
            InputError::new(
                target.parent.display().to_string(),
                format!("cannot create the output's parent directory: {e}"),
            )
        })?;
        let mut p = Prepared {
            target,
            lock: None,
            created,
            notes: Vec::new(),
        };
        p.lock = Some(lock(&p.target)?);
        p.notes = recover(&p.target);
        // re-check under the lock: another run or the recovery may have changed it
        check_replaceable(&p.target)?;
        Ok(p)
    }

    /// The directory the report replaces (a symbolic link at `--out` resolved).
    #[must_use]
    pub fn dir(&self) -> &Path {
        &self.target.dir
    }

    /// Write `files` (name, bytes) as the report directory (see the [module](self)).
    ///
    /// # Errors
    /// An [`InputError`] when `--out` changed meanwhile and now holds foreign files; I/O
    /// errors otherwise. On every error the previous report (if any) is in place and nothing
    /// of the user's is touched.
    pub fn write(mut self, files: &[(String, Vec<u8>)]) -> Result<()> {
        for (name, _) in files {
            anyhow::ensure!(
                is_report_file(name),
                "internal: bad report file name {name}"
            );
        }
        let t = &self.target;
        let tmp = (0..100)
            .map(|n| {
                t.parent
                    .join(format!(".{}.tmp-{}-{n}", t.tag, std::process::id()))
            })
            .find(|p| std::fs::create_dir(p).is_ok())
            .with_context(|| {
                format!(
                    "creating a temporary directory beside {} in {}",
                    t.shown,
                    t.parent.display()
                )
            })?;
        let result = build_and_swap(t, &tmp, files);
        if result.is_err() {
            // failed before the swap: our own temporary directory (the files we wrote, the
            // manifest, the directory)
            let names: Vec<String> = files.iter().map(|(n, _)| n.clone()).collect();
            let present: Vec<String> = names.into_iter().filter(|n| tmp.join(n).exists()).collect();
            let _ = remove_ours(&tmp, &present);
        } else {
            self.created.clear();
        }
        result
    }
}

/// Write the report into `tmp` (manifest first), then swap it into place and remove the
/// previous report.
fn build_and_swap(t: &Target, tmp: &Path, files: &[(String, Vec<u8>)]) -> Result<()> {
    use std::io::Write;
    let manifest = manifest_text(files.iter().map(|(file, _)| file.as_str()));
    std::fs::write(tmp.join(MANIFEST), manifest)
        .with_context(|| format!("writing {}", tmp.join(MANIFEST).display()))?;
    for (file, bytes) in files {
        let mut f = std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(tmp.join(file))
            .with_context(|| format!("writing {file}"))?;
        f.write_all(bytes)
            .with_context(|| format!("writing {file}"))?;
    }
    // the directory may have changed while we computed
    check_replaceable(t)?;
    let exists = std::fs::symlink_metadata(&t.dir).is_ok();
    if !exists {
        return std::fs::rename(tmp, &t.dir)
            .with_context(|| format!("moving the report into {}", t.shown));
    }
    let old = match exchange(tmp, &t.dir) {
        Ok(()) => tmp.to_path_buf(),
        Err(e) if exchange_unsupported(&e) => {
            // two renames; a kill between them is recovered by the next run
            let old = t
                .parent
                .join(format!(".{}.old-{}-0", t.tag, std::process::id()));
            std::fs::rename(&t.dir, &old)
                .with_context(|| format!("moving the previous report {} aside", t.shown))?;
            if let Err(e) = std::fs::rename(tmp, &t.dir) {
                let _ = std::fs::rename(&old, &t.dir);
                return Err(anyhow::Error::new(e)
                    .context(format!("moving the new report into {}", t.shown)));
            }
            old
        }
        Err(e) => {
            return Err(
                anyhow::Error::new(e).context(format!("swapping the new report into {}", t.shown))
            );
        }
    };
    // The new report is in place. Remove the previous one: only the files of ours it holds.
    // A failure here loses nothing (the next run removes or leaves the leftover): a warning.
    let cleanup = match contents(&old) {
        Ok(Contents::Empty) => std::fs::remove_dir(&old).map_err(|e| e.to_string()),
        Ok(Contents::Ours { present, .. }) => {
            remove_ours(&old, &present).map_err(|e| e.to_string())
        }
        Ok(Contents::Foreign(why)) => Err(format!("{why}, so it was left there")),
        Err(e) => Err(e.to_string()),
    };
    if let Err(why) = cleanup {
        eprintln!(
            "warning: {}",
            ::study::fmt::terminal(&format!(
                "the new report is in {}; the previous one, moved to {}, was not removed: {why}",
                t.shown,
                old.display()
            ))
        );
    }
    Ok(())
}

/// Swap two directory entries atomically (Linux `renameat2(RENAME_EXCHANGE)`).
fn exchange(a: &Path, b: &Path) -> std::io::Result<()> {
    use rustix::fs::{CWD, RenameFlags, renameat_with};
    renameat_with(CWD, a, CWD, b, RenameFlags::EXCHANGE).map_err(std::io::Error::from)
}

fn exchange_unsupported(e: &std::io::Error) -> bool {
    matches!(
        e.raw_os_error(),
        Some(code) if code == rustix::io::Errno::INVAL.raw_os_error()
            || code == rustix::io::Errno::NOSYS.raw_os_error()
            || code == rustix::io::Errno::OPNOTSUPP.raw_os_error()
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_report_file_names_may_be_removed() {
        for ok in [
            "report.md",
            "report.html",
            "results.json",
            "end_to_end.csv",
            "figure_4_rate_error.svg",
        ] {
            assert!(is_report_file(ok), "{ok}");
        }
        for bad in [
            "../victim.txt",
            "/etc/passwd",
            "..",
            ".",
            "",
            ".report-manifest",
            "a/b.md",
            "x.md\0",
            "victim.txt",
            "report.md/",
            "Report.md",
            ".hidden.md",
            "a..md",
            "-x.md",
        ] {
            assert!(!is_report_file(bad), "{bad:?}");
        }
    }

    #[test]
    fn temporary_names_stay_short_for_any_directory_name() {
        assert_eq!(tag(std::ffi::OsStr::new("paper")), "paper");
        let long = "a".repeat(245);
        let t = tag(std::ffi::OsStr::new(&long));
        assert_eq!(t.len(), 17);
        assert_eq!(t, tag(std::ffi::OsStr::new(&long)), "stable");
        assert_ne!(t, tag(std::ffi::OsStr::new(&"a".repeat(244))));
        assert!(tag(std::ffi::OsStr::new("a\u{1b}b")).starts_with('~'));
    }
}
