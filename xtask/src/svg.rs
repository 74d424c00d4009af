//! Stack several SVG documents vertically into one.

/// Width and height attributes of an SVG document (pixels).
fn size(svg: &str) -> (f64, f64) {
    let attr = |name: &str| -> f64 {
        let key = format!("{name}=\"");
        svg.find("<svg")
            .and_then(|s| svg[s..].find(&key).map(|i| s + i + key.len()))
            .and_then(|start| {
                svg[start..]
                    .find('"')
                    .and_then(|end| svg[start..start + end].trim_end_matches("px").parse().ok())
            })
            .unwrap_or(0.0)
    };
    (attr("width"), attr("height"))
}

/// One SVG document containing `parts` one below the other.
pub fn stack(parts: &[String]) -> String {
    let mut y = 0.0;
    let mut width: f64 = 0.0;
    let mut body = String::new();
    for p in parts {
        let (w, h) = size(p);
        let inner = p.find("<svg").map_or(p.as_str(), |i| &p[i..]);
        // Re-anchor the nested document at its offset.
        body.push_str(&inner.replacen("<svg", &format!("<svg x=\"0\" y=\"{y}\""), 1));
        body.push('\n');
        y += h;
        width = width.max(w);
    }
    format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{width}\" height=\"{y}\" viewBox=\"0 0 {width} {y}\">\n{body}</svg>\n"
    )
}

#[cfg(test)]
mod tests {
    #[test]
    fn stacked_document_has_summed_height_and_both_parts() {
        let a = "<?xml version=\"1.0\"?><svg width=\"100\" height=\"50\" xmlns=\"http://www.w3.org/2000/svg\"><rect/></svg>".to_string();
        let b =
            "<svg width=\"80\" height=\"30\" xmlns=\"http://www.w3.org/2000/svg\"><circle/></svg>"
                .to_string();
        let s = super::stack(&[a, b]);
        assert!(s.contains("width=\"100\" height=\"80\""));
        assert!(s.contains("<svg x=\"0\" y=\"50\" width=\"80\""));
        assert_eq!(s.matches("<svg").count(), 3);
    }
}
