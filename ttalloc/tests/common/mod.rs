//! Running the built `xtask` binary from the workspace root, and scratch files.
#![allow(dead_code)]

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

/// The workspace root (where `studies/` lives).
pub(crate) fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Run `cargo xtask <args>` (the built binary) in the workspace root with `stdin`.
pub(crate) fn run_with_stdin(args: &[&str], stdin: &[u8]) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_ttalloc"))
        .args(args)
        .current_dir(root())
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("xtask runs");
    let mut input = child.stdin.take().expect("stdin");
    let data = stdin.to_vec();
    let writer = std::thread::spawn(move || {
        // the command may stop reading early (an error): a broken pipe here is fine
        let _ = input.write_all(&data);
    });
    let out = child.wait_with_output().expect("xtask finishes");
    writer.join().expect("stdin writer");
    out
}

/// Run `cargo xtask <args>` with empty standard input.
pub(crate) fn run(args: &[&str]) -> Output {
    run_with_stdin(args, b"")
}

/// Standard output as text.
pub(crate) fn stdout(o: &Output) -> String {
    String::from_utf8(o.stdout.clone()).expect("UTF-8 stdout")
}

/// Standard error as text.
pub(crate) fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Assert success and parse standard output as JSON.
pub(crate) fn json(args: &[&str]) -> serde_json::Value {
    let o = run(args);
    assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    serde_json::from_slice(&o.stdout).expect("JSON on stdout")
}

/// Assert success (else show the exit code and standard error) and parse standard output as
/// JSON.
pub(crate) fn json_of(out: &Output) -> serde_json::Value {
    assert!(
        out.status.success(),
        "exit {:?}: {}",
        out.status.code(),
        stderr(out)
    );
    serde_json::from_slice(&out.stdout).expect("JSON on standard output")
}

/// Assert exit code 2, nothing on standard output, and a message containing every `needle`.
pub(crate) fn assert_input_error(o: &Output, needles: &[&str]) {
    assert_input_error_of("", o, needles);
}

/// [`assert_input_error`] for one `case` of a table (named in every message).
pub(crate) fn assert_input_error_of(case: &str, o: &Output, needles: &[&str]) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(2), "{case} exit code; stderr: {err}");
    assert!(
        o.stdout.is_empty(),
        "{case} stdout must be empty, got {}",
        stdout(o)
    );
    for n in needles {
        assert!(err.contains(n), "{case} stderr lacks `{n}`: {err}");
    }
    assert!(!err.contains("panicked"), "{case} {err}");
}

/// Assert that `prefix` followed by each `[flag, value]` of `cases` exits 2 naming the flag
/// (each message names the case).
pub(crate) fn assert_flags_refused(prefix: &[&str], cases: &[[&str; 2]]) {
    for case in cases {
        let mut args = prefix.to_vec();
        args.extend_from_slice(case);
        assert_input_error_of(&format!("{case:?}"), &run(&args), &[case[0]]);
    }
}

/// A shipped study's path relative to the workspace root.
pub(crate) fn study(name: &str) -> String {
    format!("studies/{name}.toml")
}

/// The text of a shipped study.
pub(crate) fn study_text(name: &str) -> String {
    std::fs::read_to_string(root().join(study(name))).expect("study file")
}

/// The paper's study with its test positions replaced by `positions` (each `[phi1, phi2]`,
/// deg, as written in the file).
pub(crate) fn paper_study_with_positions(positions: &[String]) -> String {
    let text = study_text("gyrowheel-2017");
    let start = text.find("positions_deg = [").unwrap();
    let end = start + text[start..].find("\n]\n").unwrap() + 3;
    format!(
        "{}positions_deg = [{}]\n{}",
        &text[..start],
        positions.join(","),
        &text[end..]
    )
}

/// Write `text` to `dir/name` and return its path.
pub(crate) fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).expect("write scratch file");
    p
}

/// A number of a JSON value.
pub(crate) fn num(v: &serde_json::Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

/// A fresh directory `<prefix>-<name>` under the target's scratch directory (never the source
/// tree), emptied first if a previous run left it.
pub(crate) fn scratch(prefix: &str, name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("{prefix}-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch directory");
    dir
}

/// `cmd.output()` for a binary this test just copied: a freshly written executable can be
/// "busy" (ETXTBSY) for a moment, because another test thread may have forked a child that
/// still held the copy's write descriptor until its own exec. That is the test harness's race,
/// not the program's, so the start is retried a few times.
pub(crate) fn output_of_fresh_copy(cmd: &mut Command) -> Output {
    let mut tries = 0;
    loop {
        match cmd.output() {
            Err(e) if e.kind() == std::io::ErrorKind::ExecutableFileBusy && tries < 50 => {
                tries += 1;
                std::thread::sleep(std::time::Duration::from_millis(20));
            }
            r => return r.expect("the copied binary runs"),
        }
    }
}

/// Assert success, showing the exit code and both outputs otherwise.
pub(crate) fn ok(o: &Output) {
    assert!(
        o.status.success(),
        "exit {:?}\nstderr: {}\nstdout: {}",
        o.status.code(),
        stderr(o),
        String::from_utf8_lossy(&o.stdout)
    );
}

/// The SHA-256 of `bytes` in lowercase hex (a report manifest line's first field).
pub(crate) fn sha256_hex(bytes: &[u8]) -> String {
    use sha2::Digest;
    sha2::Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// The names in `dir`, sorted.
pub(crate) fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// The names in `dir` that start with a dot (a temporary, old or lock file left behind),
/// sorted.
pub(crate) fn hidden_names(dir: &Path) -> Vec<String> {
    names(dir)
        .into_iter()
        .filter(|n| n.starts_with('.'))
        .collect()
}

/// A paper report into `out` (1500 samples: few, fast).
pub(crate) fn paper_into(out: &Path) -> Output {
    run(&[
        "reproduce-paper",
        "--out",
        out.to_str().unwrap(),
        "--samples",
        "1500",
    ])
}

/// calib-run's six-face and three-rotation study (an absolute path).
pub(crate) fn six_face_study() -> String {
    format!(
        "{}/../calib-run/studies/imu-six-face-three-rotation.toml",
        env!("CARGO_MANIFEST_DIR")
    )
}

/// A recording of [`six_face_study`] simulated with its own coefficients (50 Hz, 10 s dwells,
/// seed 4), written to `dir/run.csv`.
pub(crate) fn six_face_recording(dir: &Path) -> PathBuf {
    let path = six_face_study();
    let s =
        study::Study::parse(&path, &std::fs::read_to_string(&path).expect("study")).expect("valid");
    let settings = calib_run::simulate::SimSettings::for_study(&s, 50.0, 10.0, 4);
    let mut buf = Vec::new();
    calib_run::simulate::simulate_recording(&s, &s.sensor, &settings, &mut buf).expect("simulated");
    let out = dir.join("run.csv");
    std::fs::write(&out, buf).expect("written");
    out
}

/// [`six_face_recording`] with the `gx` cell of line 20 made `oops<number>`, written to
/// `dir/bad.csv` (the good recording stays as `dir/run.csv`).
pub(crate) fn six_face_recording_with_a_bad_cell(dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(six_face_recording(dir)).expect("the recording");
    let bad: String = text
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i == 19 {
                let (t, rest) = l.split_once(',').expect("cells");
                format!("{t},oops{rest}\n")
            } else {
                format!("{l}\n")
            }
        })
        .collect();
    write(dir, "bad.csv", &bad)
}

/// What the library answers for a study and a tolerance sheet (paths from the workspace root),
/// the inputs `check-turntable --study STUDY --tolerances SHEET` reads: the study, the sheet,
/// the end-to-end model of the study's schedule and the GUM verdict of every specification
/// (the study's tolerance law, noise and timing).
pub(crate) struct LibraryPlan {
    /// The study.
    pub study: study::Study,
    /// The sheet, read for the study's turntable.
    pub tolerances: study::Tolerances,
    /// The end-to-end model of the study's schedule and reading.
    pub e2e: e2e_verify::EndToEnd,
    /// Every specification's GUM budget over the sheet.
    pub verdict: e2e_verify::budget::PlanVerdict,
}

/// [`LibraryPlan`] of the study file at `study` and the sheet `sheet`.
pub(crate) fn library_plan(study: &Path, sheet: &str) -> LibraryPlan {
    let s = study::Study::load(&root().join(study)).expect("the study");
    let tolerances = study::Tolerances::load(&root().join(sheet), &s.turntable).expect("sheet");
    let poses: Vec<tt_kinematics::Pose> = s
        .positions_deg
        .iter()
        .map(|p| tt_kinematics::Pose::from_deg(p).expect("a pose"))
        .collect();
    let e2e = e2e_verify::EndToEnd::new(&s.turntable, &s.calibration, &poses, s.reading)
        .expect("the model");
    let law = s.uncertainty.tolerance_distribution;
    let verdict = e2e
        .budget()
        .plan_verdict(
            &s.specifications,
            &tolerances.ub_rad,
            |n, a| law.input(n, a),
            &s.noise,
            s.timing.as_ref(),
        )
        .expect("the verdict");
    LibraryPlan {
        study: s,
        tolerances,
        e2e,
        verdict,
    }
}

/// A command line: `cmd`, then each flag and its value, then `extra`.
pub(crate) fn command_line<'a>(
    cmd: &'a str,
    flags: &[(&'a str, &'a str)],
    extra: &[&'a str],
) -> Vec<&'a str> {
    let mut a = vec![cmd];
    for (flag, value) in flags {
        a.extend([*flag, *value]);
    }
    a.extend_from_slice(extra);
    a
}

/// `end-to-end --study STUDY --samples SAMPLES`, then `extra` and `--json`: asserts success and
/// parses standard output.
pub(crate) fn end_to_end_json(study: &str, samples: &str, extra: &[&str]) -> serde_json::Value {
    let tail = [extra, &["--json"]].concat();
    json(&command_line(
        "end-to-end",
        &[("--study", study), ("--samples", samples)],
        &tail,
    ))
}

/// The arguments of `check-turntable --study STUDY --tolerances SHEET --samples SAMPLES`
/// followed by `extra`.
pub(crate) fn check_turntable<'a>(
    study: &'a str,
    sheet: &'a str,
    samples: &'a str,
    extra: &[&'a str],
) -> Vec<&'a str> {
    let flags = [
        ("--study", study),
        ("--tolerances", sheet),
        ("--samples", samples),
    ];
    command_line("check-turntable", &flags, extra)
}

/// The arguments of `report --study STUDY --out OUT --samples SAMPLES` followed by `extra`.
pub(crate) fn report_args<'a>(
    study: &'a str,
    out: &'a Path,
    samples: &'a str,
    extra: &[&'a str],
) -> Vec<&'a str> {
    let out = out.to_str().expect("a UTF-8 path");
    let flags = [("--study", study), ("--out", out), ("--samples", samples)];
    command_line("report", &flags, extra)
}
