//! Memory does not grow with the input (issue 15 defects 3 and 6): the peak resident memory
//! of a command, read from `/proc/<pid>/status` (`VmHWM`, Linux) while it runs.

mod common;

use std::io::Write;
use std::path::Path;
use std::process::Command;

/// Peak resident set of the command in KiB ([`testkit::peak_kib`]), with `stdin` fed from a
/// file; stdout discarded. Panics unless the command succeeds.
fn peak_kib(args: &[&str], stdin: Option<&std::path::Path>) -> u64 {
    let mut c = Command::new(env!("CARGO_BIN_EXE_ttalloc"));
    c.args(args).current_dir(common::root());
    if let Some(p) = stdin {
        c.stdin(std::fs::File::open(p).unwrap());
    }
    testkit::peak_kib(c, &format!("{args:?}"))
}

/// A 65 MB turntable CSV goes through `orientation-error` (as a file and on standard input)
/// with a peak memory far below the input's size (before: 327 MB for 210 MB).
#[test]
fn orientation_error_memory_does_not_grow_with_the_input() {
    let header = "phi1_deg,phi2_deg,dphi_y1_arcmin,dphi_z2_arcmin,dalpha_x1_arcmin,dalpha_z1_arcmin,dalpha_x2_arcmin,dalpha_y2_arcmin,deps_x_arcmin,deps_y_arcmin,deta_mm";
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("big.csv");
    let mut f = std::io::BufWriter::new(std::fs::File::create(&path).unwrap());
    writeln!(f, "{header}").unwrap();
    for i in 0..1_300_000 {
        writeln!(
            f,
            "{},{},0.4,0.78,0.42,0.78,0.28,0.28,0.42,0.42,0.1",
            i % 360,
            (i * 7) % 360
        )
        .unwrap();
    }
    drop(f);
    let size_kib = std::fs::metadata(&path).unwrap().len() / 1024;
    assert!(size_kib > 50_000);
    let file = peak_kib(&["orientation-error", path.to_str().unwrap()], None);
    let stdin = peak_kib(&["orientation-error", "-"], Some(&path));
    for (what, peak) in [("file", file), ("stdin", stdin)] {
        assert!(
            peak < size_kib / 2,
            "{what}: peak {peak} KiB for {size_kib} KiB of input"
        );
    }
}

/// The end-to-end Monte Carlo streams its statistics: 100 times more turntables take no more
/// memory (before: 167 MB for 10^6 draws, an abort for 10^17).
#[test]
fn end_to_end_memory_does_not_grow_with_the_sample_count() {
    let small = peak_kib(&["end-to-end", "--samples", "2e3"], None);
    let large = peak_kib(&["end-to-end", "--samples", "2e5"], None);
    assert!(
        large < small + 8 * 1024,
        "2e3 draws: {small} KiB, 2e5 draws: {large} KiB"
    );
}

/// `allan` streams its log: 15 times more samples (3e6 lines, 24 MB as doubles) take no more
/// memory, from a file or from standard input, on the octave grid or with every cluster time
/// of the `all` grid (four deviations each).
#[test]
fn allan_memory_does_not_grow_with_the_log_length() {
    let dir = tempfile::tempdir().unwrap();
    let log = |name: &str, n: u64| {
        let path = dir.path().join(name);
        let mut f = std::io::BufWriter::new(std::fs::File::create(&path).unwrap());
        writeln!(f, "gz").unwrap();
        let mut x: u64 = 1;
        for _ in 0..n {
            x = x.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
            writeln!(f, "{}", (x >> 44) as f64 * 1e-6).unwrap();
        }
        drop(f);
        path
    };
    let small = log("small.csv", 200_000);
    let large = log("large.csv", 3_000_000);
    let args = |p: &std::path::Path| {
        vec![
            "allan".to_string(),
            p.to_str().unwrap().to_string(),
            "--rate-hz".into(),
            "100".into(),
        ]
    };
    let run = |a: &[String], stdin: Option<&std::path::Path>| {
        peak_kib(&a.iter().map(String::as_str).collect::<Vec<_>>(), stdin)
    };
    let s = run(&args(&small), None);
    let l = run(&args(&large), None);
    let l_stdin = run(
        &["allan".into(), "--rate-hz".into(), "100".into()],
        Some(&large),
    );
    // every cluster time of the `all` grid, four deviations each
    let all = |p: &std::path::Path| [args(p), vec!["--taus".into(), "all".into()]].concat();
    let s_all = run(&all(&small), None);
    let l_all = run(&all(&large), None);
    for (what, base, peak) in [
        ("file", s, l),
        ("stdin", s, l_stdin),
        ("--taus all", s_all, l_all),
    ] {
        assert!(
            peak < base + 8 * 1024,
            "{what}: 2e5 samples {base} KiB, 3e6 samples {peak} KiB"
        );
    }
}

/// The paper's study with `n` test positions on a grid of its two shafts (about the square
/// root of `n` angles each), written to `dir`.
fn grid_study(dir: &Path, n: usize) -> std::path::PathBuf {
    let a = (n as f64).sqrt() as usize;
    let b = n.div_ceil(a);
    let positions: Vec<String> = (0..n)
        .map(|k| {
            let (i, j) = (k / b, k % b);
            format!(
                "[{}, {}]",
                360.0 * i as f64 / a as f64,
                360.0 * j as f64 / b as f64
            )
        })
        .collect();
    let text = common::paper_study_with_positions(&positions);
    common::write(dir, &format!("grid-{n}.toml"), &text)
}

/// Memory grows linearly with the test positions, never with their square (issue 32:
/// `estimable` peaked at 38 MB for 1,000 positions, 177 MB for 3,000 and 1.66 GB for 10,000:
/// the n x n projector of the second-order bound and |A| |A^+| of the precisions). Four
/// times the positions take less than five times the memory (the square would take sixteen
/// times the part that grows).
#[test]
fn memory_grows_linearly_with_the_test_positions() {
    let dir = tempfile::tempdir().unwrap();
    let (small, large) = (grid_study(dir.path(), 1000), grid_study(dir.path(), 4000));
    for cmd in ["estimable", "requirement"] {
        let s = peak_kib(&[cmd, "--study", small.to_str().unwrap()], None);
        let l = peak_kib(&[cmd, "--study", large.to_str().unwrap()], None);
        assert!(
            l < 5 * s,
            "{cmd}: 1,000 positions {s} KiB, 4,000 positions {l} KiB"
        );
    }
}
