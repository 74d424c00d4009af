//! Issue 19: nothing outside `--out` is ever touched, a killed run never loses a report, and a
//! study's text never reaches a terminal, a report or a shell line raw.
//!
//! - A crafted `.report-manifest` cannot make the program delete anything (only report file
//!   names of ours are ever removed).
//! - The study's `name` is a file-name-safe slug: the default report directory stays inside
//!   `target/report`.
//! - Control characters of a study are shown escaped by every command; `report.md` and
//!   `report.html` show the study's text literally (checked with a CommonMark renderer); the
//!   "Reproduce:" line and design-schedule's `command` shell-quote every path.
//! - Replacing a report is crash-safe: the leftovers of a killed run (constructed on disk) are
//!   recovered or removed; a user's directory where a report file was is refused before
//!   anything moves.
//! - `--write-study` files get the umask's permissions; unwritable places are refused before
//!   the work (exit 2 naming the path); a 245-character `--out` works; a symbolic link to a
//!   directory as `--out` is followed.

mod common;

use common::{
    assert_input_error, hidden_names, names, ok, paper_into, root, run, sha256_hex, stderr, stdout,
    study_text, write,
};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The manifest's signature line (the file format of a report directory).
const SIGNATURE: &str = "# files written by `cargo xtask` (gyrowheel turntable project) with their SHA-256; a file is replaced only while it matches";

/// A report directory of ours at `dir` (manifest listing `listed` with the hash of `old
/// <name>`, holding `present` with that content).
fn fake_report(dir: &Path, listed: &[&str], present: &[&str]) {
    std::fs::create_dir_all(dir).unwrap();
    let mut m = format!("{SIGNATURE}\n");
    for l in listed {
        m.push_str(&format!(
            "{}  {l}\n",
            sha256_hex(format!("old {l}").as_bytes())
        ));
    }
    std::fs::write(dir.join(".report-manifest"), m).unwrap();
    for p in present {
        std::fs::write(dir.join(p), format!("old {p}")).unwrap();
    }
}

/// The report in `out` is a complete new one (1500 samples) and nothing but it.
fn assert_new_report(out: &Path) {
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("results.json")).unwrap()).unwrap();
    assert_eq!(json["samples"], 1500);
    let manifest = std::fs::read_to_string(out.join(".report-manifest")).unwrap();
    let mut listed: Vec<String> = manifest
        .lines()
        .skip(1)
        .map(|l| {
            let (hash, name) = l.split_once("  ").unwrap();
            assert_eq!(
                sha256_hex(&std::fs::read(out.join(name)).unwrap()),
                hash,
                "{name}"
            );
            name.to_string()
        })
        .collect();
    listed.push(".report-manifest".into());
    listed.sort();
    assert_eq!(names(out), listed);
}

/// Issue 19 §2: a manifest that lists `../victim.txt` and an absolute path is not ours: the run
/// is refused (exit 2, naming the manifest's bad entry) before anything moves; the victims and
/// the directory are untouched. (Before: both victims were deleted, exit 0.)
#[test]
fn crafted_manifest_never_deletes_anything_outside_out() {
    let dir = tempfile::tempdir().unwrap();
    let elsewhere = tempfile::tempdir().unwrap();
    let victim = write(dir.path(), "victim.txt", "keep me");
    let victim2 = write(elsewhere.path(), "victim2.txt", "keep me too");
    let out = dir.path().join("out");
    for bad in ["../victim.txt".to_string(), victim2.display().to_string()] {
        fake_report(&out, &["report.md", &bad], &["report.md"]);
        let before = names(&out);
        let o = paper_into(&out);
        assert_input_error(&o, &[out.to_str().unwrap(), ".report-manifest", &bad]);
        assert_eq!(std::fs::read_to_string(&victim).unwrap(), "keep me");
        assert_eq!(std::fs::read_to_string(&victim2).unwrap(), "keep me too");
        assert_eq!(names(&out), before, "the directory is untouched");
        assert_eq!(names(dir.path()), ["out", "victim.txt"], "nothing moved");
        std::fs::remove_dir_all(&out).unwrap();
    }
}

/// Issue 19 §2: the study's `name` picks the default report directory
/// (`target/report/<name>`); a path, `..`, `.`, a NUL and 300 characters are refused when the
/// study is read (exit 2 naming the key `name`), before any work and without writing anything.
#[test]
fn study_name_cannot_leave_the_report_directory() {
    let dir = tempfile::tempdir().unwrap();
    let long = "n".repeat(300);
    for (i, name) in ["../../../escaped", "..", ".", "nul\\u0000", long.as_str()]
        .iter()
        .enumerate()
    {
        let text = study_text("gyrowheel-2017").replacen(
            "name = \"gyrowheel-2017\"",
            &format!("name = \"{name}\""),
            1,
        );
        let p = write(dir.path(), &format!("s{i}.toml"), &text);
        let o = run(&[
            "report",
            "--study",
            p.to_str().unwrap(),
            "--samples",
            "1500",
        ]);
        assert_input_error(&o, &[p.to_str().unwrap(), "key `name`", "file-name-safe"]);
    }
    assert!(!root().join("escaped").exists());
    assert!(!root().join("target/escaped").exists());
}

/// Characters that must never appear raw in an output (the line feed and tab of the output's
/// own layout excepted).
fn raw_controls(text: &str) -> Vec<char> {
    text.chars()
        .filter(|c| tt_core::human::is_unsafe_char(*c) && !matches!(c, '\n' | '\t'))
        .collect()
}

/// The paper's study with hostile text in its description, units and a joint's description.
fn hostile_study() -> String {
    let text = study_text("gyrowheel-2017");
    let desc = text
        .lines()
        .find(|l| l.starts_with("description = "))
        .unwrap()
        .to_string();
    text.replacen(
        &desc,
        r#"description = "<script>alert(1)</script> **bold** `code` [x](#y) &amp; _u_ ~~s~~ \u001b[31mred\u0007 \r\n# Heading\n- item | pipe\n\n    indented""#,
        1,
    )
    .replace(
        "unit = \"deg_per_h\"",
        r#"unit = "deg/h<img src=x onerror=alert(2)>""#,
    )
    .replacen(
        "phi1 = \"outer axis\"",
        r#"phi1 = "outer <b>axis</b>""#,
        1,
    )
}

/// Run `cmd` through bash word splitting only (`set -- CMD`) and return the words it makes:
/// a path that is not quoted would run `echo PWNED` or split.
fn shell_words(cmd: &str) -> Vec<String> {
    let o = Command::new("bash")
        .arg("-c")
        .arg(format!("set -- {cmd}; printf '%s\\0' \"$@\""))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    String::from_utf8(o.stdout)
        .unwrap()
        .split('\0')
        .filter(|w| !w.is_empty())
        .map(String::from)
        .collect()
}

/// Issue 19 §2: a study's text (a description with ESC, BEL, CR and line breaks; units, a
/// joint's description and a tolerance sheet's name with raw HTML; Markdown markup) and a path
/// `my study;echo PWNED;.toml`:
/// - no command prints a raw control character (standard output and errors; the one-line
///   labels refuse them at parse time, see study's tests);
/// - `report.md`, rendered by a CommonMark renderer, and `report.html` show the text literally
///   (no tag, emphasis, link, heading or code of the study's making);
/// - no file of the report carries a raw control character;
/// - the "Reproduce:" line and design-schedule's `command` keep the path one shell word, and
///   the study written by `--write-study` parses (its comment cannot inject TOML).
#[test]
fn study_text_never_reaches_a_terminal_a_report_or_a_shell_line_raw() {
    let dir = tempfile::tempdir().unwrap();
    let study = write(dir.path(), "my study;echo PWNED;.toml", &hostile_study());
    let s = study.to_str().unwrap();
    let tol = write(
        dir.path(),
        "tol.toml",
        &std::fs::read_to_string(root().join("studies/tolerances/table4.toml"))
            .unwrap()
            .replacen(
                "name = \"Zhao et al. 2017, Table 4 (the paper's allocation)\"",
                r#"name = "<script>x</script>""#,
                1,
            ),
    );
    let t = tol.to_str().unwrap();
    for cmd in [
        vec!["requirement", "--study", s],
        vec!["allocate", "--study", s],
        vec!["end-to-end", "--study", s, "--samples", "1500"],
        vec![
            "check-turntable",
            "--study",
            s,
            "--tolerances",
            t,
            "--samples",
            "200",
        ],
    ] {
        let o = run(&cmd);
        ok(&o);
        let (out, err) = (stdout(&o), stderr(&o));
        assert!(raw_controls(&out).is_empty(), "{cmd:?}: {out:?}");
        assert!(raw_controls(&err).is_empty(), "{cmd:?}: {err:?}");
    }
    // an error that quotes the file's text
    let bad = write(
        dir.path(),
        "bad.toml",
        &study_text("gyrowheel-2017").replacen(
            "delta_r = \"small-angle\" ",
            r#"delta_r = "x\u001b[31m\u0007""#,
            1,
        ),
    );
    let o = run(&["requirement", "--study", bad.to_str().unwrap()]);
    assert_input_error(&o, &["calibration.delta_r", "x\\u{1b}[31m\\u{7}"]);
    assert!(raw_controls(&stderr(&o)).is_empty(), "{:?}", stderr(&o));

    // the report
    let out = dir.path().join("out");
    let o = run(&[
        "report",
        "--study",
        s,
        "--tolerances",
        t,
        "--out",
        out.to_str().unwrap(),
        "--samples",
        "1500",
    ]);
    ok(&o);
    assert!(raw_controls(&stdout(&o)).is_empty(), "{}", stdout(&o));
    for f in names(&out) {
        let text = std::fs::read_to_string(out.join(&f)).unwrap();
        assert!(
            raw_controls(&text).is_empty(),
            "{f}: {:?}",
            raw_controls(&text)
        );
    }
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    let mut rendered = String::new();
    pulldown_cmark::html::push_html(
        &mut rendered,
        pulldown_cmark::Parser::new_ext(
            &md,
            pulldown_cmark::Options::ENABLE_TABLES | pulldown_cmark::Options::ENABLE_STRIKETHROUGH,
        ),
    );
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    for (what, page) in [("report.md rendered", &rendered), ("report.html", &html)] {
        for raw in [
            "<script",
            "<img src=x",
            "<b>axis",
            "<strong>bold",
            "<em>u</em>",
            "<del>s",
            "href=\"#y\"",
            "<h1>Heading",
            "<code>code</code>",
        ] {
            assert!(!page.contains(raw), "{what} carries `{raw}` from the study");
        }
        for shown in [
            "&lt;script&gt;alert(1)&lt;/script&gt; **bold** `code` [x](#y) &amp;amp; _u_ ~~s~~ \\u{1b}[31mred\\u{7}",
            "# Heading - item",
            "deg/h&lt;img src=x onerror=alert(2)&gt;",
            "outer &lt;b&gt;axis&lt;/b&gt;",
            "&lt;script&gt;x&lt;/script&gt;",
        ] {
            assert!(
                page.contains(shown),
                "{what} does not show `{shown}` literally"
            );
        }
    }
    // the Reproduce line keeps the path one word
    let line = md
        .lines()
        .find(|l| l.contains("Reproduce: `"))
        .expect("a Reproduce line");
    let cmd = &line[line.find("Reproduce: `").unwrap() + 12..line.rfind('`').unwrap()];
    let words = shell_words(cmd);
    assert_eq!(words[..3], ["cargo", "xtask", "report"]);
    assert!(words.iter().any(|w| w == s), "{words:?}");
    assert!(words.iter().any(|w| w == t), "{words:?}");
    assert!(
        !words.iter().any(|w| w.contains("PWNED") && w != s),
        "{words:?}"
    );

    // design-schedule: the command and the written study
    let written = dir.path().join("designed.toml");
    let o = run(&[
        "design-schedule",
        "--study",
        s,
        "--json",
        "--write-study",
        written.to_str().unwrap(),
    ]);
    ok(&o);
    assert!(raw_controls(&stderr(&o)).is_empty());
    let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let words = shell_words(json["command"].as_str().unwrap());
    assert_eq!(words[..3], ["cargo", "xtask", "design-schedule"]);
    assert!(words.iter().any(|w| w == s), "{words:?}");
    let back = study::Study::load(&written).unwrap();
    assert_eq!(back.name, "gyrowheel-2017");
}

/// Issue 19 §2: a study path with a line break cannot inject a line into the study that
/// `--write-study` writes (the command in its comment is one `$'...'` word).
#[test]
fn a_line_break_in_a_path_cannot_inject_into_the_written_study() {
    let dir = tempfile::tempdir().unwrap();
    let study = write(
        dir.path(),
        "x\nname = \"injected\"\n.toml",
        &study_text("gyrowheel-2017"),
    );
    let written = dir.path().join("designed.toml");
    let o = run(&[
        "design-schedule",
        "--study",
        study.to_str().unwrap(),
        "--write-study",
        written.to_str().unwrap(),
    ]);
    ok(&o);
    assert!(raw_controls(&stdout(&o)).is_empty(), "{}", stdout(&o));
    let text = std::fs::read_to_string(&written).unwrap();
    assert!(text.contains("\\U0000000aname = \"injected\""), "{text}");
    let back = study::Study::load(&written).unwrap();
    assert_eq!(back.name, "gyrowheel-2017");
}

/// Issue 19 §2: a run killed between moving the previous report aside and moving the new one
/// in left `out` missing, the previous report in `.out.old-*` and the new one in `.out.tmp-*`
/// (constructed here). The next run restores and then replaces the report: `out` is a complete
/// report, no leftover remains. (Before: `out` stayed missing until a rerun, and both hidden
/// directories stayed forever.)
#[test]
fn a_run_killed_between_the_renames_is_recovered_by_the_next() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let listed = ["report.md", "results.json"];
    fake_report(&dir.path().join(".out.old-4242-0"), &listed, &listed);
    fake_report(&dir.path().join(".out.tmp-4242-0"), &listed, &listed);
    let o = paper_into(&out);
    ok(&o);
    assert!(
        stdout(&o).contains("recovered the previous report"),
        "{}",
        stdout(&o)
    );
    assert_new_report(&out);
    assert_eq!(names(dir.path()), ["out"], "no leftover");
}

/// Issue 19 §2: leftovers of our own killed runs (a half-written `.out.tmp-*` with our manifest,
/// an empty one) are removed by the next run; look-alikes that are not ours (no manifest, a
/// manifest naming `../victim.txt`) are left alone and said so, and the victim survives.
#[test]
fn leftovers_of_killed_runs_are_removed_and_look_alikes_left_alone() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let p = dir.path();
    fake_report(&out, &["report.md"], &["report.md"]);
    fake_report(
        &p.join(".out.tmp-77-0"),
        &["report.md", "results.json"],
        &["report.md"],
    );
    std::fs::create_dir(p.join(".out.tmp-78-1")).unwrap();
    std::fs::create_dir(p.join(".out.old-79-0")).unwrap();
    write(&p.join(".out.old-79-0"), "notes.txt", "mine");
    let victim = write(p, "victim.txt", "keep me");
    fake_report(
        &p.join(".out.tmp-80-0"),
        &["report.md", "../victim.txt"],
        &["report.md"],
    );
    let o = paper_into(&out);
    ok(&o);
    let text = stdout(&o);
    assert!(
        text.contains(".out.old-79-0") && text.contains("left"),
        "{text}"
    );
    assert_new_report(&out);
    assert_eq!(
        names(p),
        [".out.old-79-0", ".out.tmp-80-0", "out", "victim.txt"]
    );
    assert_eq!(
        std::fs::read_to_string(p.join(".out.old-79-0/notes.txt")).unwrap(),
        "mine"
    );
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "keep me");
}

/// Issue 19 §2: where a previous report had `report.md`, the user made a directory (with notes)
/// or a link: the run is refused with exit 2 naming it, before anything moves (no `.out.old-*`,
/// the notes where they were). (Before: exit 1, and the notes moved into `.out.old-*`.)
#[test]
fn a_user_entry_where_a_report_file_was_is_refused_before_anything_moves() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    fake_report(&out, &["report.md", "results.json"], &["results.json"]);
    std::fs::create_dir(out.join("report.md")).unwrap();
    write(&out.join("report.md"), "notes.txt", "mine");
    let o = paper_into(&out);
    assert_input_error(&o, &[out.to_str().unwrap(), "report.md"]);
    assert_eq!(
        std::fs::read_to_string(out.join("report.md/notes.txt")).unwrap(),
        "mine"
    );
    assert_eq!(names(dir.path()), ["out"]);

    std::fs::remove_dir_all(out.join("report.md")).unwrap();
    let target = write(dir.path(), "target.txt", "mine");
    std::os::unix::fs::symlink(&target, out.join("report.md")).unwrap();
    let o = paper_into(&out);
    assert_input_error(&o, &[out.to_str().unwrap(), "report.md"]);
    assert_eq!(std::fs::read_to_string(&target).unwrap(), "mine");
    assert!(
        std::fs::symlink_metadata(out.join("report.md"))
            .unwrap()
            .file_type()
            .is_symlink()
    );
    assert_eq!(names(dir.path()), ["out", "target.txt"]);
}

/// The octal permission bits of `p`.
fn mode(p: &Path) -> u32 {
    use std::os::unix::fs::PermissionsExt;
    std::fs::metadata(p).unwrap().permissions().mode() & 0o777
}

/// Issue 19 §2: `--write-study` creates the file like any other program: `0666` less the umask
/// (before: always 0600).
#[test]
fn write_study_respects_the_umask() {
    let dir = tempfile::tempdir().unwrap();
    for (umask, expected) in [("022", 0o644), ("027", 0o640)] {
        let written = dir.path().join(format!("designed-{umask}.toml"));
        let o = Command::new("sh")
            .arg("-c")
            .arg(format!("umask {umask}; exec \"$0\" \"$@\""))
            .arg(env!("CARGO_BIN_EXE_ttalloc"))
            .args(["design-schedule", "--write-study"])
            .arg(&written)
            .current_dir(root())
            .output()
            .unwrap();
        ok(&o);
        assert_eq!(mode(&written), expected, "umask {umask}");
    }
    let left = hidden_names(dir.path());
    assert!(left.is_empty(), "no temporary file left: {left:?}");
}

/// Issue 19 §3: `--out` with a 245-character final component (temporary names once appended
/// `.tmp-PID-NANOS` to it: exit 1, file name too long) is written and replaced like any other;
/// its temporary names stay short.
#[test]
fn a_245_character_out_name_is_written_and_replaced() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r".repeat(245));
    for _ in 0..2 {
        ok(&paper_into(&out));
        assert_new_report(&out);
    }
    assert_eq!(names(dir.path()), ["r".repeat(245)], "no leftover");
}

/// Issue 19 §4: places where nothing can be created (`/sys` refuses new files even to root)
/// are refused before the work with exit 2 naming the directory: `--write-study` (before:
/// exit 1 after the whole search) and the report's lock (before: exit 1).
#[test]
fn unwritable_output_places_exit_2_naming_the_path_before_the_work() {
    let o = run(&[
        "design-schedule",
        "--write-study",
        "/sys/xtask-designed.toml",
    ]);
    assert_input_error(&o, &["/sys", "--write-study", "cannot create a file"]);
    let o = run(&[
        "report",
        "--study",
        "studies/gyrowheel-2017.toml",
        "--out",
        "/sys/xtask-report",
    ]);
    assert_input_error(
        &o,
        &["/sys", "cannot write in the output's parent directory"],
    );
    let o = run(&["reproduce-paper", "--out", "/sys/xtask/deeper"]);
    assert_input_error(
        &o,
        &["/sys/xtask", "cannot create the output's parent directory"],
    );
}

/// Issue 19 §7: a symbolic link to a directory as `--out` is followed (the report goes into
/// the directory it names; the link stays); a link to a file or a dangling link is refused
/// saying what it is; a link to a directory of someone else's files is refused as that
/// directory would be. (Before: "exists and is not a directory" for a link to a directory.)
#[test]
fn a_symbolic_link_to_a_directory_as_out_is_followed_and_others_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path();
    let real = p.join("real");
    std::fs::create_dir(&real).unwrap();
    let link = p.join("link");
    std::os::unix::fs::symlink(&real, &link).unwrap();
    for _ in 0..2 {
        let o = paper_into(&link);
        ok(&o);
        assert!(stdout(&o).contains("a link to"), "{}", stdout(&o));
        assert!(
            std::fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(std::fs::read_link(&link).unwrap(), real);
        assert_new_report(&real);
    }
    assert_eq!(names(p), ["link", "real"], "no leftover");

    let file = write(p, "file.txt", "mine");
    let to_file = p.join("to-file");
    std::os::unix::fs::symlink(&file, &to_file).unwrap();
    assert_input_error(
        &paper_into(&to_file),
        &[
            to_file.to_str().unwrap(),
            "symbolic link",
            "not a directory",
        ],
    );
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "mine");

    let dangling = p.join("dangling");
    std::os::unix::fs::symlink(p.join("nowhere"), &dangling).unwrap();
    assert_input_error(
        &paper_into(&dangling),
        &[
            dangling.to_str().unwrap(),
            "symbolic link",
            "cannot be followed",
        ],
    );
    assert!(!p.join("nowhere").exists());

    let foreign: PathBuf = p.join("foreign");
    std::fs::create_dir(&foreign).unwrap();
    write(&foreign, "notes.txt", "mine");
    let to_foreign = p.join("to-foreign");
    std::os::unix::fs::symlink(&foreign, &to_foreign).unwrap();
    assert_input_error(&paper_into(&to_foreign), &["notes.txt"]);
    assert_eq!(names(&foreign), ["notes.txt"]);
}
