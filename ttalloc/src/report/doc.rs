//! The report as a document: an ordered list of blocks rendered both as Markdown (figures as
//! linked SVG files) and as one self-contained HTML page (figures inline as data URIs, a
//! table of contents, tables that fit a 1280 px window).
//!
//! Inline markup in text: `` `code` ``, `**bold**`, internal links `[text](#id)` and
//! CommonMark's backslash escapes (`\*` is a literal `*`); everything else is escaped in HTML.
//! Text from a file (a study's description, units, paths, a tolerance sheet's name) enters a
//! document only through [`text`] or [`code`]: it then shows literally in both renderings, never
//! as markup, raw HTML or a raw control character.

use std::fmt::Write as _;

/// One block of the report.
#[derive(Debug, Clone)]
pub enum Block {
    /// A heading of level 1-4 and its anchor id.
    Heading(u8, String, String),
    /// A paragraph.
    Paragraph(String),
    /// A highlighted paragraph (the answer of a section), with optional bullets under it.
    Callout(String, Vec<String>),
    /// A bulleted list.
    List(Vec<String>),
    /// A table: header, rows of cells.
    Table(Vec<String>, Vec<Vec<String>>),
    /// A figure: anchor id, file name, caption, SVG text, width and height (px).
    Figure {
        /// Anchor id.
        id: String,
        /// File name of the SVG beside the report.
        file: String,
        /// Caption.
        caption: String,
        /// The SVG document.
        svg: String,
    },
    /// Preformatted text.
    Code(String),
    /// Where the table of contents goes.
    Contents,
}

/// The report.
#[derive(Debug, Clone, Default)]
pub struct Doc {
    /// Blocks in reading order.
    pub blocks: Vec<Block>,
    ids: Vec<String>,
}

/// First of the private-use characters that stand for escaped ASCII punctuation while inline
/// markup is parsed (`\*` becomes `ESCAPED + '*'`); [`text`] shows any such character of a file
/// escaped, so they never come from outside.
const ESCAPED: u32 = 0xE000;

fn is_placeholder(c: char) -> bool {
    (ESCAPED..ESCAPED + 0x80).contains(&u32::from(c))
}

/// The characters [`text`] escapes anywhere: Markdown's inline markup, raw HTML and entities.
/// (`|` is escaped by the table renderer, which knows where it matters.)
const MD_ACTIVE: &[char] = &['\\', '`', '*', '_', '[', ']', '<', '>', '&', '~', '#'];

/// Text from a file, as literal document text: line breaks and tabs become spaces, control
/// and bidirectional characters are shown escaped ([`study::fmt::visible`]), and every
/// character that Markdown or HTML would read as structure is backslash-escaped (as are `-`,
/// `+`, `=` at the start, and `.`/`)` after leading digits: list and heading markers). Both
/// renderings then show exactly the text.
#[must_use]
pub fn text(s: &str) -> String {
    let flat = s.replace("\r\n", " ").replace(['\n', '\t'], " ");
    let shown = study::fmt::visible(&flat);
    let mut out = String::with_capacity(shown.len() + 8);
    let digits = shown.chars().take_while(char::is_ascii_digit).count();
    for (i, c) in shown.chars().enumerate() {
        if is_placeholder(c) {
            out.push_str(&format!("\\\\u{{{:x}}}", u32::from(c)));
            continue;
        }
        let line_start = i == 0 && matches!(c, '-' | '+' | '=');
        let list_marker = i == digits && digits > 0 && matches!(c, '.' | ')');
        if MD_ACTIVE.contains(&c) || line_start || list_marker {
            out.push('\\');
        }
        out.push(c);
    }
    out
}

/// Text from a file (a path, a name) as a code span: shown literally, control characters
/// escaped; one that holds a backtick (which would end the span) becomes literal [`text`].
#[must_use]
pub fn code(s: &str) -> String {
    let shown = study::fmt::visible(s);
    if shown.contains('`') || shown.chars().any(is_placeholder) || shown.is_empty() {
        text(&shown)
    } else {
        format!("`{shown}`")
    }
}

/// Replace every backslash escape outside code spans by its placeholder, so that the
/// markup parsers below see only real markup.
fn protect(t: &str) -> String {
    let mut out = String::with_capacity(t.len());
    let mut in_code = false;
    let mut chars = t.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '\\' if !in_code => match chars.peek() {
                Some(&n) if n.is_ascii_punctuation() => {
                    chars.next();
                    out.push(char::from_u32(ESCAPED + u32::from(n)).unwrap_or(n));
                }
                _ => out.push(c),
            },
            '`' => {
                in_code = !in_code;
                out.push(c);
            }
            _ => out.push(c),
        }
    }
    out
}

/// The placeholders of [`protect`] back as literal characters (`md`: as Markdown escapes).
fn unprotect(t: &str, md: bool) -> String {
    let mut out = String::with_capacity(t.len());
    for c in t.chars() {
        if is_placeholder(c) {
            if md {
                out.push('\\');
            }
            out.push(char::from_u32(u32::from(c) - ESCAPED).unwrap_or(c));
        } else {
            out.push(c);
        }
    }
    out
}

/// A GitHub-style anchor: lower case, letters, digits, `-` and `_` kept, spaces to `-`,
/// everything else dropped.
#[must_use]
pub fn slug(text: &str) -> String {
    let mut s = String::new();
    for c in plain(text).chars() {
        if c.is_alphanumeric() || c == '_' || c == '-' {
            s.extend(c.to_lowercase());
        } else if c == ' ' {
            s.push('-');
        }
    }
    s
}

/// Text without the inline markup (`code`, **bold**, [text](#id) → text; escapes resolved):
/// for anchors, attributes and figure labels.
#[must_use]
pub fn plain(text: &str) -> String {
    unprotect(&strip(&protect(text)), false)
}

/// [`plain`] for Markdown: the markup removed, backslash escapes kept (a link's label).
fn plain_md(text: &str) -> String {
    unprotect(&strip(&protect(text)), true)
}

/// Remove code, bold and link markup from protected text.
fn strip(text: &str) -> String {
    let mut out = String::new();
    let mut rest = text;
    while let Some(i) = rest.find('[') {
        out.push_str(&rest[..i]);
        let after = &rest[i..];
        match link_at(after) {
            Some((label, _, len)) => {
                out.push_str(label);
                rest = &after[len..];
            }
            None => {
                out.push('[');
                rest = &after[1..];
            }
        }
    }
    out.push_str(rest);
    out.replace(['`'], "").replace("**", "")
}

/// `[label](#id)` at the start of `s`: (label, id, length).
fn link_at(s: &str) -> Option<(&str, &str, usize)> {
    let close = s.find("](#")?;
    let label = &s[1..close];
    if label.contains('[') || label.contains(']') {
        return None;
    }
    let end = s[close..].find(')')? + close;
    let id = &s[close + 3..end];
    (!id.is_empty() && !id.contains(' ')).then_some((label, id, end + 1))
}

impl Doc {
    fn unique_id(&mut self, base: &str) -> String {
        let mut id = base.to_string();
        let mut k = 1;
        while self.ids.contains(&id) {
            id = format!("{base}-{k}");
            k += 1;
        }
        self.ids.push(id.clone());
        id
    }

    /// Append a heading; returns its anchor id (unique, from the text).
    pub fn h(&mut self, level: u8, text: impl Into<String>) -> String {
        let text = text.into();
        let id = self.unique_id(&slug(&text));
        self.blocks.push(Block::Heading(level, text, id.clone()));
        id
    }

    /// Append a paragraph.
    pub fn p(&mut self, text: impl Into<String>) {
        self.blocks.push(Block::Paragraph(text.into()));
    }

    /// Append a highlighted paragraph.
    pub fn callout(&mut self, text: impl Into<String>) {
        self.blocks.push(Block::Callout(text.into(), Vec::new()));
    }

    /// Append a highlighted paragraph with bullets under it.
    pub fn callout_list(&mut self, text: impl Into<String>, items: Vec<String>) {
        self.blocks.push(Block::Callout(text.into(), items));
    }

    /// Append a list.
    pub fn list(&mut self, items: Vec<String>) {
        if !items.is_empty() {
            self.blocks.push(Block::List(items));
        }
    }

    /// Append a table.
    pub fn table(&mut self, header: &[&str], rows: Vec<Vec<String>>) {
        self.blocks.push(Block::Table(
            header.iter().map(|s| (*s).to_string()).collect(),
            rows,
        ));
    }

    /// Append a figure; returns its anchor id (`figure-<file stem>`).
    pub fn figure(&mut self, file: &str, caption: impl Into<String>, svg: String) -> String {
        let id = self.unique_id(&format!(
            "figure-{}",
            file.trim_end_matches(".svg").replace('_', "-")
        ));
        self.blocks.push(Block::Figure {
            id: id.clone(),
            file: file.to_string(),
            caption: caption.into(),
            svg,
        });
        id
    }

    /// Append preformatted text.
    pub fn code(&mut self, text: impl Into<String>) {
        self.blocks.push(Block::Code(text.into()));
    }

    /// Put the table of contents here.
    pub fn contents(&mut self) {
        self.blocks.push(Block::Contents);
    }

    /// The figures (file name, SVG) to write beside the report.
    pub fn figures(&self) -> impl Iterator<Item = (&str, &str)> {
        self.blocks.iter().filter_map(|b| match b {
            Block::Figure { file, svg, .. } => Some((file.as_str(), svg.as_str())),
            _ => None,
        })
    }

    /// Every anchor id of the document (headings and figures).
    #[must_use]
    pub fn anchors(&self) -> Vec<&str> {
        self.blocks
            .iter()
            .filter_map(|b| match b {
                Block::Heading(_, _, id) | Block::Figure { id, .. } => Some(id.as_str()),
                _ => None,
            })
            .collect()
    }

    fn headings(&self) -> impl Iterator<Item = (u8, &str, &str)> {
        self.blocks.iter().filter_map(|b| match b {
            Block::Heading(l, t, id) if (2..=3).contains(l) => Some((*l, t.as_str(), id.as_str())),
            _ => None,
        })
    }

    /// Markdown; figures linked by file name, anchors as GitHub makes them from headings.
    #[must_use]
    pub fn to_markdown(&self) -> String {
        let mut s = String::new();
        for b in &self.blocks {
            match b {
                Block::Heading(l, t, _) => {
                    let _ = writeln!(s, "{} {t}\n", "#".repeat(usize::from(*l)));
                }
                Block::Paragraph(t) => {
                    // leading spaces would make an indented code block
                    let _ = writeln!(s, "{}\n", t.trim_start());
                }
                Block::Callout(t, items) => {
                    let _ = writeln!(s, "> {t}");
                    if !items.is_empty() {
                        s.push_str(">\n");
                    }
                    for i in items {
                        let _ = writeln!(s, "> - {i}");
                    }
                    s.push('\n');
                }
                Block::List(items) => {
                    for i in items {
                        let _ = writeln!(s, "- {i}");
                    }
                    s.push('\n');
                }
                Block::Table(h, rows) => {
                    let cell = |c: &String| c.replace('|', "\\|").replace('\n', " ");
                    let _ = writeln!(
                        s,
                        "| {} |",
                        h.iter().map(cell).collect::<Vec<_>>().join(" | ")
                    );
                    let _ = writeln!(s, "|{}", "---|".repeat(h.len()));
                    for r in rows {
                        let _ = writeln!(
                            s,
                            "| {} |",
                            r.iter().map(cell).collect::<Vec<_>>().join(" | ")
                        );
                    }
                    s.push('\n');
                }
                Block::Figure {
                    id, file, caption, ..
                } => {
                    // an explicit anchor: links to a figure resolve in Markdown too
                    let _ = writeln!(
                        s,
                        "<a id=\"{id}\"></a>\n\n![{}]({file})\n\n*{caption}*\n",
                        plain_md(caption)
                    );
                }
                Block::Code(t) => {
                    let _ = writeln!(s, "```text\n{t}\n```\n");
                }
                Block::Contents => {
                    s.push_str("**Contents**\n\n");
                    for (l, t, id) in self.headings() {
                        let indent = if l == 3 { "  " } else { "" };
                        let _ = writeln!(s, "{indent}- [{}](#{id})", plain_md(t));
                    }
                    s.push('\n');
                }
            }
        }
        s
    }

    /// One self-contained HTML page.
    #[must_use]
    pub fn to_html(&self, title: &str) -> String {
        let mut s = format!(
            "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
             <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\
             <title>{}</title>\n<style>{CSS}</style></head><body>\n<main>\n",
            escape(&plain(title))
        );
        for b in &self.blocks {
            match b {
                Block::Heading(l, t, id) => {
                    let _ = writeln!(s, "<h{l} id=\"{id}\">{}</h{l}>", inline(t));
                }
                Block::Paragraph(t) => {
                    let _ = writeln!(s, "<p>{}</p>", inline(t));
                }
                Block::Callout(t, items) => {
                    let _ = write!(s, "<div class=\"callout\"><p>{}</p>", inline(t));
                    if !items.is_empty() {
                        s.push_str("<ul>");
                        for i in items {
                            let _ = write!(s, "<li>{}</li>", inline(i));
                        }
                        s.push_str("</ul>");
                    }
                    s.push_str("</div>\n");
                }
                Block::List(items) => {
                    s.push_str("<ul>\n");
                    for i in items {
                        let _ = writeln!(s, "<li>{}</li>", inline(i));
                    }
                    s.push_str("</ul>\n");
                }
                Block::Table(h, rows) => {
                    let wide = if h.len() >= 6 { " class=\"wide\"" } else { "" };
                    let _ = write!(s, "<table{wide}><thead><tr>");
                    for c in h {
                        let _ = write!(s, "<th>{}</th>", inline(c));
                    }
                    s.push_str("</tr></thead><tbody>\n");
                    // a column is numeric (right-aligned) when every non-empty cell is a number
                    let numeric: Vec<bool> = (0..h.len())
                        .map(|j| {
                            let cells: Vec<&String> = rows
                                .iter()
                                .filter_map(|r| r.get(j))
                                .filter(|c| !matches!(c.as_str(), "" | "-" | "none"))
                                .collect();
                            !cells.is_empty() && cells.iter().all(|c| is_number(c))
                        })
                        .collect();
                    for r in rows {
                        s.push_str("<tr>");
                        for (j, c) in r.iter().enumerate() {
                            let class = if numeric.get(j).copied().unwrap_or(false) {
                                " class=\"num\""
                            } else {
                                ""
                            };
                            let _ = write!(s, "<td{class}>{}</td>", inline(c));
                        }
                        s.push_str("</tr>\n");
                    }
                    s.push_str("</tbody></table>\n");
                }
                Block::Figure {
                    id, caption, svg, ..
                } => {
                    let (w, h) = svg_size(svg);
                    let _ = writeln!(
                        s,
                        "<figure id=\"{id}\"><img src=\"data:image/svg+xml;base64,{}\" width=\"{w}\" height=\"{h}\" alt=\"{}\"><figcaption>{}</figcaption></figure>",
                        base64(svg.as_bytes()),
                        escape(&plain(caption)).replace('"', "&quot;"),
                        inline(caption)
                    );
                }
                Block::Code(t) => {
                    let _ = writeln!(s, "<pre>{}</pre>", escape(t));
                }
                Block::Contents => {
                    s.push_str("<nav class=\"toc\"><p><b>Contents</b></p><ul>\n");
                    let mut open = false;
                    for (l, t, id) in self.headings() {
                        if l == 2 {
                            if open {
                                s.push_str("</ul></li>\n");
                            }
                            let _ = write!(s, "<li><a href=\"#{id}\">{}</a>", escape(&plain(t)));
                            s.push_str("<ul>");
                            open = true;
                        } else {
                            let _ =
                                writeln!(s, "<li><a href=\"#{id}\">{}</a></li>", escape(&plain(t)));
                        }
                    }
                    if open {
                        s.push_str("</ul></li>\n");
                    }
                    s.push_str("</ul></nav>\n");
                }
            }
        }
        s.push_str("</main></body></html>\n");
        // empty sub-lists of the contents
        s.replace("<ul></ul>", "")
    }
}

/// Code spans longer than this (characters) may wrap anywhere (test names, commands).
const LONG_CODE: usize = 24;

/// The page's style: readable width, tables that fit (long identifiers wrap), figures scaled
/// to the column. Fonts: the families `cargo xtask test` installs (fonts-dejavu-core,
/// fonts-liberation) first, so that the page lays out alike wherever the README's set-up ran.
const CSS: &str = "\
body{font-family:'DejaVu Sans','Liberation Sans',sans-serif;color:#222;margin:0;line-height:1.5}\
code,pre{font-family:'DejaVu Sans Mono','Liberation Mono',monospace}\
main{max-width:1180px;margin:0 auto;padding:1em 1.5em 3em}\
h1{font-size:1.7em;margin:.4em 0}h2{margin-top:1.8em;border-bottom:1px solid #ccc;padding-bottom:.15em}\
h3{margin-top:1.4em}\
table{border-collapse:collapse;margin:.8em 0;font-size:.9em;max-width:100%}\
table.wide{font-size:.84em}\
td,th{border:1px solid #bbb;padding:3px 7px;text-align:left;vertical-align:top;overflow-wrap:break-word}\
th{background:#eef1f5}td.num{text-align:right;white-space:nowrap;font-variant-numeric:tabular-nums}\
code{background:#f3f3f3;padding:0 2px;font-size:.92em;white-space:nowrap}code.long{white-space:normal;overflow-wrap:anywhere}\
pre{background:#f5f5f5;padding:.6em;white-space:pre-wrap;overflow-wrap:anywhere}\
figure{margin:1em 0}figure img{max-width:100%;height:auto;display:block}\
figcaption{font-style:italic;color:#444;margin-top:.3em}\
.callout{background:#f4f8ec;border-left:4px solid #6a9a2a;padding:.1em .8em;margin:1em 0}.callout ul{margin-top:0}\
nav.toc{background:#fafafa;border:1px solid #ddd;padding:.3em 1em;margin:1em 0}\
nav.toc ul{margin:.2em 0;padding-left:1.3em}nav.toc>ul>li>ul{font-size:.92em}\
b.no{color:#a01818}b.yes{color:#1d6b1d}";

fn is_number(c: &str) -> bool {
    let t = c.trim().trim_end_matches('%');
    !t.is_empty() && t.parse::<f64>().is_ok()
}

/// Width and height of an SVG document (its `width`/`height` attributes, px).
fn svg_size(svg: &str) -> (u32, u32) {
    let attr = |name: &str| -> u32 {
        let key = format!(" {name}=\"");
        svg.find("<svg")
            .and_then(|s| svg[s..].find(&key).map(|i| s + i + key.len()))
            .and_then(|start| {
                svg[start..].find('"').and_then(|end| {
                    svg[start..start + end]
                        .trim_end_matches("px")
                        .parse::<f64>()
                        .ok()
                })
            })
            .map_or(0, |v| v.round() as u32)
    };
    (attr("width"), attr("height"))
}

/// Standard base64 (RFC 4648) with padding.
fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for c in bytes.chunks(3) {
        let n = (u32::from(c[0]) << 16)
            | (u32::from(*c.get(1).unwrap_or(&0)) << 8)
            | u32::from(*c.get(2).unwrap_or(&0));
        for k in 0..4 {
            if k <= c.len() {
                out.push(A[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// HTML-escape text (`&`, `<`, `>`; escaped characters of [`protect`] as themselves).
fn escape(t: &str) -> String {
    unprotect(t, false)
        .replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// Escape, then turn `code`, **bold** and [text](#id) into HTML. `**no**` and `**yes**`
/// (verdicts) get a colour.
fn inline(t: &str) -> String {
    let t = protect(t);
    let mut out = String::new();
    for (k, part) in t.split('`').enumerate() {
        if k % 2 == 1 {
            // long identifiers may break anywhere; short ones never
            let class = if part.chars().count() > LONG_CODE {
                " class=\"long\""
            } else {
                ""
            };
            let _ = write!(out, "<code{class}>{}</code>", escape(part));
            continue;
        }
        for (j, q) in part.split("**").enumerate() {
            let q = links(q);
            if j % 2 == 1 {
                let class = match q.as_str() {
                    s if s.starts_with("no") => " class=\"no\"",
                    s if s.starts_with("yes") => " class=\"yes\"",
                    _ => "",
                };
                let _ = write!(out, "<b{class}>{q}</b>");
            } else {
                out.push_str(&q);
            }
        }
    }
    out
}

/// Escape text and turn `[label](#id)` into links.
fn links(t: &str) -> String {
    let mut out = String::new();
    let mut rest = t;
    while let Some(i) = rest.find('[') {
        out.push_str(&escape(&rest[..i]));
        let after = &rest[i..];
        match link_at(after) {
            Some((label, id, len)) => {
                let _ = write!(out, "<a href=\"#{}\">{}</a>", escape(id), escape(label));
                rest = &after[len..];
            }
            None => {
                out.push('[');
                rest = &after[1..];
            }
        }
    }
    out.push_str(&escape(rest));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn html_escapes_text_links_anchors_and_inlines_figures_as_data_uris() {
        let mut d = Doc::default();
        d.contents();
        let a = d.h(2, "Δω against ψ <1>");
        d.p("x < y, `a<b>`, **no**, see [the figure](#figure-f)");
        d.table(&["a", "b"], vec![vec!["1|2".into(), "0.5".into()]]);
        let f = d.figure(
            "f.svg",
            "cap & more",
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"100\" height=\"50\"></svg>".into(),
        );
        assert_eq!(a, "δω-against-ψ-1");
        assert_eq!(f, "figure-f");
        let html = d.to_html("t");
        assert!(
            html.contains("<h2 id=\"δω-against-ψ-1\">Δω against ψ &lt;1&gt;</h2>"),
            "{html}"
        );
        assert!(html.contains("x &lt; y, <code>a&lt;b&gt;</code>, <b class=\"no\">no</b>, see <a href=\"#figure-f\">the figure</a>"), "{html}");
        assert!(
            html.contains("<td>1|2</td><td class=\"num\">0.5</td>"),
            "{html}"
        );
        d.p("`a_very_long_identifier_that_must_wrap_somewhere`");
        assert!(d.to_html("t").contains("<code class=\"long\">a_very_long"));
        assert!(html.contains("<figure id=\"figure-f\"><img src=\"data:image/svg+xml;base64,"));
        assert!(html.contains("width=\"100\" height=\"50\" alt=\"cap &amp; more\""));
        assert!(html.contains("<a href=\"#δω-against-ψ-1\">Δω against ψ &lt;1&gt;</a>"));
        let md = d.to_markdown();
        assert!(md.contains("| 1\\|2 | 0.5 |"));
        assert!(md.contains("<a id=\"figure-f\"></a>\n\n![cap & more](f.svg)"));
        assert!(md.contains("- [Δω against ψ <1>](#δω-against-ψ-1)"));
        assert_eq!(d.figures().count(), 1);
        assert_eq!(d.h(2, "Δω against ψ <1>"), "δω-against-ψ-1-1");
    }

    /// Issue 19 §2: text from a file shows literally in both renderings: in HTML it is the
    /// escaped text (no tag, bold, code or link of its making), [`plain`] gives it back (control
    /// characters shown escaped, line breaks as spaces), and in Markdown every active character
    /// is backslash-escaped.
    #[test]
    fn study_text_shows_literally_in_html_and_markdown() {
        let hostile = [
            "<script>alert(1)</script>",
            "**bold** `code` [x](#y) ![i](#z) &amp; _u_ ~~s~~ | pipe",
            "- item",
            "1. first",
            "# heading",
            "a\u{1b}[31mb\u{7}\r\nc\td",
            "\\* backslash \\",
            "private \u{e02a} use",
            "deg_per_h/(g)",
        ];
        for h in hostile {
            let t = text(h);
            let flat = h.replace("\r\n", " ").replace(['\n', '\t'], " ");
            let shown = study::fmt::visible(&flat).replace('\u{e02a}', "\\u{e02a}");
            assert_eq!(plain(&t), shown, "{h:?}");
            assert_eq!(inline(&t), escape(&shown), "{h:?}");
            assert!(!t.chars().any(study::fmt::is_unsafe_char), "{t:?}");
            let mut d = Doc::default();
            d.p(t.clone());
            d.table(&["a"], vec![vec![t.clone()]]);
            let html = d.to_html("x");
            assert!(
                !html.contains("<script") && !html.contains("<b>") && !html.contains("href=\"#y\"")
            );
        }
        assert_eq!(text("a<b>&c*_`[]#~"), "a\\<b\\>\\&c\\*\\_\\`\\[\\]\\#\\~");
        assert_eq!(text("- x"), "\\- x");
        assert_eq!(text("12. x"), "12\\. x");
        assert_eq!(code("my study;echo.toml"), "`my study;echo.toml`");
        assert_eq!(code("a`b"), "a\\`b");
        assert_eq!(plain(&code("a\nb")), "a\\nb");
        let mut d = Doc::default();
        d.h(1, format!("Report: {}", text("my_study")));
        assert!(
            d.to_html("Report: my\\_study")
                .contains("<title>Report: my_study</title>")
        );
        assert!(d.to_markdown().starts_with("# Report: my\\_study"));
    }

    #[test]
    fn base64_matches_rfc4648_vectors() {
        for (i, o) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(i.as_bytes()), o);
        }
    }
}
