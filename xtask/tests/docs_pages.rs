//! The pages are tested (issue 33 §6): README.md and every `docs/**/*.md` page.
//!
//! - Every ` ```sh ` block runs: each `cargo xtask <command>` / `ttalloc <command>` line goes
//!   through the built binary from the repository root, with every file it would write
//!   (`--out`, `--write-*`, `--figure`, `--pareto-svg`, `--findings`, and the default report
//!   directories) redirected into a fresh temporary directory, and must exit 0; a
//!   ` ```text output ` block right after it is output the page quotes, each of its lines
//!   (`...` elides) found in the block's standard output.
//! - A ` ```sh manual ` block (too slow for the suite, recursive, or needing the user's own
//!   files; the page says why) still parses: its subcommands exist and take every long flag
//!   it names; a `cargo run`/`cargo bench` line's example or bench exists.
//! - Every relative link resolves to an existing file, and to a heading where it names one.
//! - Every page with a ` ```rust ` block is included as a doctest by some library crate
//!   (`#[doc = include_str!(...)]` under `#[cfg(doctest)]`).
//!
//! Self-contained (no `common` module): the command-line tests around it are moving.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

/// The workspace root (where README.md and docs/ live).
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("xtask sits in the workspace root")
        .to_path_buf()
}

/// README.md and every Markdown page under docs/, sorted, relative to the root.
fn pages() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(dir).expect("docs/ is readable") {
            let p = e.expect("a directory entry").path();
            if p.is_dir() {
                walk(&p, out);
            } else if p.extension().is_some_and(|x| x == "md") {
                out.push(p);
            }
        }
    }
    let mut out = vec![root().join("README.md")];
    walk(&root().join("docs"), &mut out);
    out.sort();
    out.into_iter()
        .map(|p| {
            p.strip_prefix(root())
                .expect("under the root")
                .to_path_buf()
        })
        .collect()
}

fn read(page: &Path) -> String {
    std::fs::read_to_string(root().join(page)).unwrap_or_else(|e| panic!("{page:?}: {e}"))
}

/// A fenced code block of a page.
struct Block {
    page: PathBuf,
    /// 1-based line of the opening fence.
    line: usize,
    info: String,
    body: Vec<String>,
    /// The ` ```text output ` block that follows it, if any.
    quoted: Option<Vec<String>>,
}

/// Every fenced block of a page, in order; a ` ```text output ` block is attached to the
/// block before it (only blank lines between) and not listed on its own.
fn blocks(page: &Path) -> Vec<Block> {
    let text = read(page);
    let mut out: Vec<Block> = Vec::new();
    let mut open: Option<Block> = None;
    let mut last_close: Option<usize> = None;
    let mut blank_since_close = true;
    for (i, l) in text.lines().enumerate() {
        let t = l.trim_start();
        if let Some(b) = open.as_mut() {
            if t.starts_with("```") && t.trim() == "```" {
                let b = open.take().expect("open");
                let follows = last_close.is_some() && blank_since_close;
                if b.info == "text output" {
                    let prev = out.last_mut().filter(|_| follows).unwrap_or_else(|| {
                        panic!(
                            "{:?}:{}: a `text output` block follows no block",
                            b.page, b.line
                        )
                    });
                    prev.quoted = Some(b.body);
                } else {
                    out.push(b);
                }
                last_close = Some(i);
                blank_since_close = true;
            } else {
                b.body.push(l.to_string());
            }
        } else if let Some(info) = t.strip_prefix("```") {
            open = Some(Block {
                page: page.to_path_buf(),
                line: i + 1,
                info: info.trim().to_string(),
                body: Vec::new(),
                quoted: None,
            });
        } else if !t.is_empty() {
            blank_since_close = false;
        }
    }
    assert!(open.is_none(), "{page:?}: an unclosed code fence");
    out
}

/// Shell words of a line: whitespace-separated, with '...' and "..." quoting; a `#` that
/// starts a word starts a comment.
fn words(line: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut cur = String::new();
    let mut in_word = false;
    let mut quote: Option<char> = None;
    for c in line.chars() {
        match quote {
            Some(q) if c == q => quote = None,
            Some(_) => cur.push(c),
            None if c == '\'' || c == '"' => {
                quote = Some(c);
                in_word = true;
            }
            None if c.is_whitespace() => {
                if in_word {
                    out.push(std::mem::take(&mut cur));
                    in_word = false;
                }
            }
            None if c == '#' && !in_word => break,
            None => {
                cur.push(c);
                in_word = true;
            }
        }
    }
    assert!(quote.is_none(), "unclosed quote in `{line}`");
    if in_word {
        out.push(cur);
    }
    out
}

/// The command lines of a block: continuation lines (`\`) joined, comments and blank lines
/// dropped, each split into words.
fn lines(block: &Block) -> Vec<(String, Vec<String>)> {
    let mut out = Vec::new();
    let mut acc = String::new();
    for l in &block.body {
        if let Some(head) = l.trim_end().strip_suffix('\\') {
            acc.push_str(head);
            acc.push(' ');
            continue;
        }
        acc.push_str(l);
        let w = words(&acc);
        if !w.is_empty() {
            out.push((acc.trim().to_string(), w));
        }
        acc.clear();
    }
    out
}

/// The arguments after `cargo xtask` or `ttalloc` (anywhere in the line, so that
/// `/usr/bin/time -v cargo xtask ...` counts), or None for any other program.
fn ttalloc_args(w: &[String]) -> Option<Vec<String>> {
    if let Some(i) = w
        .windows(2)
        .position(|p| p[0] == "cargo" && p[1] == "xtask")
    {
        return Some(w[i + 2..].to_vec());
    }
    let i = w.iter().position(|x| x == "ttalloc")?;
    // `cargo install --path ttalloc` names the crate, not the program
    (i == 0 || !w[..i].iter().any(|x| x == "cargo")).then(|| w[i + 1..].to_vec())
}

/// Run the built binary (`cargo xtask`) with `args` from the workspace root.
fn run(args: &[String]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_xtask"))
        .args(args)
        .current_dir(root())
        .stdin(Stdio::null())
        .output()
        .expect("xtask runs")
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// The subcommands `cargo xtask --help` lists.
fn subcommands() -> BTreeSet<String> {
    let help = stdout(&run(&["--help".to_string()]));
    help.lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next().map(String::from))
        .filter(|c| c != "help")
        .collect()
}

/// The long flags a subcommand's `--help` names.
fn flags_of(cmd: &str) -> BTreeSet<String> {
    let help = stdout(&run(&[cmd.to_string(), "--help".to_string()]));
    help.split_whitespace()
        .filter(|w| w.starts_with("--") && w.len() > 2)
        .map(|w| {
            w.trim_end_matches([',', '.', ')', '`', ';'])
                .split(['=', '<', '['])
                .next()
                .unwrap_or("")
                .to_string()
        })
        .collect()
}

/// The long flags of a command line (`--flag` or `--flag=value`).
fn flags_in(args: &[String]) -> Vec<String> {
    args.iter()
        .filter(|a| a.starts_with("--") && a.len() > 2)
        .map(|a| a.split('=').next().unwrap_or("").to_string())
        .collect()
}

/// Flags whose value is a file or directory the command writes.
const WRITE_FLAGS: [&str; 7] = [
    "--out",
    "--write-study",
    "--write-noise",
    "--figure",
    "--pareto-svg",
    "--findings",
    "--write-csv",
];

/// `args` with every written path moved into `dir` (its file name kept) and recorded in
/// `written`, every argument naming a path written earlier in the block read from where it
/// went, and `--out DIR` added to the commands that write a report by default.
fn redirected(
    args: &[String],
    dir: &Path,
    written: &mut std::collections::BTreeMap<String, String>,
) -> Vec<String> {
    let into = |v: &str, written: &mut std::collections::BTreeMap<String, String>| {
        let name = Path::new(v)
            .file_name()
            .map_or_else(|| "out".into(), |n| n.to_string_lossy().into_owned());
        let to = dir.join(name).to_string_lossy().into_owned();
        written.insert(v.to_string(), to.clone());
        to
    };
    let mut out = Vec::new();
    let mut it = args.iter();
    let mut has_out = false;
    while let Some(a) = it.next() {
        let split = a.split_once('=').filter(|(f, _)| WRITE_FLAGS.contains(f));
        if let Some((flag, value)) = split {
            has_out |= flag == "--out";
            out.push(format!("{flag}={}", into(value, written)));
        } else if WRITE_FLAGS.contains(&a.as_str()) {
            has_out |= a == "--out";
            out.push(a.clone());
            let v = it.next().unwrap_or_else(|| panic!("{a} without a value"));
            out.push(into(v, written));
        } else {
            out.push(written.get(a).cloned().unwrap_or_else(|| a.clone()));
        }
    }
    if !has_out
        && matches!(
            args.first().map(String::as_str),
            Some("report" | "reproduce-paper")
        )
    {
        out.push("--out".into());
        out.push(dir.join("report").to_string_lossy().into_owned());
    }
    out
}

/// Every runnable ` ```sh ` block of every page runs with exit 0 and prints what the page
/// quotes; a runnable block holds only `cargo xtask` / `ttalloc` lines.
#[test]
fn every_sh_block_of_the_pages_runs_with_exit_0_and_prints_what_the_page_quotes() {
    let mut ran = 0;
    for page in pages() {
        for b in blocks(&page).into_iter().filter(|b| b.info == "sh") {
            let mut printed = String::new();
            // one directory per block: a later line reads what an earlier one wrote
            let dir = tempfile::tempdir().expect("a temporary directory");
            let mut written = std::collections::BTreeMap::new();
            for (line, w) in lines(&b) {
                let args = ttalloc_args(&w).unwrap_or_else(|| {
                    panic!(
                        "{:?}:{}: `{line}` is not a cargo xtask / ttalloc command: put it in a ```sh manual block",
                        b.page, b.line
                    )
                });
                assert!(
                    !w.iter()
                        .any(|x| ["|", ">", "<", ";", "&&", "||"].contains(&x.as_str())),
                    "{:?}:{}: `{line}`: no shell plumbing in a runnable block",
                    b.page,
                    b.line
                );
                assert_ne!(
                    args.first().map(String::as_str),
                    Some("test"),
                    "{:?}:{}: `cargo xtask test` is the whole suite: a ```sh manual block",
                    b.page,
                    b.line
                );
                let o = run(&redirected(&args, dir.path(), &mut written));
                assert_eq!(
                    o.status.code(),
                    Some(0),
                    "{:?}:{}: `{line}` failed:\n{}",
                    b.page,
                    b.line,
                    String::from_utf8_lossy(&o.stderr)
                );
                printed.push_str(&stdout(&o));
                ran += 1;
            }
            for q in b.quoted.iter().flatten() {
                let q = q.trim();
                if q.is_empty() || q == "..." {
                    continue;
                }
                assert!(
                    printed.contains(q),
                    "{:?}:{}: the output lacks the quoted line `{q}`:\n{printed}",
                    b.page,
                    b.line
                );
            }
        }
    }
    assert!(
        ran >= 10,
        "only {ran} commands ran: the pages lost their examples"
    );
}

/// A ` ```sh manual ` block still names commands that exist, with flags they take, and
/// examples and benches that exist; a shell block has no other info string.
#[test]
fn every_manual_sh_block_names_existing_commands_flags_examples_and_benches() {
    let commands = subcommands();
    assert!(commands.len() >= 10, "{commands:?}");
    let mut checked = 0;
    for page in pages() {
        for b in blocks(&page) {
            assert!(
                !b.info.starts_with("sh") || b.info == "sh" || b.info == "sh manual",
                "{:?}:{}: a shell block is ```sh or ```sh manual, not ```{}",
                b.page,
                b.line,
                b.info
            );
            if b.info != "sh manual" {
                continue;
            }
            for (line, w) in lines(&b) {
                if let Some(args) = ttalloc_args(&w) {
                    let cmd = args.first().cloned().unwrap_or_default();
                    if cmd == "test" {
                        checked += 1;
                        continue; // xtask's own: its arguments go to cargo test
                    }
                    assert!(
                        commands.contains(&cmd),
                        "{:?}:{}: `{line}`: no command `{cmd}`",
                        b.page,
                        b.line
                    );
                    let known = flags_of(&cmd);
                    for f in flags_in(&args[1..]) {
                        assert!(
                            known.contains(&f),
                            "{:?}:{}: `{line}`: `{cmd}` takes no `{f}`",
                            b.page,
                            b.line
                        );
                    }
                    checked += 1;
                } else if w.first().is_some_and(|c| c == "cargo") {
                    let after = |flag: &str| {
                        w.iter()
                            .position(|x| x == flag)
                            .and_then(|i| w.get(i + 1))
                            .cloned()
                    };
                    let krate = after("-p").or_else(|| after("--package"));
                    for (flag, sub) in [("--example", "examples"), ("--bench", "benches")] {
                        if let Some(name) = after(flag) {
                            let k = krate.clone().unwrap_or_else(|| {
                                panic!("{:?}:{}: `{line}` without -p", b.page, b.line)
                            });
                            let dir = if root().join(&k).is_dir() {
                                root().join(&k)
                            } else {
                                root().join("examples").join(&k)
                            };
                            let file = dir.join(sub).join(format!("{name}.rs"));
                            assert!(
                                file.is_file() || dir.join(sub).join(&name).is_dir(),
                                "{:?}:{}: `{line}`: no {file:?}",
                                b.page,
                                b.line
                            );
                        }
                    }
                    checked += 1;
                }
            }
        }
    }
    assert!(checked >= 5, "only {checked} manual lines checked");
}

/// Every subcommand has a row in the commands table of docs/commands.md naming every long flag
/// of its `--help` (moved here with the table from the README).
#[test]
fn commands_page_table_lists_every_command_and_flag() {
    let page = read(Path::new("docs/commands.md"));
    let commands = subcommands();
    assert!(commands.len() >= 10, "{commands:?}");
    for c in commands {
        let row = page
            .lines()
            .find(|l| l.starts_with(&format!("| `cargo xtask {c}")))
            .unwrap_or_else(|| panic!("docs/commands.md has no commands-table row for `{c}`"));
        for flag in flags_of(&c)
            .into_iter()
            .filter(|f| f != "--help" && f.len() > 2)
        {
            assert!(
                row.contains(&flag),
                "docs/commands.md row for `{c}` lacks `{flag}`: {row}"
            );
        }
    }
}

/// GitHub's anchor of a heading: lower case, punctuation dropped, spaces to `-`.
fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || *c == ' ' || *c == '-' || *c == '_')
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

/// The anchors of a Markdown file's headings (outside code blocks), with GitHub's `-1`,
/// `-2` suffixes for repeated headings.
fn anchors(text: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    let mut in_code = false;
    for l in text.lines() {
        if l.trim_start().starts_with("```") {
            in_code = !in_code;
            continue;
        }
        if in_code || !l.starts_with('#') {
            continue;
        }
        let base = slug(l.trim_start_matches('#').replace('`', "").as_str());
        let mut s = base.clone();
        let mut n = 0;
        while out.contains(&s) {
            n += 1;
            s = format!("{base}-{n}");
        }
        out.insert(s);
    }
    out
}

/// The link targets `[text](target)` of a page, outside code blocks and code spans, with
/// their line numbers.
fn links(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut in_code = false;
    for (i, l) in text.lines().enumerate() {
        if l.trim_start().starts_with("```") {
            in_code = !in_code;
            continue;
        }
        if in_code {
            continue;
        }
        // drop code spans
        let prose: String = l.split('`').step_by(2).collect::<Vec<_>>().join(" ");
        let mut rest = prose.as_str();
        while let Some(p) = rest.find("](") {
            let after = &rest[p + 2..];
            let end = after.find(')').unwrap_or(after.len());
            out.push((i + 1, after[..end].trim().to_string()));
            rest = &after[end..];
        }
    }
    out
}

/// Every relative link of README.md and the docs pages resolves to a file or directory of
/// the repository, and to a heading of the target page where it names one.
#[test]
fn every_relative_link_of_the_pages_resolves_to_a_file_and_heading() {
    let mut checked = 0;
    for page in pages() {
        let text = read(&page);
        for (line, target) in links(&text) {
            if target.contains("://") || target.starts_with("mailto:") {
                continue;
            }
            let (path, anchor) = match target.split_once('#') {
                Some((p, a)) => (p, Some(a)),
                None => (target.as_str(), None),
            };
            let file = if path.is_empty() {
                root().join(&page)
            } else {
                root()
                    .join(page.parent().unwrap_or(Path::new("")))
                    .join(path)
            };
            assert!(
                file.exists(),
                "{page:?}:{line}: the link `{target}` names no file ({file:?})"
            );
            if let Some(a) = anchor {
                let t = std::fs::read_to_string(&file)
                    .unwrap_or_else(|e| panic!("{page:?}:{line}: `{target}`: {e}"));
                assert!(
                    anchors(&t).contains(a),
                    "{page:?}:{line}: the link `{target}` names no heading of {file:?}"
                );
            }
            checked += 1;
        }
    }
    assert!(checked >= 10, "only {checked} links checked");
}

/// The library sources of the workspace (`*/src/lib.rs`, `examples/*/src/lib.rs`).
fn lib_sources() -> Vec<String> {
    let mut out = Vec::new();
    for base in [root(), root().join("examples")] {
        for e in std::fs::read_dir(base).expect("the root is readable") {
            let lib = e.expect("an entry").path().join("src/lib.rs");
            if let Ok(t) = std::fs::read_to_string(&lib) {
                out.push(t);
            }
        }
    }
    out
}

/// Every page with a ` ```rust ` block is compiled and run as a doctest: some library crate
/// includes it (`include_str!` of its path under docs/). A sketch that is not meant to
/// compile says so (` ```rust,ignore `).
#[test]
fn every_page_with_rust_code_is_included_as_a_doctest() {
    let libs = lib_sources();
    let mut included = 0;
    for page in pages() {
        if !blocks(&page)
            .iter()
            .any(|b| b.info.starts_with("rust") && !b.info.contains("ignore"))
        {
            continue;
        }
        let name = page.to_string_lossy().replace('\\', "/");
        assert!(
            name.starts_with("docs/"),
            "{name}: Rust code belongs on a docs page, where it is doctested"
        );
        assert!(
            libs.iter().any(|l| l.contains("#[cfg(doctest)]")
                && l.lines()
                    .any(|x| x.contains("include_str!") && x.contains(&format!("{name}\")")))),
            "{name} has Rust code but no library crate includes it as a doctest"
        );
        included += 1;
    }
    assert!(included >= 1, "no page with Rust code");
}
