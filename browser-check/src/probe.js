// Evaluated in the loaded page by browser-check (Runtime.evaluate, returnByValue).
// Returns one JSON-able object; see `Probe` in src/lib.rs for the fields.
(() => {
  const de = document.documentElement;
  const body = document.body;
  const clip = (s, n) => {
    s = (s || "").replace(/\s+/g, " ").trim();
    return s.length > n ? s.slice(0, n - 1) + "\u2026" : s;
  };
  const headings = Array.from(document.querySelectorAll("h1,h2,h3,h4,h5,h6"));
  // text of the last heading that comes before `el` in document order
  const headingBefore = (el) => {
    let best = null;
    for (const h of headings) {
      if (h === el || h.contains(el)) { best = h; continue; }
      if (h.compareDocumentPosition(el) & Node.DOCUMENT_POSITION_FOLLOWING) best = h; else break;
    }
    return best ? clip(best.textContent, 80) : null;
  };
  // short CSS path, e.g. "body > table:nth-of-type(3)"
  const cssPath = (el) => {
    const parts = [];
    for (let e = el; e && e.nodeType === 1 && parts.length < 5; e = e.parentElement) {
      const tag = e.tagName.toLowerCase();
      if (e.id) { parts.unshift(tag + "#" + CSS.escape(e.id)); break; }
      if (e === body || e === de) { parts.unshift(tag); break; }
      let part = tag;
      const p = e.parentElement;
      if (p) {
        const same = Array.from(p.children).filter((c) => c.tagName === e.tagName);
        if (same.length > 1) part += ":nth-of-type(" + (same.indexOf(e) + 1) + ")";
      }
      parts.unshift(part);
    }
    return parts.join(" > ");
  };
  const px = (v) => Math.round(v * 10) / 10;

  const viewportWidth = de.clientWidth; // the window minus its vertical scrollbar
  const result = {
    title: document.title,
    url: location.href,
    inner_width: window.innerWidth,
    inner_height: window.innerHeight,
    client_width: de.clientWidth,
    scroll_width: Math.max(de.scrollWidth, body ? body.scrollWidth : 0),
    scroll_height: Math.max(de.scrollHeight, body ? body.scrollHeight : 0),
    inline_svgs: document.querySelectorAll("svg:not(svg svg)").length,
    images: [],
    links: [],
    wide: [],
  };

  // --- images: <img>, <object>, <embed>, <input type=image>
  for (const img of document.querySelectorAll("img, input[type=image]")) {
    const r = img.getBoundingClientRect();
    result.images.push({
      tag: img.tagName.toLowerCase(),
      src: img.getAttribute("src") || "",
      resolved: img.currentSrc || img.src || "",
      natural_width: img.naturalWidth || 0,
      natural_height: img.naturalHeight || 0,
      rendered_width: px(r.width),
      rendered_height: px(r.height),
      alt: img.getAttribute("alt"),
      heading: headingBefore(img),
    });
  }
  for (const o of document.querySelectorAll("object, embed")) {
    const tag = o.tagName.toLowerCase();
    const src = o.getAttribute(tag === "object" ? "data" : "src") || "";
    let resolved = "";
    try { resolved = new URL(src, document.baseURI).href; } catch (e) { resolved = src; }
    // the embedded document: readable for file:// pages thanks to
    // --allow-file-access-from-files; null when the resource did not load
    let nw = 0, nh = 0;
    try {
      const d = o.contentDocument || (o.getSVGDocument ? o.getSVGDocument() : null);
      const root = d && d.documentElement;
      if (root) {
        if (root.width && root.width.baseVal && root.viewBox) {
          // SVG: width attribute, else the viewBox, else the layout box
          const w = root.width.baseVal, h = root.height.baseVal;
          const vb = root.viewBox.baseVal;
          const pct = SVGLength.SVG_LENGTHTYPE_PERCENTAGE;
          nw = (w.unitType !== pct && w.value) || (vb && vb.width) || root.getBoundingClientRect().width;
          nh = (h.unitType !== pct && h.value) || (vb && vb.height) || root.getBoundingClientRect().height;
        } else {
          nw = root.scrollWidth;
          nh = root.scrollHeight;
        }
      }
    } catch (e) { /* cross-origin: leave 0 */ }
    const r = o.getBoundingClientRect();
    result.images.push({
      tag, src, resolved,
      natural_width: Math.round(nw), natural_height: Math.round(nh),
      rendered_width: px(r.width), rendered_height: px(r.height),
      alt: null,
      heading: headingBefore(o),
    });
  }

  // --- internal links: href="#id", or this document's URL plus a fragment
  const here = location.href.split("#")[0];
  for (const a of document.querySelectorAll("a[href], area[href]")) {
    const href = a.getAttribute("href");
    const sameDoc = href.startsWith("#") || (a.href.split("#")[0] === here && a.href.includes("#"));
    if (!sameDoc) continue;
    let frag = a.href.includes("#") ? a.href.slice(a.href.indexOf("#") + 1) : "";
    try { frag = decodeURIComponent(frag); } catch (e) { /* keep raw */ }
    // HTML: "" and "top" scroll to the top; otherwise an id, else an <a name>
    const ok = frag === "" || frag.toLowerCase() === "top" ||
      document.getElementById(frag) !== null ||
      Array.from(document.getElementsByName(frag)).some((e) => e.tagName === "A");
    result.links.push({ href, target: frag, resolves: ok, text: clip(a.textContent, 60) });
  }

  // --- elements wider than the window (or sticking out of its right edge)
  const limit = viewportWidth + 0.5;
  const clippedByAncestor = (el) => {
    for (let p = el.parentElement; p && p !== body && p !== de; p = p.parentElement) {
      const s = getComputedStyle(p);
      if (s.overflowX !== "visible") return true; // hidden, clip, auto, scroll
    }
    return false;
  };
  const candidates = new Set();
  const all = body ? [body, ...body.getElementsByTagName("*")] : [];
  for (const el of all) {
    const r = el.getBoundingClientRect();
    if (r.width === 0 && r.height === 0) continue;
    const right = r.right + window.scrollX;
    if ((right > limit || r.width > limit) && !clippedByAncestor(el)) candidates.add(el);
  }
  const outermost = Array.from(candidates).filter((el) => !candidates.has(el.parentElement));
  outermost.sort((a, b) => b.getBoundingClientRect().right - a.getBoundingClientRect().right);
  for (const el of outermost.slice(0, 20)) {
    const r = el.getBoundingClientRect();
    const w = {
      tag: el.tagName.toLowerCase(),
      id: el.id || null,
      class: (typeof el.className === "string" && el.className) ? el.className : null,
      selector: cssPath(el),
      heading: headingBefore(el),
      left: px(r.left + window.scrollX),
      top: px(r.top + window.scrollY),
      height: px(r.height),
      right: px(r.right + window.scrollX),
      width: px(r.width),
      text: clip(el.textContent, 80),
      columns: [],
    };
    if (el.tagName === "TABLE" && el.rows.length > 0) {
      const head = el.tHead && el.tHead.rows.length ? el.tHead.rows[0] : el.rows[0];
      Array.from(head.cells).forEach((c, i) => {
        // the widest unbreakable piece of the column (min-content), to tell a
        // column that cannot wrap from one that merely could be narrower
        let minContent = 0;
        for (const row of el.rows) {
          const cell = row.cells[i];
          if (!cell) continue;
          const probe = cell.cloneNode(true);
          probe.style.cssText = "position:absolute;visibility:hidden;width:min-content;white-space:normal";
          cell.parentElement.appendChild(probe);
          minContent = Math.max(minContent, probe.getBoundingClientRect().width);
          probe.remove();
        }
        w.columns.push({
          index: i,
          header: clip(c.textContent, 40),
          width: px(c.getBoundingClientRect().width),
          min_content_width: px(minContent),
        });
      });
    }
    result.wide.push(w);
  }
  return result;
})()
