//! The report as a document: an ordered list of blocks rendered both as Markdown (figures as
//! linked SVG files) and as one self-contained HTML page (figures inline as data URIs, a
//! table of contents, tables that fit a 1280 px window).
//!
//! Inline markup in text is CommonMark's (`` `code` ``, `**bold**`, links `[text](#id)`,
//! backslash escapes: `\*` is a literal `*`), parsed and written to HTML by pulldown-cmark;
//! raw HTML in a text is shown as text, never let through.
//! Text from a file (a study's description, units, paths, a tolerance sheet's name) enters a
//! document only through [`text`] or [`code`]: it then shows literally in both renderings, never
//! as markup, raw HTML or a raw control character.

use pulldown_cmark::{Event, Options, Parser, Tag, TagEnd};
use std::fmt::Write as _;
use std::ops::Range;

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

/// The characters [`text`] escapes anywhere: Markdown's inline markup, raw HTML and entities.
/// (`|` is escaped by the table renderer, which knows where it matters.)
const MD_ACTIVE: &[char] = &['\\', '`', '*', '_', '[', ']', '<', '>', '&', '~', '#'];

/// Text from a file, as literal document text: line breaks and tabs become spaces, control
/// and bidirectional characters are shown escaped ([`tt_core::human::visible`]), and every
/// character that Markdown or HTML would read as structure is backslash-escaped (as are `-`,
/// `+`, `=` at the start, and `.`/`)` after leading digits: list and heading markers). Both
/// renderings then show exactly the text.
#[must_use]
pub fn text(s: &str) -> String {
    let flat = s.replace("\r\n", " ").replace(['\n', '\t'], " ");
    let shown = tt_core::human::visible(&flat);
    let mut out = String::with_capacity(shown.len() + 8);
    let digits = shown.chars().take_while(char::is_ascii_digit).count();
    for (i, c) in shown.chars().enumerate() {
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
    let shown = tt_core::human::visible(s);
    if shown.contains('`') || shown.is_empty() {
        text(&shown)
    } else {
        format!("`{shown}`")
    }
}

/// A no-break space put before a text while it is parsed: CommonMark reads it as white space
/// (delimiters after it open as at a line's start) but never as indentation, so a text is
/// parsed as inline content only (a leading `-`, `#`, `1.` or `>` is text, not a block).
const INLINE_ONLY: char = '\u{a0}';

/// The CommonMark inline content of one document text, with each event's source range (in
/// `src`, which is the text behind [`INLINE_ONLY`]). Raw HTML is never let through: it comes
/// back as text. Block structure (only possible after a line break) is dropped.
fn inline_events(src: &str) -> impl Iterator<Item = (Event<'_>, Range<usize>)> {
    let mut first = true;
    Parser::new_ext(src, Options::empty())
        .into_offset_iter()
        .filter_map(move |(e, r)| {
            let e = match e {
                Event::Text(t) if first => {
                    first = false;
                    let t = t.strip_prefix(INLINE_ONLY).unwrap_or(&t).to_string();
                    if t.is_empty() {
                        return None;
                    }
                    Event::Text(t.into())
                }
                Event::Html(t) | Event::InlineHtml(t) => Event::Text(t),
                Event::Start(Tag::Strong | Tag::Emphasis | Tag::Link { .. })
                | Event::End(TagEnd::Strong | TagEnd::Emphasis | TagEnd::Link)
                | Event::Text(_)
                | Event::Code(_)
                | Event::SoftBreak
                | Event::HardBreak => e,
                // paragraphs, images (their text stays), blocks after a line break
                _ => return None,
            };
            Some((e, r))
        })
}

/// `t` behind [`INLINE_ONLY`], for [`inline_events`].
fn inline_source(t: &str) -> String {
    format!("{INLINE_ONLY}{t}")
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
    let src = inline_source(text);
    let mut out = String::with_capacity(text.len());
    for (e, _) in inline_events(&src) {
        match e {
            Event::Text(t) | Event::Code(t) => out.push_str(&t),
            Event::SoftBreak | Event::HardBreak => out.push(' '),
            _ => {}
        }
    }
    out
}

/// [`plain`] for Markdown: the markup removed, backslash escapes and entities kept as written
/// (a link's label).
fn plain_md(text: &str) -> String {
    let src = inline_source(text);
    let mut out = String::with_capacity(text.len());
    for (e, r) in inline_events(&src) {
        match e {
            Event::Text(t) => {
                let written = src.get(r.clone()).unwrap_or_default();
                if r.start > 0 && src.as_bytes()[r.start - 1] == b'\\' {
                    // a backslash escape: the parser's range starts after the backslash
                    out.push('\\');
                    out.push_str(written);
                } else if written.starts_with(INLINE_ONLY) {
                    out.push_str(&t);
                } else {
                    out.push_str(written);
                }
            }
            Event::Code(t) => out.push_str(&t),
            Event::SoftBreak | Event::HardBreak => out.push(' '),
            _ => {}
        }
    }
    out
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
                // leading spaces would make an indented code block here too
                Block::Callout(t, items) => {
                    let _ = writeln!(s, "> {}", t.trim_start());
                    if !items.is_empty() {
                        s.push_str(">\n");
                    }
                    for i in items {
                        let _ = writeln!(s, "> - {}", i.trim_start());
                    }
                    s.push('\n');
                }
                Block::List(items) => {
                    for i in items {
                        let _ = writeln!(s, "- {}", i.trim_start());
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
                        data_encoding::BASE64.encode(svg.as_bytes()),
                        attribute(&plain(caption)),
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

/// HTML-escape text of the page's own making after [`plain`] (`&`, `<`, `>`; as the
/// CommonMark renderer escapes text).
fn escape(t: &str) -> String {
    let mut out = String::with_capacity(t.len());
    // writing into a String cannot fail
    let _ = pulldown_cmark_escape::escape_html_body_text(&mut out, t);
    out
}

/// An attribute value (`&`, `<`, `>`, `"`, `'` escaped).
fn attribute(t: &str) -> String {
    let mut out = String::with_capacity(t.len());
    let _ = pulldown_cmark_escape::escape_html(&mut out, t);
    out
}

/// The inline markup of a document text as HTML, by the CommonMark renderer: `code`,
/// **bold** (`**no**` and `**yes**`, verdicts, get a colour), links, and the text escaped; raw
/// HTML shows as text. Code spans longer than [`LONG_CODE`] characters may wrap.
fn inline(t: &str) -> String {
    let src = inline_source(t);
    let mut events: Vec<Event<'_>> = inline_events(&src).map(|(e, _)| e).collect();
    for k in 0..events.len() {
        let class = match &events[k] {
            Event::Start(Tag::Strong) => match events.get(k + 1) {
                Some(Event::Text(t)) if t.starts_with("no") => " class=\"no\"",
                Some(Event::Text(t)) if t.starts_with("yes") => " class=\"yes\"",
                _ => "",
            },
            Event::End(TagEnd::Strong) => {
                events[k] = Event::InlineHtml("</b>".into());
                continue;
            }
            // the target as written (the renderer would percent-encode a non-ASCII anchor)
            Event::Start(Tag::Link { dest_url, .. }) => {
                events[k] =
                    Event::InlineHtml(format!("<a href=\"{}\">", attribute(dest_url)).into());
                continue;
            }
            Event::End(TagEnd::Link) => {
                events[k] = Event::InlineHtml("</a>".into());
                continue;
            }
            Event::Code(c) if c.chars().count() > LONG_CODE => {
                events[k] =
                    Event::InlineHtml(format!("<code class=\"long\">{}</code>", escape(c)).into());
                continue;
            }
            _ => continue,
        };
        events[k] = Event::InlineHtml(format!("<b{class}>").into());
    }
    let mut out = String::with_capacity(t.len() + 16);
    pulldown_cmark::html::push_html(&mut out, events.into_iter());
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
            let shown = tt_core::human::visible(&flat);
            assert_eq!(plain(&t), shown, "{h:?}");
            assert_eq!(inline(&t), escape(&shown), "{h:?}");
            assert!(!t.chars().any(tt_core::human::is_unsafe_char), "{t:?}");
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
}
