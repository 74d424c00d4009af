//! Hostile text from a study (its description, a unit, a path, a sheet's name) enters a
//! document through `doc::text` or `doc::code` and then shows literally in both renderings:
//! no raw HTML, no script, no heading, list, link, bold or code span of its making, no raw
//! control character.

use tt_report::{Doc, doc};

const HOSTILE: &[&str] = &[
    "<script>alert(1)</script>",
    "<img src=x onerror=alert(2)>",
    "**bold** `code` [x](#y) ![i](#z) &amp; _u_ ~~s~~ | pipe",
    "[forged](javascript:alert(3)) <https://example.invalid>",
    "- item",
    "1. first",
    "# heading",
    "> quote",
    "    indented",
    "a\u{1b}[31mb\u{7}\r\nc\td\u{202e}e",
    "\\* backslash \\",
    "x\n# heading after a break\n- and a list",
];

/// The Markdown of `t` rendered by a CommonMark renderer (as a reader's viewer would).
fn commonmark(md: &str) -> String {
    let mut html = String::new();
    pulldown_cmark::html::push_html(
        &mut html,
        pulldown_cmark::Parser::new_ext(md, pulldown_cmark::Options::ENABLE_TABLES),
    );
    html
}

/// No markup of the hostile text's making in an HTML page.
fn assert_nothing_forged(what: &str, html: &str) {
    for raw in [
        "<script",
        "<img src=x",
        "<strong>bold",
        "<b>bold",
        "<em>u",
        "<del>s",
        "href=\"#y\"",
        "href=\"javascript",
        "href=\"https://example",
        "<h1>heading",
        "<h1>Heading",
        "<code>code</code>",
        "<blockquote>\n<p>quote",
        "<li>item",
        "<li>first",
        "<pre><code>indented",
    ] {
        assert!(!html.contains(raw), "{what}: carries `{raw}`\n{html}");
    }
    assert!(
        !html
            .chars()
            .any(|c| c == '\u{1b}' || c == '\u{7}' || c == '\u{202e}'),
        "{what}: a raw control or bidirectional character"
    );
}

#[test]
fn hostile_study_text_shows_literally_in_html_and_in_rendered_markdown() {
    let mut d = Doc::default();
    for h in HOSTILE {
        d.h(2, doc::text(h));
        d.p(doc::text(h));
        d.callout_list(doc::text(h), vec![doc::text(h)]);
        d.list(vec![doc::text(h), doc::code(h)]);
        d.table(&["a", "b"], vec![vec![doc::text(h), doc::code(h)]]);
        d.figure(
            "f.svg",
            doc::text(h),
            "<svg width=\"1\" height=\"1\"></svg>".into(),
        );
    }
    let html = d.to_html(&doc::text(HOSTILE[0]));
    assert_nothing_forged("report.html", &html);
    assert!(html.contains("<title>&lt;script&gt;alert(1)&lt;/script&gt;</title>"));
    let md = d.to_markdown();
    assert_nothing_forged("report.md rendered", &commonmark(&md));
    // each text shows as written (escaped for HTML) in the page and the rendered Markdown
    for shown in [
        "&lt;script&gt;alert(1)&lt;/script&gt;",
        "&lt;img src=x onerror=alert(2)&gt;",
        "**bold** `code` [x](#y) ![i](#z) &amp;amp; _u_ ~~s~~ | pipe",
        "[forged](javascript:alert(3)) &lt;https://example.invalid&gt;",
        "# heading",
        "&gt; quote",
        "a\\u{1b}[31mb\\u{7} c d\\u{202e}e",
        "x # heading after a break - and a list",
    ] {
        assert!(html.contains(shown), "report.html does not show `{shown}`");
        assert!(
            commonmark(&md).contains(shown),
            "report.md does not show `{shown}`"
        );
    }
}

#[test]
fn text_and_code_escape_only_what_markdown_would_read() {
    assert_eq!(
        doc::text("a<b>&c*_`[]#~"),
        "a\\<b\\>\\&c\\*\\_\\`\\[\\]\\#\\~"
    );
    assert_eq!(doc::text("- x"), "\\- x");
    assert_eq!(doc::text("12. x"), "12\\. x");
    assert_eq!(doc::text("deg/h (g) 3.5"), "deg/h (g) 3.5");
    assert_eq!(doc::code("my study;echo.toml"), "`my study;echo.toml`");
    assert_eq!(doc::code("a`b"), "a\\`b");
    assert_eq!(doc::code(""), "");
    assert_eq!(doc::plain(&doc::code("a\nb")), "a\\nb");
}

#[test]
fn a_heading_from_study_text_gets_an_anchor_of_its_plain_text() {
    let mut d = Doc::default();
    let id = d.h(2, format!("Study {}", doc::text("my_study <v2>")));
    assert_eq!(id, "study-my_study-v2");
    let html = d.to_html("t");
    assert!(html.contains("<h2 id=\"study-my_study-v2\">Study my_study &lt;v2&gt;</h2>"));
}
