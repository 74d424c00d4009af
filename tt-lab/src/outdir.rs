//! Writing a report directory safely: nothing the program did not write is ever deleted,
//! moved or replaced; a failed or killed run never leaves `--out` missing; leftovers of a
//! killed run are recovered or removed by the next one.
//!
//! - `--out DIR` is checked before any work ([`Prepared::new`]): a missing or empty `DIR`, or
//!   one holding exactly a previous report of ours (regular files listed in its [`MANIFEST`],
//!   every name one this program writes, [`is_report_file`], each with the SHA-256 of its
//!   content: a file whose content differs is the user's), is accepted; anything else (a
//!   foreign file, a report file edited since, a directory or a symbolic link where `report.md`
//!   was, a manifest of an older version without hashes, a manifest listing `../x` or `/etc/x`)
//!   is refused with exit code 2 and nothing is touched. `DIR` naming a file, ending in `.` or
//!   `..`, or being a mount point (none can be exchanged) is refused the same way.
//! - An existing `DIR` is replaced keeping its mode and owner, so it must be one the user may
//!   read, write and search (`faccessat` with the effective ids) and own, its group one of the
//!   user's; as root, who may write anywhere, the owner's write bit decides (a `555` directory
//!   is refused).
//! - A symbolic link to a directory as `DIR` is followed: the report replaces the directory it
//!   points to (which must pass the same check); the link itself is kept. A link to a file or a
//!   dangling link is refused (exit 2, saying what it points to).
//! - The parent of `DIR` must be writable: the lock `.<tag>.lock` (a signature line, the process
//!   id and a random token) is created there before the work, and its failure (an unwritable or
//!   read-only parent) is an input error (exit 2 naming the directory). A second run into the
//!   same `DIR` finds the lock and stops at once; a lock of ours whose process is gone is taken
//!   over; a file at that name without the signature (another program's) is refused, never
//!   removed. A run removes its lock only while it holds the text it wrote.
//! - The report is built in `.<tag>.tmp-<pid>-<n>` beside `DIR`, its manifest written first (so
//!   that even a half-written one is recognisably ours), then swapped with `DIR` in one atomic
//!   `renameat2(RENAME_EXCHANGE)`: there is no moment without `DIR`. Where the file system
//!   cannot exchange, `DIR` is renamed to `.<tag>.old-<pid>-<n>` and the new report into place.
//!   The previous report is then removed file by file (only the files its manifest lists with
//!   their content's hash).
//! - `<tag>` is `DIR`'s name when it is at most 64 bytes of printable UTF-8, else `~` and a
//!   64-bit hash of it, so that temporary names stay short for any `DIR`.
//! - Recovery, under the lock, at the start of every run: a `.<tag>.tmp-*` or `.<tag>.old-*`
//!   directory of ours (only our manifest and the files it lists with matching hashes, or
//!   empty) is removed (one holding a file cut short by a kill is left, with a note); if
//!   `DIR` is missing, the newest complete `.<tag>.old-*` is renamed back to `DIR` first (a run
//!   killed between its two renames). A directory of that name that is not ours is left alone.

use crate::error::{Context, InputError, LabError, Result};
use crate::paths::visible;
use std::ffi::OsString;
use std::path::{Path, PathBuf};

/// The manifest file of a report directory: a signature line, then one line per written
/// file: its SHA-256 (64 lowercase hex digits), two spaces and its name (`sha256sum`'s format).
pub const MANIFEST: &str = ".report-manifest";

/// The manifest's first line.
pub const SIGNATURE: &str = "# files written by `cargo xtask` (gyrowheel turntable project) with their SHA-256; a file is replaced only while it matches";

/// The first line of a manifest written before the hashes (names only): such a report's files
/// cannot be proven ours, so a directory holding one is refused, never emptied.
pub const OLD_SIGNATURE: &str =
    "# files written by `cargo xtask` (gyrowheel turntable project); safe to replace as a whole";

/// The extensions of the files a report holds.
const REPORT_EXTENSIONS: &[&str] = &["md", "html", "svg", "csv", "json"];

/// Longest directory name used as is in temporary names, bytes.
const MAX_TAG_BYTES: usize = 64;

/// Whether `name` is the name of a file this program writes into a report directory:
/// `[a-z0-9][a-z0-9_]*` (at most 100 characters) and one of the extensions `md`, `html`, `svg`,
/// `csv`, `json`. No `/`, no `..`, no NUL, never absolute, never hidden: the only names a
/// manifest may make this program remove (and then only while the content matches its hash).
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

/// The SHA-256 of `bytes`, 64 lowercase hex digits.
pub fn sha256_hex(bytes: &[u8]) -> String {
    use sha2::Digest;
    hex(&sha2::Sha256::digest(bytes))
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// The SHA-256 of the file at `path`, read in blocks (memory does not grow with its size).
fn file_sha256(path: &Path) -> std::io::Result<String> {
    use sha2::Digest;
    let mut h = sha2::Sha256::new();
    std::io::copy(&mut std::fs::File::open(path)?, &mut h)?;
    Ok(hex(&h.finalize()))
}

/// The text of the manifest of a report made of `files` (name, content): the [`SIGNATURE`]
/// line, then `<sha256>  <name>` per file (what a report directory's [`MANIFEST`] holds).
pub fn manifest_text<'a>(files: impl IntoIterator<Item = (&'a str, &'a [u8])>) -> String {
    let mut text = format!("{SIGNATURE}\n");
    for (name, bytes) in files {
        text.push_str(&sha256_hex(bytes));
        text.push_str("  ");
        text.push_str(name);
        text.push('\n');
    }
    text
}

/// The (name, SHA-256) lines of a manifest's text after its signature; `Err` with why the
/// first line that is not `<64 lowercase hex digits>  <report file name>`, or that lists a name
/// again, is not ours (this program lists each file once, so a name listed twice, even with
/// one matching hash, proves nothing).
fn manifest_entries(text: &str) -> Result<Vec<(String, String)>, String> {
    let mut entries: Vec<(String, String)> = Vec::new();
    for line in text.lines().skip(1) {
        let (h, n) = line
            .split_once("  ")
            .filter(|(h, n)| {
                h.len() == 64
                    && h.bytes()
                        .all(|b| b.is_ascii_digit() || (b'a'..=b'f').contains(&b))
                    && is_report_file(n)
            })
            .ok_or_else(|| {
                format!(
                    "has the line `{}`, which is not `<sha256>  <name of a file this program writes>`",
                    ::tt_core::human::visible(line)
                )
            })?;
        if entries.iter().any(|(m, _)| m == n) {
            return Err(format!(
                "lists {} twice (this program lists each file once)",
                ::tt_core::human::visible(n)
            ));
        }
        entries.push((n.to_string(), h.to_string()));
    }
    Ok(entries)
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
        Some(s) if s.len() <= MAX_TAG_BYTES && !s.chars().any(::tt_core::human::is_unsafe_char) => {
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
                ::tt_core::human::visible(&name.to_string_lossy())
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
            .map(|n| ::tt_core::human::visible(n).into_owned())
            .collect();
        if names.len() > 3 {
            some.push("...".into());
        }
        some.join(", ")
    };
    let manifest_is_file = entries.iter().any(|(n, t)| n == MANIFEST && t.is_file());
    let text = if manifest_is_file {
        std::fs::read_to_string(dir.join(MANIFEST)).ok()
    } else {
        None
    };
    let first = text
        .as_deref()
        .and_then(|t| t.lines().next())
        .map(str::to_string);
    if first.as_deref() == Some(OLD_SIGNATURE) {
        return Ok(Contents::Foreign(format!(
            "its {MANIFEST} is of an older version of this program (names without content hashes), so its files cannot be proven to be what this program wrote"
        )));
    }
    let Some(text) = text.filter(|_| first.as_deref() == Some(SIGNATURE)) else {
        let names: Vec<&str> = entries.iter().map(|(n, _)| n.as_str()).collect();
        return Ok(Contents::Foreign(format!(
            "it holds files this program did not write ({})",
            shown(&names)
        )));
    };
    let listed = match manifest_entries(&text) {
        Ok(l) => l,
        Err(why) => {
            return Ok(Contents::Foreign(format!(
                "its {MANIFEST} {why} (a crafted or damaged manifest is never trusted)"
            )));
        }
    };
    let foreign: Vec<&str> = entries
        .iter()
        .filter(|(n, _)| n != MANIFEST && !listed.iter().any(|(l, _)| l == n))
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
    // a name proves nothing: only a file whose content is what this program wrote is ours
    for name in &present {
        let want = listed.iter().find(|(l, _)| l == name).map(|(_, h)| h);
        if want != Some(&file_sha256(&dir.join(name))?) {
            return Ok(Contents::Foreign(format!(
                "{} is listed in its {MANIFEST} but its content is not what this program wrote there (changed since, or not ours)",
                ::tt_core::human::visible(name)
            )));
        }
    }
    let complete = listed.iter().all(|(n, _)| present.contains(n));
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
    /// Whether `--out` is a symbolic link (to `dir`).
    linked: bool,
}

/// Whether `out` as written ends in a `.` or `..` component (`od/.`, `od/..`, `od/./`): such a
/// name cannot be exchanged with a new directory (the kernel says "busy"), so it is refused.
fn ends_in_dot(out: &Path) -> bool {
    use std::os::unix::ffi::OsStrExt;
    let mut b = out.as_os_str().as_bytes();
    while b.len() > 1 && b.ends_with(b"/") {
        b = &b[..b.len() - 1];
    }
    let last = b.rsplit(|c| *c == b'/').next().unwrap_or_default();
    last == b"." || last == b".."
}

fn resolve(out: &Path) -> Result<Target, InputError> {
    let shown = visible(out);
    let refuse = |why: String| InputError::new(&shown, why);
    if ends_in_dot(out) {
        return Err(refuse(
            "--out ends in `.` or `..`: a report replaces its directory, which needs the directory's own name (write it without the `.` or `..`)".into(),
        ));
    }
    let dir = match std::fs::symlink_metadata(out) {
        Ok(m) if m.file_type().is_symlink() => {
            let link = std::fs::read_link(out).map_or_else(|_| "?".into(), |l| visible(&l));
            match std::fs::canonicalize(out) {
                Ok(real) if real.is_dir() => real,
                Ok(real) => {
                    return Err(refuse(format!(
                        "is a symbolic link to {}, which is not a directory; choose another --out",
                        visible(&real)
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
    if let (Ok(d), Ok(p)) = (std::fs::metadata(&dir), std::fs::metadata(&parent)) {
        use std::os::unix::fs::MetadataExt;
        if d.dev() != p.dev() {
            return Err(refuse(
                "is a mount point: a report replaces its directory, which cannot be done to a mount point; choose a directory inside it".into(),
            ));
        }
    }
    Ok(Target {
        linked: dir != out,
        shown,
        tag: tag(&name),
        dir,
        parent,
    })
}

/// Refuse an existing `dir` that the report could not replace keeping its mode and owner: one
/// the user cannot read, write and search (`faccessat` with the effective ids; as root, which
/// may write anywhere, the owner's write bit decides: a `555` directory is refused), one owned
/// by another user, or (not as root) one whose group is not one of the user's.
fn check_keepable(t: &Target) -> Result<(), InputError> {
    use rustix::fs::{Access, AtFlags, CWD, accessat};
    use std::os::unix::fs::MetadataExt;
    let m = match std::fs::metadata(&t.dir) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(e) => {
            return Err(InputError::new(
                &t.shown,
                format!("cannot look at the output directory: {e}"),
            ));
        }
        Ok(m) => m,
    };
    let euid = rustix::process::geteuid();
    let refuse = |why: String| {
        InputError::new(
            &t.shown,
            format!(
                "{why}; a report replaces the directory keeping its mode and owner, so nothing was written: choose another --out"
            ),
        )
    };
    let access = Access::READ_OK | Access::WRITE_OK | Access::EXEC_OK;
    if euid.is_root() {
        if m.mode() & 0o200 == 0 {
            return Err(refuse(format!(
                "its owner may not write it (mode {:o}; as root, the owner's write bit decides)",
                m.mode() & 0o7777
            )));
        }
    } else if let Err(e) = accessat(CWD, &t.dir, access, AtFlags::EACCESS) {
        return Err(refuse(format!(
            "you may not read and write it (mode {:o}: {e})",
            m.mode() & 0o7777
        )));
    } else if m.uid() != euid.as_raw() {
        return Err(refuse(format!(
            "it belongs to another user (uid {})",
            m.uid()
        )));
    } else if m.gid() != rustix::process::getegid().as_raw()
        && !rustix::process::getgroups().is_ok_and(|g| g.iter().any(|g| g.as_raw() == m.gid()))
    {
        return Err(refuse(format!(
            "its group (gid {}) is not one of yours",
            m.gid()
        )));
    }
    Ok(())
}

/// Check that `dir` may be replaced: missing, empty or a report of ours.
fn check_replaceable(t: &Target) -> Result<(), InputError> {
    let shown = if t.linked {
        format!("{} (a link to {})", t.shown, visible(&t.dir))
    } else {
        t.shown.clone()
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

/// The first line of a lock of ours; the next two are `pid <process id>` and
/// `token <32 hex digits>` (random: which run wrote it).
const LOCK_SIGNATURE: &str =
    "# lock of a `cargo xtask` report run (gyrowheel turntable project); removed by that run";

/// A lock file's text for this run: the [`LOCK_SIGNATURE`], the process id, a random token.
fn lock_text() -> String {
    use std::io::Read;
    let mut seed = [0_u8; 16];
    let random = std::fs::File::open("/dev/urandom").and_then(|mut f| f.read_exact(&mut seed));
    let now = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap_or_default();
    // without /dev/urandom: the process id and the time to the nanosecond, hashed
    let token = sha256_hex(
        format!(
            "{:?} {} {} {:?}",
            random.map(|()| seed),
            std::process::id(),
            now.as_nanos(),
            std::thread::current().id()
        )
        .as_bytes(),
    );
    format!(
        "{LOCK_SIGNATURE}\npid {}\ntoken {}\n",
        std::process::id(),
        &token[..32]
    )
}

/// The process id in a lock of ours; `None` when `text` is not one (no signature, or not
/// exactly the three lines [`lock_text`] writes).
fn lock_pid(text: &str) -> Option<u32> {
    let mut lines = text.lines();
    (lines.next() == Some(LOCK_SIGNATURE)).then_some(())?;
    let pid = lines.next()?.strip_prefix("pid ")?.parse::<u32>().ok()?;
    let token = lines.next()?.strip_prefix("token ")?;
    (token.len() == 32 && token.bytes().all(|b| b.is_ascii_hexdigit()) && lines.next().is_none())
        .then_some(pid)
}

/// The lock file, with the text this run wrote in it: removed when dropped, only while it still
/// holds that text (never another run's lock or another program's file).
struct Lock {
    path: PathBuf,
    text: String,
}

impl Drop for Lock {
    fn drop(&mut self) {
        if std::fs::read_to_string(&self.path).is_ok_and(|t| t == self.text) {
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

fn lock(t: &Target) -> Result<Lock> {
    let path = t.parent.join(format!(".{}.lock", t.tag));
    let shown_path = || visible(&path);
    let text = lock_text();
    for _ in 0..3 {
        // written whole beside it, then linked into place without replacing anything: another
        // run never sees a lock half written
        let placed = crate::newfile::create_temporary(&t.parent).and_then(|(tmp, mut f)| {
            use std::io::Write;
            let linked = f
                .write_all(text.as_bytes())
                .and_then(|()| crate::newfile::link_new(&tmp, &path));
            if !matches!(linked, Ok(false)) {
                // still at its temporary name (not linked, or linked as a second name)
                let _ = std::fs::remove_file(&tmp);
            }
            linked
        });
        match placed {
            Ok(_) => {
                return Ok(Lock {
                    path: path.clone(),
                    text,
                });
            }
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                let found = match std::fs::read_to_string(&path) {
                    Ok(found) => found,
                    // released meanwhile: try again
                    Err(e) if e.kind() == std::io::ErrorKind::NotFound => continue,
                    Err(_) => String::new(),
                };
                let Some(pid) = lock_pid(&found) else {
                    return Err(InputError::new(
                        shown_path(),
                        format!(
                            "the lock of --out {} has this name, but this file is not a lock of this program (it lacks its signature); it was not touched: move it away if no run is writing the report, or choose another --out",
                            t.shown
                        ),
                    )
                    .into());
                };
                if our_process_alive(pid) {
                    return Err(InputError::new(
                        t.shown.clone(),
                        format!(
                            "another run is writing this report (lock file {}, process {pid}); wait for it to finish",
                            shown_path()
                        ),
                    )
                    .into());
                }
                // a lock of ours whose process is gone: stale (removed only while unchanged)
                if std::fs::read_to_string(&path).is_ok_and(|t| t == found) {
                    std::fs::remove_file(&path)
                        .with_context(|| format!("removing the stale lock {}", shown_path()))?;
                }
            }
            Err(e) => {
                return Err(InputError::new(
                    visible(&t.parent),
                    format!(
                        "cannot write in the output's parent directory (creating the lock {} failed: {e}); choose another --out",
                        shown_path()
                    ),
                )
                .into());
            }
        }
    }
    Err(InputError::new(t.shown.clone(), "could not take the output lock").into())
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
                visible(&path)
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
                    visible(&t.dir),
                    visible(&p)
                ));
            }
        }
    }
    for (p, _, present, _) in ours {
        if let Err(e) = remove_ours(&p, &present) {
            notes.push(format!(
                "could not remove the leftover {}: {e}",
                visible(&p)
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
        check_keepable(&target)?;
        let created = create_dirs(&target.parent).map_err(|e| {
            InputError::new(
                visible(&target.parent),
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
        check_keepable(&p.target)?;
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
            if !is_report_file(name) {
                return Err(LabError::Library(
                    format!("internal: bad report file name {name}").into(),
                ));
            }
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
                    visible(&t.parent)
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
    let manifest = manifest_text(files.iter().map(|(file, b)| (file.as_str(), b.as_slice())));
    std::fs::write(tmp.join(MANIFEST), manifest)
        .with_context(|| format!("writing {}", visible(&tmp.join(MANIFEST))))?;
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
    if exists {
        // the new directory takes the mode and owner of the one it replaces (checked possible
        // before the work, by `check_keepable`)
        use std::os::unix::fs::{MetadataExt, PermissionsExt};
        let m = std::fs::metadata(&t.dir).with_context(|| format!("looking at {}", t.shown))?;
        std::os::unix::fs::chown(tmp, Some(m.uid()), Some(m.gid()))
            .and_then(|()| {
                std::fs::set_permissions(tmp, std::fs::Permissions::from_mode(m.mode() & 0o7777))
            })
            .with_context(|| format!("giving the new report the mode and owner of {}", t.shown))?;
    } else {
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
                return Err(LabError::Io {
                    what: format!("moving the new report into {}", t.shown),
                    source: e,
                });
            }
            old
        }
        Err(e) => {
            return Err(LabError::Io {
                what: format!("swapping the new report into {}", t.shown),
                source: e,
            });
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
            ::tt_core::human::terminal(&format!(
                "the new report is in {}; the previous one, moved to {}, was not removed: {why}",
                t.shown,
                visible(&old)
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
    fn a_manifest_lists_each_file_with_the_sha256_of_its_content() {
        let text = manifest_text([("report.md", b"abc".as_slice()), ("a.svg", b"".as_slice())]);
        assert_eq!(
            manifest_entries(&text).unwrap(),
            [
                (
                    "report.md".to_string(),
                    // FIPS 180-2's example "abc"
                    "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad".to_string()
                ),
                (
                    "a.svg".to_string(),
                    "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855".to_string()
                ),
            ]
        );
        for bad in [
            "report.md",
            "ba7816bf  report.md",
            "BA7816BF8F01CFEA414140DE5DAE2223B00361A396177A9CB410FF61F20015AD  report.md",
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad  ../x.md",
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad report.md",
        ] {
            let why = manifest_entries(&format!("{SIGNATURE}\n{bad}\n")).unwrap_err();
            assert!(why.contains(&format!("`{bad}`")), "{why}");
        }
        // a name listed twice proves nothing, even when one of its hashes matches
        let twice = format!("{text}{}", text.lines().nth(1).unwrap());
        let why = manifest_entries(&twice).unwrap_err();
        assert!(why.contains("lists report.md twice"), "{why}");
    }

    #[test]
    fn only_a_lock_with_the_signature_is_ours() {
        let text = lock_text();
        assert_eq!(lock_pid(&text), Some(std::process::id()));
        assert_ne!(text, lock_text(), "a new token per lock");
        for foreign in [
            "1234\n".to_string(),
            String::new(),
            format!("{LOCK_SIGNATURE}\npid 1234\n"),
            format!("{text}more\n"),
            text.replace("pid ", "pid x"),
        ] {
            assert_eq!(lock_pid(&foreign), None, "{foreign:?}");
        }
    }

    #[test]
    fn an_out_ending_in_a_dot_component_is_recognised() {
        for dot in ["od/.", "od/./", "od/..", "od/..//", ".", "..", "/a/b/."] {
            assert!(ends_in_dot(Path::new(dot)), "{dot}");
        }
        for name in ["od", "od.", "od/.x", "od/..x", "./od", "../od", "/"] {
            assert!(!ends_in_dot(Path::new(name)), "{name}");
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
