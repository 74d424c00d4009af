//! A small document model rendered both as Markdown (figures as linked SVG files) and as a
//! self-contained HTML page (figures inline).

use std::fmt::Write as _;

/// One block of the report.
#[derive(Debug, Clone)]
pub enum Block {
    /// A heading of level 1-4.
    Heading(u8, String),
    /// A paragraph of plain text (`code` spans in backticks are kept).
    Paragraph(String),
    /// A bulleted list.
    List(Vec<String>),
    /// A table: header and rows of cells.
    Table(Vec<String>, Vec<Vec<String>>),
    /// A figure: file name, caption, SVG text.
    Figure(String, String, String),
    /// Preformatted text.
    Code(String),
}

/// The report: an ordered list of blocks.
#[derive(Debug, Clone, Default)]
pub struct Report {
    /// The blocks in reading order.
    pub blocks: Vec<Block>,
}

impl Report {
    /// Append a heading.
    pub fn h(&mut self, level: u8, text: impl Into<String>) {
        self.blocks.push(Block::Heading(level, text.into()));
    }
    /// Append a paragraph.
    pub fn p(&mut self, text: impl Into<String>) {
        self.blocks.push(Block::Paragraph(text.into()));
    }
    /// Append a list.
    pub fn list(&mut self, items: Vec<String>) {
        self.blocks.push(Block::List(items));
    }
    /// Append a table.
    pub fn table(&mut self, header: &[&str], rows: Vec<Vec<String>>) {
        self.blocks.push(Block::Table(
            header.iter().map(|s| s.to_string()).collect(),
            rows,
        ));
    }
    /// Append a figure.
    pub fn figure(&mut self, file: &str, caption: impl Into<String>, svg: String) {
        self.blocks
            .push(Block::Figure(file.to_string(), caption.into(), svg));
    }
    /// Append preformatted text.
    pub fn code(&mut self, text: impl Into<String>) {
        self.blocks.push(Block::Code(text.into()));
    }

    /// The figures (file name, SVG) to write beside the Markdown.
    pub fn figures(&self) -> impl Iterator<Item = (&str, &str)> {
        self.blocks.iter().filter_map(|b| match b {
            Block::Figure(f, _, svg) => Some((f.as_str(), svg.as_str())),
            _ => None,
        })
    }

    /// Markdown rendering; figures are linked by file name.
    pub fn to_markdown(&self) -> String {
        let mut s = String::new();
        for b in &self.blocks {
            match b {
                Block::Heading(l, t) => {
                    let _ = writeln!(s, "{} {t}\n", "#".repeat(usize::from(*l)));
                }
                Block::Paragraph(t) => {
                    let _ = writeln!(s, "{t}\n");
                }
                Block::List(items) => {
                    for i in items {
                        let _ = writeln!(s, "- {i}");
                    }
                    s.push('\n');
                }
                Block::Table(h, rows) => {
                    let cell = |c: &String| c.replace('|', "\\|");
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
                Block::Figure(f, cap, _) => {
                    let _ = writeln!(s, "![{cap}]({f})\n\n*{cap}*\n");
                }
                Block::Code(t) => {
                    let _ = writeln!(s, "```text\n{t}\n```\n");
                }
            }
        }
        s
    }

    /// Self-contained HTML rendering with the SVG figures inline.
    pub fn to_html(&self, title: &str) -> String {
        let mut s = format!(
            "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{}</title>\n<style>\
             body{{font-family:sans-serif;max-width:1000px;margin:2em auto;line-height:1.45;padding:0 1em}}\
             table{{border-collapse:collapse;margin:1em 0;font-size:0.92em}}\
             td,th{{border:1px solid #bbb;padding:3px 7px;text-align:left;vertical-align:top}}\
             th{{background:#eee}} code,pre{{background:#f5f5f5}} pre{{padding:0.6em;overflow-x:auto}}\
             figure{{margin:1em 0}} figcaption{{font-style:italic}} svg{{max-width:100%;height:auto}}\
             </style></head><body>\n",
            escape(title)
        );
        for b in &self.blocks {
            match b {
                Block::Heading(l, t) => {
                    let _ = writeln!(s, "<h{l}>{}</h{l}>", inline(t));
                }
                Block::Paragraph(t) => {
                    let _ = writeln!(s, "<p>{}</p>", inline(t));
                }
                Block::List(items) => {
                    s.push_str("<ul>\n");
                    for i in items {
                        let _ = writeln!(s, "<li>{}</li>", inline(i));
                    }
                    s.push_str("</ul>\n");
                }
                Block::Table(h, rows) => {
                    s.push_str("<table><thead><tr>");
                    for c in h {
                        let _ = write!(s, "<th>{}</th>", inline(c));
                    }
                    s.push_str("</tr></thead><tbody>\n");
                    for r in rows {
                        s.push_str("<tr>");
                        for c in r {
                            let _ = write!(s, "<td>{}</td>", inline(c));
                        }
                        s.push_str("</tr>\n");
                    }
                    s.push_str("</tbody></table>\n");
                }
                Block::Figure(_, cap, svg) => {
                    let body = svg.find("<svg").map_or(svg.as_str(), |i| &svg[i..]);
                    let _ = writeln!(
                        s,
                        "<figure>{body}<figcaption>{}</figcaption></figure>",
                        inline(cap)
                    );
                }
                Block::Code(t) => {
                    let _ = writeln!(s, "<pre>{}</pre>", escape(t));
                }
            }
        }
        s.push_str("</body></html>\n");
        s
    }
}

fn escape(t: &str) -> String {
    t.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// Escape, then turn `code` spans and **bold** into HTML.
fn inline(t: &str) -> String {
    let e = escape(t);
    let mut out = String::new();
    for (k, part) in e.split('`').enumerate() {
        if k % 2 == 1 {
            let _ = write!(out, "<code>{part}</code>");
        } else {
            for (j, q) in part.split("**").enumerate() {
                if j % 2 == 1 {
                    let _ = write!(out, "<b>{q}</b>");
                } else {
                    out.push_str(q);
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn html_escapes_text_and_inlines_figures() {
        let mut r = Report::default();
        r.h(1, "A <title>");
        r.p("x < y and `code` and **bold**");
        r.table(&["a", "b"], vec![vec!["1|2".into(), "3".into()]]);
        r.figure("f.svg", "cap", "<?xml version=\"1.0\"?><svg></svg>".into());
        let html = r.to_html("t");
        assert!(html.contains("<h1>A &lt;title&gt;</h1>"));
        assert!(html.contains("x &lt; y and <code>code</code> and <b>bold</b>"));
        assert!(html.contains("<figure><svg></svg>"));
        let md = r.to_markdown();
        assert!(md.contains("| 1\\|2 | 3 |"));
        assert!(md.contains("![cap](f.svg)"));
        assert_eq!(r.figures().count(), 1);
    }
}
