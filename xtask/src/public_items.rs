//! `cargo xtask public-items [--root DIR] [--unused]`: the library crates' public items, counted
//! per crate (issue 33's check), and with `--unused` those that nothing outside their crate's
//! `src/` names.
//!
//! **The counting rule** (a text scan, the same for any commit, so `--root` on an old tree
//! gives the count before a change): a public item is a line of a `.rs` file under a library
//! crate's `src/` that starts (after indentation) with `pub` and a space followed by
//! `fn`, `struct`, `enum`, `trait`, `type`, `const`, `static`, `mod`, `use` or `union` (after
//! `unsafe`/`const`/`async`/`extern "C"` qualifiers). `pub(crate)`, `pub(super)` and fields
//! are not items (fields are shown in their own column, not in the total). A `pub` item
//! inside a private module counts, as the text says `pub`: making it `pub(crate)` says what
//! it is. The library crates are the directories at the root with a `src/lib.rs`, except
//! the tools [`TOOLS`] (the command-line crate `ttalloc` counts: its library half was the
//! study-level library before the redesign of issue 33).
//!
//! **Unused** (approximate, on the safe side): an item is used when its name occurs as a
//! whole word (`[A-Za-z0-9_]` bounded) anywhere outside its own crate's `src/`: any other
//! `.rs` file under the root (other crates' `src`, every crate's `tests`, `examples`,
//! `benches`, its own included), the Python package's `.py` files, the code blocks and inline
//! code spans of every Markdown file (docs pages, READMEs and their API tables: an item
//! documented there is API), and the code blocks of doc comments in its own
//! `src/` (doctests compile as another crate). A name that another crate uses for its own
//! item, or a method name such as `new`, makes an item look used: the scan misses such
//! unused items, it never lists a used one by name. A `pub use` is used when any name it
//! re-exports is; a glob re-export is always used.

use std::collections::{BTreeMap, HashMap, HashSet};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Crates at the root with a `src/lib.rs` that are tools, not library crates.
pub(crate) const TOOLS: [&str; 4] = ["xtask", "browser-check", "testkit", "python"];

/// The item keywords the rule counts.
const KINDS: [&str; 10] = [
    "fn", "struct", "enum", "trait", "type", "const", "static", "mod", "use", "union",
];

/// One public item: where it is, its kind and the names it makes public.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Item {
    /// The file, relative to the root.
    pub file: PathBuf,
    /// 1-based line.
    pub line: usize,
    /// `fn`, `struct`, ..., `use`.
    pub kind: &'static str,
    /// The item's name (a `pub use`: every name it re-exports; a glob: `*`).
    pub names: Vec<String>,
    /// A `pub use`'s renamings (`a::B as C`: `("B", "C")`): `B` is used when `C` is.
    pub renamed: Vec<(String, String)>,
    /// Whether its file's module is reachable from the crate root through `pub mod`s, or it
    /// is indented (a method, reachable through its type, or in an inline module).
    pub in_public_module: bool,
}

/// One crate's count.
#[derive(Debug, Default)]
pub(crate) struct CrateCount {
    /// The crate's public items.
    pub items: Vec<Item>,
    /// Lines declaring a `pub` field (`pub name: Type`), not in the total.
    pub fields: usize,
}

/// The library crates under `root` (directory names), sorted.
///
/// # Errors
/// The root cannot be read.
pub(crate) fn library_crates(root: &Path) -> std::io::Result<Vec<String>> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(root)? {
        let e = e?;
        let name = e.file_name().to_string_lossy().into_owned();
        if e.path().join("src/lib.rs").is_file() && !TOOLS.contains(&name.as_str()) {
            out.push(name);
        }
    }
    out.sort();
    Ok(out)
}

/// Every file with extension `ext` under `dir` (recursively; `target`, `.git` and hidden
/// directories skipped), sorted.
fn files(dir: &Path, ext: &str, out: &mut Vec<PathBuf>) {
    let Ok(rd) = std::fs::read_dir(dir) else {
        return;
    };
    let mut entries: Vec<_> = rd.filter_map(Result::ok).map(|e| e.path()).collect();
    entries.sort();
    for p in entries {
        let name = p.file_name().map(|n| n.to_string_lossy().into_owned());
        let name = name.unwrap_or_default();
        if p.is_dir() {
            if name != "target" && !name.starts_with('.') && name != "node_modules" {
                files(&p, ext, out);
            }
        } else if p.extension().is_some_and(|x| x == ext) {
            out.push(p);
        }
    }
}

/// Whether a path under `src/` is a binary's (`main.rs`, `bin/`): another crate, that uses
/// the library through its public items.
fn is_binary(rel: &Path) -> bool {
    rel == Path::new("main.rs") || rel.starts_with("bin")
}

/// The item a source line declares public, if it does (the rule of the module docs);
/// `rest` gives the following lines, for a `pub use` that spans several.
fn item_of(line: &str, rest: &[&str]) -> Option<(&'static str, Vec<(String, String)>)> {
    let mut s = line.trim_start().strip_prefix("pub ")?.trim_start();
    loop {
        let before = s;
        for q in ["unsafe ", "async ", "extern \"C\" ", "extern "] {
            if let Some(t) = s.strip_prefix(q) {
                s = t.trim_start();
            }
        }
        if let Some(t) = s.strip_prefix("const ") {
            let t = t.trim_start();
            if t.starts_with("fn ") || t.starts_with("unsafe ") || t.starts_with("async ") {
                s = t;
            }
        }
        if s == before {
            break;
        }
    }
    let kind = KINDS.iter().find(|k| {
        s.strip_prefix(**k)
            .is_some_and(|t| t.starts_with(' ') || t.starts_with('\t'))
    })?;
    let body = s[kind.len()..].trim_start();
    if *kind == "use" {
        let mut text = body.to_string();
        for more in rest {
            if text.contains(';') {
                break;
            }
            text.push(' ');
            text.push_str(more.trim());
        }
        let text = text.split(';').next().unwrap_or_default();
        return Some((kind, use_names(text)));
    }
    let name: String = body
        .trim_start_matches("r#")
        .chars()
        .take_while(|c| c.is_alphanumeric() || *c == '_')
        .collect();
    (!name.is_empty()).then(|| (*kind, vec![(name.clone(), name)]))
}

/// The names a `use` tree makes visible, each with the name it imports (`a::{b, c as d}` ->
/// `(b, b)`, `(c, d)`; a glob -> `(*, *)`).
fn use_names(tree: &str) -> Vec<(String, String)> {
    let mut names = Vec::new();
    for leaf in tree.split(['{', '}', ',']) {
        let leaf = leaf.trim();
        if leaf.is_empty() {
            continue;
        }
        let (path, name) = leaf.split_once(" as ").unwrap_or((leaf, leaf));
        let original = path.rsplit("::").next().unwrap_or(path).trim();
        let name = name.rsplit("::").next().unwrap_or(name).trim();
        if name.ends_with('*') {
            names.push(("*".to_string(), "*".to_string()));
        } else if !name.is_empty() && name != "self" && name != "_" {
            names.push((original.to_string(), name.to_string()));
        }
    }
    names
}

/// `pub name: Type` (a field, not an item).
fn is_field(line: &str) -> bool {
    let Some(s) = line.trim_start().strip_prefix("pub ") else {
        return false;
    };
    let name: String = s
        .chars()
        .take_while(|c| c.is_alphanumeric() || *c == '_')
        .collect();
    !name.is_empty()
        && !KINDS.contains(&name.as_str())
        && s[name.len()..].trim_start().starts_with(':')
        && !s[name.len()..].trim_start().starts_with("::")
}

/// Whether the module of the file `f` under `src` is public: every module from the crate
/// root down to it declared `pub mod` in its parent's file (`a/b.rs` in `a.rs` or
/// `a/mod.rs`). Inline and `#[path]` modules are not followed.
fn public_module(src: &Path, f: &Path) -> bool {
    let Ok(rel) = f.strip_prefix(src) else {
        return false;
    };
    let mut parts: Vec<String> = rel
        .iter()
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    let last = parts.pop().unwrap_or_default();
    let stem = last.trim_end_matches(".rs");
    if !matches!(stem, "lib" | "mod") {
        parts.push(stem.to_string());
    }
    (0..parts.len()).all(|k| {
        let dir: PathBuf = parts[..k].iter().collect();
        let parent = if k == 0 {
            src.join("lib.rs")
        } else {
            let d = src.join(&dir);
            let flat = d.with_extension("rs");
            if flat.is_file() {
                flat
            } else {
                d.join("mod.rs")
            }
        };
        let text = std::fs::read_to_string(parent).unwrap_or_default();
        let decl = [
            format!("pub mod {};", parts[k]),
            format!("pub mod {} {{", parts[k]),
        ];
        text.lines().any(|l| decl.iter().any(|d| l.trim() == d))
    })
}

/// Count one crate's public items (`dir` its directory, paths shown relative to `root`).
pub(crate) fn count_crate(root: &Path, dir: &Path) -> CrateCount {
    let mut srcs = Vec::new();
    files(&dir.join("src"), "rs", &mut srcs);
    srcs.retain(|f| !is_binary(f.strip_prefix(dir.join("src")).unwrap_or(f)));
    let mut count = CrateCount::default();
    for f in srcs {
        let text = std::fs::read_to_string(&f).unwrap_or_default();
        let lines: Vec<&str> = text.lines().collect();
        for (i, l) in lines.iter().enumerate() {
            if let Some((kind, names)) = item_of(l, &lines[i + 1..]) {
                count.items.push(Item {
                    file: f.strip_prefix(root).unwrap_or(&f).to_path_buf(),
                    line: i + 1,
                    kind,
                    names: names.iter().map(|(_, n)| n.clone()).collect(),
                    renamed: names.into_iter().filter(|(o, n)| o != n).collect(),
                    in_public_module: l.starts_with(char::is_whitespace)
                        || public_module(&dir.join("src"), &f),
                });
            } else if is_field(l) {
                count.fields += 1;
            }
        }
    }
    count
}

/// The words (identifier tokens) of a text.
fn words(text: &str) -> impl Iterator<Item = &str> {
    text.split(|c: char| !(c.is_alphanumeric() || c == '_'))
        .filter(|w| !w.is_empty())
}

/// The code of a Markdown text: its fenced blocks and its inline code spans (an API table
/// naming `accessor()` documents it).
fn fenced(lines: impl Iterator<Item = String>) -> String {
    let mut out = String::new();
    let mut inside = false;
    for l in lines {
        if l.trim_start().starts_with("```") {
            inside = !inside;
        } else if inside {
            out.push_str(&l);
            out.push('\n');
        } else {
            for span in l.split('`').skip(1).step_by(2) {
                out.push_str(span);
                out.push('\n');
            }
        }
    }
    out
}

/// The code blocks of a Rust file's doc comments (`///`, `//!`).
fn doc_code(text: &str) -> String {
    fenced(text.lines().filter_map(|l| {
        let t = l.trim_start();
        t.strip_prefix("///")
            .or_else(|| t.strip_prefix("//!"))
            .map(str::to_string)
    }))
}

/// Where each word occurs: the crates whose `src/` holds it (`Some`), or `None` for any place
/// outside a library crate's `src/` (tests, other tools, Python, Markdown code, doctests).
struct Uses(HashMap<String, HashSet<Option<String>>>);

impl Uses {
    fn add(&mut self, text: &str, owner: Option<&str>) {
        for w in words(text) {
            self.0
                .entry(w.to_string())
                .or_default()
                .insert(owner.map(str::to_string));
        }
    }

    /// Whether `name` occurs anywhere but in `krate`'s own `src/` code.
    fn outside(&self, name: &str, krate: &str) -> bool {
        name == "*"
            || self
                .0
                .get(name)
                .is_some_and(|o| o.iter().any(|c| c.as_deref() != Some(krate)))
    }
}

/// The scan of the tree at `root`: every library crate's count, and where every word occurs.
pub(crate) struct Scan {
    /// Per library crate (directory name), its count.
    pub crates: BTreeMap<String, CrateCount>,
    uses: Uses,
}

impl Scan {
    /// Scan the tree at `root`.
    ///
    /// # Errors
    /// The root cannot be read.
    pub(crate) fn new(root: &Path) -> std::io::Result<Self> {
        let libs = library_crates(root)?;
        let crates = libs
            .iter()
            .map(|c| (c.clone(), count_crate(root, &root.join(c))))
            .collect();
        let mut uses = Uses(HashMap::new());
        let mut rs = Vec::new();
        files(root, "rs", &mut rs);
        for f in rs {
            let text = std::fs::read_to_string(&f).unwrap_or_default();
            let rel = f.strip_prefix(root).unwrap_or(&f);
            let owner = libs.iter().find(|c| {
                let src = Path::new(c.as_str()).join("src");
                rel.starts_with(&src) && !is_binary(rel.strip_prefix(&src).unwrap_or(rel))
            });
            uses.add(&text, owner.map(String::as_str));
            if owner.is_some() {
                uses.add(&doc_code(&text), None);
            }
        }
        let mut py = Vec::new();
        files(&root.join("python"), "py", &mut py);
        for f in py {
            uses.add(&std::fs::read_to_string(&f).unwrap_or_default(), None);
        }
        let mut md = Vec::new();
        files(root, "md", &mut md);
        for f in md {
            let text = std::fs::read_to_string(&f).unwrap_or_default();
            uses.add(&fenced(text.lines().map(str::to_string)), None);
        }
        Ok(Self { crates, uses })
    }

    /// The items of `krate` that no name of theirs is used outside its `src/` (directly, or
    /// through a `pub use ... as` renaming of the crate).
    pub(crate) fn unused(&self, krate: &str) -> Vec<&Item> {
        let Some(c) = self.crates.get(krate) else {
            return Vec::new();
        };
        let renamed: Vec<&(String, String)> = c.items.iter().flat_map(|i| &i.renamed).collect();
        let used = |n: &String| {
            self.uses.outside(n, krate)
                || renamed
                    .iter()
                    .any(|(o, a)| o == n && self.uses.outside(a, krate))
        };
        c.items
            .iter()
            .filter(|i| !i.names.iter().any(used))
            .collect()
    }

    /// The items of `krate` that are public only in name: in a module that is not public
    /// (`mod x;`) and not re-exported by any `pub use` of the crate (by name).
    pub(crate) fn hidden(&self, krate: &str) -> Vec<&Item> {
        let Some(c) = self.crates.get(krate) else {
            return Vec::new();
        };
        let exported: HashSet<&String> = c
            .items
            .iter()
            .filter(|i| i.kind == "use")
            .flat_map(|i| i.names.iter().chain(i.renamed.iter().map(|(o, _)| o)))
            .collect();
        c.items
            .iter()
            .filter(|i| {
                !i.in_public_module
                    && i.kind != "use"
                    && !i.names.iter().any(|n| exported.contains(n))
            })
            .collect()
    }

    /// The report: per crate its items, fields, how many items are unused outside it and
    /// how many are hidden (in a private module, not re-exported); the totals; with `list`,
    /// every unused or hidden item with its place.
    pub(crate) fn report(&self, list: bool) -> String {
        let mut out = String::new();
        let head = ["crate", "items", "fields", "unused", "hidden"];
        let _ = writeln!(
            out,
            "{:<18} {:>6} {:>6} {:>7} {:>7}",
            head[0], head[1], head[2], head[3], head[4]
        );
        let mut total = [0; 4];
        for (name, c) in &self.crates {
            let row = [
                c.items.len(),
                c.fields,
                self.unused(name).len(),
                self.hidden(name).len(),
            ];
            let _ = writeln!(
                out,
                "{name:<18} {:>6} {:>6} {:>7} {:>7}",
                row[0], row[1], row[2], row[3]
            );
            for (t, r) in total.iter_mut().zip(row) {
                *t += r;
            }
        }
        let _ = writeln!(
            out,
            "{:<18} {:>6} {:>6} {:>7} {:>7}",
            "total", total[0], total[1], total[2], total[3]
        );
        if list {
            for name in self.crates.keys() {
                let unused = self.unused(name);
                let hidden = self.hidden(name);
                for i in &self.crates[name].items {
                    let why = match (unused.contains(&i), hidden.contains(&i)) {
                        (true, true) => "unused outside, in a private module",
                        (true, false) => "unused outside",
                        (false, true) => "in a private module",
                        (false, false) => continue,
                    };
                    let _ = writeln!(
                        out,
                        "{}:{}: pub {} {} ({why})",
                        i.file.display(),
                        i.line,
                        i.kind,
                        i.names.join(", ")
                    );
                }
            }
        }
        out
    }
}

/// The command's arguments.
#[derive(clap::Parser, Debug)]
pub(crate) struct Args {
    /// The tree to count (default: this repository), e.g. an old commit's `git archive`.
    #[arg(long)]
    pub root: Option<PathBuf>,
    /// Also list every item not named outside its own crate's `src/`, and every item in a
    /// private module that no `pub use` re-exports.
    #[arg(long)]
    pub unused: bool,
}

/// Run the command: print the report.
///
/// # Errors
/// The root cannot be read.
pub(crate) fn run(args: &Args) -> anyhow::Result<()> {
    let root = args
        .root
        .clone()
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join(".."));
    anyhow::ensure!(
        root.is_dir(),
        "--root {}: not a directory",
        tt_core::human::terminal(&root.display().to_string())
    );
    let scan = Scan::new(&root)?;
    print!("{}", scan.report(args.unused));
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(root: &Path, rel: &str, text: &str) {
        let p = root.join(rel);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, text).unwrap();
    }

    /// A tiny tree: crate `a` with an item used by crate `b`, one used only by its own
    /// tests, one named in a docs page's code block, one in its own doctest, a re-export
    /// used by the Python package, a struct named in a docs page's inline code, and two that
    /// nothing outside names (one in prose only); crate-private items
    /// and fields are not counted; the tool crate `xtask` is not a library crate.
    fn fixture() -> tempfile::TempDir {
        let d = tempfile::tempdir().unwrap();
        let r = d.path();
        write(
            r,
            "a/src/lib.rs",
            "//! ```\n//! a::in_doctest();\n//! ```\npub mod inner;\npub use inner::{Reexported, Shown as Renamed};\npub fn used_by_b() { never_called_outside(); }\npub fn used_by_own_test() {}\npub fn in_doctest() {}\npub fn in_docs_page() {}\npub(crate) fn crate_only() {}\npub fn never_called_outside() {}\npub struct Fields {\n    pub x: f64,\n}\nmod private;\n",
        );
        write(
            r,
            "a/src/private.rs",
            "pub fn helper() {}\nimpl crate::Fields {\n    pub fn x(&self) {}\n}\n",
        );
        write(r, "b/tests/t.rs", "fn t() { helper(); }\n");
        write(
            r,
            "a/src/inner.rs",
            "pub struct Reexported;\npub struct Shown;\npub const fn idle_const() -> u8 { 0 }\n",
        );
        write(
            r,
            "a/tests/t.rs",
            "#[test] fn t() { a::used_by_own_test(); }\n",
        );
        write(
            r,
            "b/src/lib.rs",
            "pub fn b() { a::used_by_b(); let _ = a::inner::Reexported; }\n",
        );
        write(r, "python/x.py", "print(Renamed)\n");
        write(
            r,
            "docs/page.md",
            "Prose naming never_called_outside, a table naming `Fields`.\n```rust\na::in_docs_page();\n```\n",
        );
        write(r, "xtask/src/lib.rs", "pub fn tool_item() {}\n");
        d
    }

    #[test]
    fn public_items_counts_pub_items_not_crate_private_items_or_fields_or_tools() {
        let d = fixture();
        let scan = Scan::new(d.path()).unwrap();
        assert_eq!(scan.crates.keys().collect::<Vec<_>>(), ["a", "b"]);
        // a: mod, use, 5 fns, struct Fields (lib.rs); 2 structs, const fn (inner.rs); 2 fns
        // (private.rs)
        assert_eq!(scan.crates["a"].items.len(), 13);
        assert_eq!(scan.crates["a"].fields, 1);
        assert_eq!(scan.crates["b"].items.len(), 1);
        let idle = scan.crates["a"]
            .items
            .iter()
            .find(|i| i.names == ["idle_const"])
            .unwrap();
        assert_eq!(idle.kind, "fn");
        let reexport = scan.crates["a"].items.iter().find(|i| i.kind == "use");
        assert_eq!(reexport.unwrap().names, ["Reexported", "Renamed"]);
    }

    #[test]
    fn public_items_unused_lists_unused_items_and_no_used_one() {
        let d = fixture();
        let scan = Scan::new(d.path()).unwrap();
        let names: Vec<&str> = scan
            .unused("a")
            .iter()
            .flat_map(|i| i.names.iter().map(String::as_str))
            .collect();
        // used in its own crate's src only, or in prose only: unused (`Shown` is used as
        // `Renamed`)
        assert_eq!(names, ["idle_const", "never_called_outside", "x"]);
        // `b` is named by nothing else
        assert_eq!(scan.unused("b").len(), 1);
        let report = scan.report(true);
        assert!(report.contains("a/src/lib.rs:11: pub fn never_called_outside (unused outside)\n"));
        assert!(report.contains("a/src/inner.rs:3: pub fn idle_const (unused outside)\n"));
        assert!(!report.contains("used_by_b"));
        // `helper` is named outside but is in a private module: hidden (the method `x` is
        // reachable through its type)
        assert!(report.contains("a/src/private.rs:1: pub fn helper (in a private module)\n"));
        assert!(report.contains("a/src/private.rs:3: pub fn x (unused outside)\n"));
        assert!(report.contains(&format!(
            "{:<18} {:>6} {:>6} {:>7} {:>7}\n",
            "total", 14, 1, 4, 1
        )));
    }
}
