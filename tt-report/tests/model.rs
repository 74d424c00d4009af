//! A document built in code renders the expected Markdown and HTML: headings and their
//! anchors, paragraphs, callouts, lists, tables, math, code, links and figures (linked SVG
//! files in Markdown, data URIs in HTML).

use tt_report::{Block, Doc, doc};

const SVG: &str = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"640\" height=\"480\"><rect width=\"10\" height=\"10\"/></svg>";

/// A small report with one block of each kind.
fn sample() -> Doc {
    let mut d = Doc::default();
    d.h(1, "Turntable error allocation: demo");
    d.contents();
    d.h(2, "The answer");
    d.callout_list(
        "**yes**: the box meets the requirement (rule: `worst case ≤ I`).",
        vec!["Δψ: 0.0261 deg".into(), "Δθ: 0.0263 deg".into()],
    );
    d.h(3, "Math and code");
    d.p("The requirement is $I = 0.027$ deg; see [the figure](#figure-mc-hist).");
    d.code("cargo xtask report --study studies/demo.toml");
    d.list(vec!["first".into(), "`second_one`".into()]);
    d.table(
        &["error", "bound (arcsec)", "share"],
        vec![
            vec!["`delta_x`".into(), "12.5".into(), "40%".into()],
            vec!["`delta_y`".into(), "-".into(), "none".into()],
        ],
    );
    d.figure("mc_hist.svg", "Distribution (**red**: ±I).", SVG.into());
    d
}

#[test]
fn markdown_has_every_block_in_order_with_github_anchors_and_linked_figures() {
    let md = sample().to_markdown();
    let expected = "\
# Turntable error allocation: demo

**Contents**

- [The answer](#the-answer)
  - [Math and code](#math-and-code)

## The answer

> **yes**: the box meets the requirement (rule: `worst case ≤ I`).
>
> - Δψ: 0.0261 deg
> - Δθ: 0.0263 deg

### Math and code

The requirement is $I = 0.027$ deg; see [the figure](#figure-mc-hist).

```text
cargo xtask report --study studies/demo.toml
```

- first
- `second_one`

| error | bound (arcsec) | share |
|---|---|---|
| `delta_x` | 12.5 | 40% |
| `delta_y` | - | none |

<a id=\"figure-mc-hist\"></a>

![Distribution (red: ±I).](mc_hist.svg)

*Distribution (**red**: ±I).*

";
    assert_eq!(md, expected);
}

#[test]
fn html_is_one_page_with_contents_classes_and_figures_as_data_uris() {
    let d = sample();
    let html = d.to_html("Turntable error allocation: demo");
    assert!(html.starts_with("<!DOCTYPE html>\n<html lang=\"en\">"));
    assert!(html.contains("<title>Turntable error allocation: demo</title>"));
    assert!(html.ends_with("</main></body></html>\n"));
    // headings carry their anchors; the contents link them, level 3 nested under level 2
    assert!(html.contains("<h2 id=\"the-answer\">The answer</h2>"));
    assert!(html.contains(
        "<nav class=\"toc\"><p><b>Contents</b></p><ul>\n<li><a href=\"#the-answer\">The answer</a><ul><li><a href=\"#math-and-code\">Math and code</a></li>\n</ul></li>\n</ul></nav>"
    ), "{html}");
    // a verdict gets its colour; code spans stay code
    assert!(html.contains(
        "<div class=\"callout\"><p><b class=\"yes\">yes</b>: the box meets the requirement (rule: <code>worst case ≤ I</code>).</p><ul><li>Δψ: 0.0261 deg</li><li>Δθ: 0.0263 deg</li></ul></div>"
    ), "{html}");
    // math is left to the reader as written; internal links are links
    assert!(html.contains(
        "<p>The requirement is $I = 0.027$ deg; see <a href=\"#figure-mc-hist\">the figure</a>.</p>"
    ));
    assert!(html.contains("<pre>cargo xtask report --study studies/demo.toml</pre>"));
    assert!(html.contains("<ul>\n<li>first</li>\n<li><code>second_one</code></li>\n</ul>"));
    // numeric columns right-aligned ("-" and "none" do not count), others not
    assert!(html.contains(
        "<tr><td><code>delta_x</code></td><td class=\"num\">12.5</td><td class=\"num\">40%</td></tr>"
    ), "{html}");
    assert!(html.contains(
        "<tr><td><code>delta_y</code></td><td class=\"num\">-</td><td class=\"num\">none</td></tr>"
    ));
    // the figure: the SVG itself as base64, its size, its caption as alt text and figcaption
    let start = html
        .find("<img src=\"data:image/svg+xml;base64,")
        .expect("an inline figure")
        + "<img src=\"data:image/svg+xml;base64,".len();
    let end = start + html[start..].find('"').unwrap();
    let decoded = data_encoding::BASE64.decode(&html.as_bytes()[start..end]);
    assert_eq!(decoded.as_deref(), Ok(SVG.as_bytes()));
    assert!(html[end..].starts_with(
        "\" width=\"640\" height=\"480\" alt=\"Distribution (red: ±I).\"><figcaption>Distribution (<b>red</b>: ±I).</figcaption></figure>"
    ), "{}", &html[end..]);
}

#[test]
fn anchors_are_unique_and_the_model_lists_its_figures() {
    let mut d = sample();
    assert_eq!(d.h(2, "The answer"), "the-answer-1");
    assert_eq!(
        d.figure("mc_hist.svg", "again", SVG.into()),
        "figure-mc-hist-1"
    );
    assert_eq!(
        d.anchors(),
        [
            "turntable-error-allocation-demo",
            "the-answer",
            "math-and-code",
            "figure-mc-hist",
            "the-answer-1",
            "figure-mc-hist-1"
        ]
    );
    let figures: Vec<(&str, &str)> = d.figures().collect();
    assert_eq!(figures, [("mc_hist.svg", SVG), ("mc_hist.svg", SVG)]);
    assert!(matches!(d.blocks.last(), Some(Block::Figure { caption, .. }) if caption == "again"));
}

#[test]
fn slug_and_plain_drop_markup_and_keep_letters_of_any_script() {
    assert_eq!(doc::slug("Δω against ψ <1>"), "δω-against-ψ-1");
    assert_eq!(doc::slug("The `two-step` **box**"), "the-two-step-box");
    assert_eq!(
        doc::plain("see [the figure](#f), `x_y` and **no**"),
        "see the figure, x_y and no"
    );
    assert_eq!(doc::plain("a\\*b\\_c"), "a*b_c");
    // an empty list adds no block
    let mut d = Doc::default();
    d.list(Vec::new());
    assert!(d.blocks.is_empty());
}
