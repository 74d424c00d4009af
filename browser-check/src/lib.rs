//! Checks an HTML report in a real headless Chromium.
//!
//! [`check_report`] opens a file in Debian's Chromium at a given window size,
//! waits for the load event, and returns a [`BrowserReport`]: whether the page
//! scrolls sideways (and which elements stick out), every image with its
//! natural width, the console errors and warnings seen during load, every
//! internal link and whether its target exists, and the paths of a viewport
//! and a full-page screenshot. [`BrowserReport::problems`] turns that into
//! plain sentences, empty when the page is fine.
//!
//! The browser is driven over the DevTools protocol (see `cdp.rs`); it is
//! found at run time (`$CHROMIUM`, `/usr/lib/chromium/chromium`,
//! `/usr/bin/chromium`, ...), runs with a fresh temporary profile in its own
//! process group, and is killed and its profile removed whatever happens.

mod cdp;
pub mod locate;

use std::collections::HashMap;
use std::fs;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::{Context, Result, anyhow, bail};
use serde::{Deserialize, Serialize};
use serde_json::{Value, json};

use locate::find_chromium;

/// Settings of one check. `Default` gives 1280x800, 60 s, screenshots in
/// `./browser-check-screenshots`.
#[derive(Debug, Clone)]
pub struct CheckOptions {
    /// Window (viewport) width in CSS pixels.
    pub width: u32,
    /// Window (viewport) height in CSS pixels.
    pub height: u32,
    /// Where the PNG screenshots go (created if missing).
    pub screenshot_dir: PathBuf,
    /// Upper bound for the whole check, browser start-up and shut-down included.
    pub timeout: Duration,
    /// Chromium binary; `None` looks at `$CHROMIUM` and the usual paths.
    pub chromium: Option<PathBuf>,
    /// Height cap of the full-page screenshot, in CSS pixels.
    pub max_full_page_height: u32,
    /// Where the temporary Chromium profile is created (default: the
    /// system's temporary directory). It is removed after the check.
    pub profile_parent: Option<PathBuf>,
}

impl Default for CheckOptions {
    fn default() -> Self {
        CheckOptions {
            width: 1280,
            height: 800,
            screenshot_dir: PathBuf::from("browser-check-screenshots"),
            timeout: Duration::from_secs(60),
            chromium: None,
            max_full_page_height: 16_000,
            profile_parent: None,
        }
    }
}

/// What Chromium saw on the page.
#[derive(Debug, Clone, Serialize)]
pub struct BrowserReport {
    /// The file:// URL that was opened.
    pub url: String,
    /// `document.title`.
    pub title: String,
    /// Chromium's version, e.g. `HeadlessChrome/156.0.8078.79`.
    pub browser: String,
    /// The requested window size.
    pub window: (u32, u32),
    /// `window.innerWidth` (includes the vertical scrollbar).
    pub inner_width: u32,
    /// `window.innerHeight`.
    pub inner_height: u32,
    /// `document.documentElement.clientWidth`: the width the page can use
    /// without scrolling sideways (inner width minus the vertical scrollbar).
    pub client_width: u32,
    /// `document.documentElement.scrollWidth`: the width of the whole page.
    pub scroll_width: u32,
    /// The height of the whole page.
    pub scroll_height: u32,
    /// Images: every `<img>`, `<input type=image>`, `<object>` and `<embed>`.
    pub images: Vec<ImageInfo>,
    /// Number of top-level inline `<svg>` elements (figures embedded in the HTML).
    pub inline_svgs: usize,
    /// Console messages, uncaught exceptions and browser log entries seen
    /// from the start of the load until the screenshots were taken.
    pub console: Vec<ConsoleMessage>,
    /// Sub-resources (images, styles, scripts, objects) that failed to load.
    pub failed_loads: Vec<FailedLoad>,
    /// Every internal link (`href="#id"`) and whether its target exists.
    pub links: Vec<InternalLink>,
    /// The outermost elements that are wider than the window or stick out of
    /// its right edge, widest first (at most 20).
    pub wide_elements: Vec<WideElement>,
    /// The screenshots written.
    pub screenshots: Screenshots,
    /// The temporary Chromium profile that was used (already removed).
    pub profile_dir: PathBuf,
    /// Wall-clock time of the whole check, browser start and stop included.
    pub elapsed: Duration,
}

/// One image-like element.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ImageInfo {
    /// `img`, `input`, `object` or `embed`.
    pub tag: String,
    /// The `src` (or `data`) attribute as written.
    pub src: String,
    /// The URL the browser resolved it to.
    pub resolved: String,
    /// Natural (intrinsic) width; 0 means the image did not load. For
    /// `<object>`/`<embed>` it is the embedded document's width.
    pub natural_width: u32,
    /// Natural height.
    pub natural_height: u32,
    /// Width on the page, CSS pixels.
    pub rendered_width: f64,
    /// Height on the page, CSS pixels.
    pub rendered_height: f64,
    /// The `alt` attribute, if any.
    pub alt: Option<String>,
    /// The nearest heading before the image.
    pub heading: Option<String>,
}

impl ImageInfo {
    /// True when the image (or embedded document) loaded.
    pub fn loaded(&self) -> bool {
        self.natural_width > 0
    }
}

/// How serious a console message is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Level {
    /// `console.error`, `console.assert` failures, uncaught exceptions, failed loads.
    Error,
    /// `console.warn`, browser warnings (deprecations, interventions).
    Warning,
    /// Everything else (`console.log`, `info`, `debug`, verbose entries).
    Info,
}

/// One console message.
#[derive(Debug, Clone, Serialize)]
pub struct ConsoleMessage {
    /// Error, warning or info.
    pub level: Level,
    /// `console-api` (a `console.*` call), `exception` (uncaught), or the
    /// browser's log source (`network`, `javascript`, `rendering`, ...).
    pub source: String,
    /// The message text (arguments joined by spaces).
    pub text: String,
    /// Where it came from (`url:line`), when known.
    pub location: Option<String>,
}

/// A sub-resource that failed to load.
#[derive(Debug, Clone, Serialize)]
pub struct FailedLoad {
    /// Its URL.
    pub url: String,
    /// Chromium's error, e.g. `net::ERR_FILE_NOT_FOUND`.
    pub error: String,
}

/// One internal link.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct InternalLink {
    /// The `href` attribute as written.
    pub href: String,
    /// The fragment (decoded), i.e. the id it points to.
    pub target: String,
    /// Whether an element with that id (or an `<a name>`) exists.
    pub resolves: bool,
    /// The link's text.
    pub text: String,
}

/// An element wider than the window or sticking out of its right edge.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct WideElement {
    /// Tag name, lower case.
    pub tag: String,
    /// `id` attribute.
    pub id: Option<String>,
    /// `class` attribute.
    pub class: Option<String>,
    /// A short CSS path, e.g. `body > table:nth-of-type(3)`.
    pub selector: String,
    /// The nearest heading before it (names a table when it has no id).
    pub heading: Option<String>,
    /// Left edge, page coordinates, CSS px.
    pub left: f64,
    /// Top edge, page coordinates, CSS px.
    pub top: f64,
    /// Height, CSS px.
    pub height: f64,
    /// Right edge, page coordinates, CSS px.
    pub right: f64,
    /// Width, CSS px.
    pub width: f64,
    /// The start of its text.
    pub text: String,
    /// For a table: its columns as laid out.
    pub columns: Vec<ColumnInfo>,
}

impl WideElement {
    /// A one-line description, e.g. `<table> under "Claims" (body > table:nth-of-type(3))`.
    pub fn describe(&self) -> String {
        let mut s = format!("<{}", self.tag);
        if let Some(id) = &self.id {
            s += &format!(" id=\"{id}\"");
        }
        if let Some(c) = &self.class {
            s += &format!(" class=\"{c}\"");
        }
        s += ">";
        if let Some(h) = &self.heading {
            s += &format!(" under \"{h}\"");
        }
        s + &format!(" ({})", self.selector)
    }
}

/// One column of a wide table.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ColumnInfo {
    /// 0-based position.
    pub index: usize,
    /// Header text (first row).
    pub header: String,
    /// Laid-out width, CSS px.
    pub width: f64,
    /// The width of its widest unbreakable content (min-content), CSS px:
    /// close to `width` means the column cannot be narrower without wrapping
    /// rules (e.g. a long identifier in `<code>`).
    pub min_content_width: f64,
}

/// The screenshots a check wrote.
#[derive(Debug, Clone, Serialize)]
pub struct Screenshots {
    /// What a reader sees first: the window at the requested size.
    pub viewport: PathBuf,
    /// The whole page (capped at `max_full_page_height`).
    pub full_page: PathBuf,
    /// Whether the full-page screenshot was cut at the height cap.
    pub full_page_truncated: bool,
    /// When the page scrolls sideways: the band of the page holding the
    /// widest offending element, at full page width (height capped at 4000 px).
    pub widest_element: Option<PathBuf>,
}

impl BrowserReport {
    /// True when the page scrolls sideways: the page is wider than the width
    /// available in the window (`client_width`, i.e. `innerWidth` minus the
    /// vertical scrollbar; also true whenever `scroll_width > inner_width`).
    pub fn overflows_horizontally(&self) -> bool {
        self.scroll_width > self.client_width
    }

    /// Images whose natural width is 0.
    pub fn broken_images(&self) -> impl Iterator<Item = &ImageInfo> {
        self.images.iter().filter(|i| !i.loaded())
    }

    /// Internal links whose target does not exist.
    pub fn broken_links(&self) -> impl Iterator<Item = &InternalLink> {
        self.links.iter().filter(|l| !l.resolves)
    }

    /// Console errors and warnings.
    pub fn console_problems(&self) -> impl Iterator<Item = &ConsoleMessage> {
        self.console.iter().filter(|m| m.level != Level::Info)
    }

    /// Every failed check, in plain words; empty when the page is fine.
    pub fn problems(&self) -> Vec<String> {
        let mut out = Vec::new();
        if self.overflows_horizontally() {
            let mut s = format!(
                "the page scrolls sideways at {} px: it is {} px wide but the window shows {} px",
                self.window.0, self.scroll_width, self.client_width
            );
            if let Some(w) = self.wide_elements.first() {
                s += &format!(
                    "; widest element: {}, {} px wide, right edge at {} px",
                    w.describe(),
                    w.width.round(),
                    w.right.round()
                );
                if !w.columns.is_empty() {
                    let cols: Vec<String> = w
                        .columns
                        .iter()
                        .map(|c| format!("{} {} px", c.header, c.width.round()))
                        .collect();
                    s += &format!(" (columns: {})", cols.join(", "));
                }
            }
            out.push(s);
            for w in self.wide_elements.iter().skip(1) {
                out.push(format!(
                    "also sticks out of the window: {}, {} px wide, right edge at {} px",
                    w.describe(),
                    w.width.round(),
                    w.right.round()
                ));
            }
        }
        for img in self.broken_images() {
            out.push(format!(
                "<{} {}=\"{}\"> did not load (natural width 0){}",
                img.tag,
                if img.tag == "object" { "data" } else { "src" },
                img.src,
                img.heading
                    .as_ref()
                    .map(|h| format!(", under \"{h}\""))
                    .unwrap_or_default()
            ));
        }
        for f in &self.failed_loads {
            out.push(format!("failed to load {} ({})", f.url, f.error));
        }
        for l in self.broken_links() {
            out.push(format!(
                "internal link href=\"{}\" (\"{}\") points to no element with id \"{}\"",
                l.href, l.text, l.target
            ));
        }
        for m in self.console_problems() {
            let kind = match (m.level, m.source.as_str()) {
                (_, "exception") => "uncaught exception",
                (Level::Error, _) => "console error",
                _ => "console warning",
            };
            out.push(format!(
                "{kind} ({}): {}{}",
                m.source,
                m.text,
                m.location
                    .as_ref()
                    .map(|l| format!(" at {l}"))
                    .unwrap_or_default()
            ));
        }
        out
    }
}

/// Checks `html` at `width` x `height` with a 60 s time limit, writing the
/// screenshots into `screenshot_dir`. See [`check_report_with`].
pub fn check_report(
    html: &Path,
    screenshot_dir: &Path,
    width: u32,
    height: u32,
) -> Result<BrowserReport> {
    check_report_with(
        html,
        &CheckOptions {
            width,
            height,
            screenshot_dir: screenshot_dir.to_path_buf(),
            ..CheckOptions::default()
        },
    )
}

/// Opens `html` (a local file) in headless Chromium and reports what it shows.
///
/// Errors (rather than problems in the report) are: the file is missing,
/// Chromium is not installed or does not start, the page does not load, or the
/// whole check takes longer than `opts.timeout`.
pub fn check_report_with(html: &Path, opts: &CheckOptions) -> Result<BrowserReport> {
    let start = Instant::now();
    let deadline = start + opts.timeout;
    let html = html
        .canonicalize()
        .with_context(|| format!("the report {} does not exist", html.display()))?;
    if !html.is_file() {
        bail!("{} is not a file", html.display());
    }
    let url = file_url(&html);
    let binary = find_chromium(opts.chromium.as_deref())?;
    fs::create_dir_all(&opts.screenshot_dir)
        .with_context(|| format!("creating {}", opts.screenshot_dir.display()))?;

    let mut browser = cdp::Browser::launch(
        &binary,
        (opts.width, opts.height),
        opts.profile_parent.as_deref(),
        deadline,
        opts.timeout,
    )
    .with_context(|| format!("starting {}", binary.display()))?;
    let profile_dir = browser.profile_path().to_path_buf();
    let result = run_check(&mut browser, &url, &html, opts);
    // close in every case; a close error only matters when the check worked
    let closed = browser.close();
    let (probe, console, failed_loads, screenshots, version) = result?;
    closed?;

    Ok(BrowserReport {
        url,
        title: probe.title,
        browser: version,
        window: (opts.width, opts.height),
        inner_width: probe.inner_width,
        inner_height: probe.inner_height,
        client_width: probe.client_width,
        scroll_width: probe.scroll_width,
        scroll_height: probe.scroll_height,
        images: probe.images,
        inline_svgs: probe.inline_svgs,
        console,
        failed_loads,
        links: probe.links,
        wide_elements: probe.wide,
        screenshots,
        profile_dir,
        elapsed: start.elapsed(),
    })
}

/// What `probe.js` returns.
#[derive(Debug, Deserialize)]
struct Probe {
    title: String,
    inner_width: u32,
    inner_height: u32,
    client_width: u32,
    scroll_width: u32,
    scroll_height: u32,
    inline_svgs: usize,
    images: Vec<ImageInfo>,
    links: Vec<InternalLink>,
    wide: Vec<WideElement>,
}

type CheckOutput = (
    Probe,
    Vec<ConsoleMessage>,
    Vec<FailedLoad>,
    Screenshots,
    String,
);

/// Collects console messages and failed loads from CDP events.
#[derive(Default)]
struct Collector {
    console: Vec<ConsoleMessage>,
    requests: HashMap<String, String>,
    failed: Vec<FailedLoad>,
    loaded: bool,
}

impl Collector {
    fn take(&mut self, ev: &Value, session: &str) {
        if ev["sessionId"].as_str() != Some(session) {
            return;
        }
        let p = &ev["params"];
        match ev["method"].as_str().unwrap_or("") {
            "Page.loadEventFired" => self.loaded = true,
            "Runtime.consoleAPICalled" => {
                let level = match p["type"].as_str().unwrap_or("") {
                    "error" | "assert" => Level::Error,
                    "warning" => Level::Warning,
                    _ => Level::Info,
                };
                let text = p["args"]
                    .as_array()
                    .map(|args| {
                        args.iter()
                            .map(remote_object_text)
                            .collect::<Vec<_>>()
                            .join(" ")
                    })
                    .unwrap_or_default();
                let frame = &p["stackTrace"]["callFrames"][0];
                self.console.push(ConsoleMessage {
                    level,
                    source: "console-api".into(),
                    text,
                    location: location(&frame["url"], &frame["lineNumber"]),
                });
            }
            "Runtime.exceptionThrown" => {
                let d = &p["exceptionDetails"];
                let text = d["exception"]["description"]
                    .as_str()
                    .or(d["text"].as_str())
                    .unwrap_or("exception")
                    .lines()
                    .next()
                    .unwrap_or("")
                    .to_string();
                self.console.push(ConsoleMessage {
                    level: Level::Error,
                    source: "exception".into(),
                    text,
                    location: location(&d["url"], &d["lineNumber"]),
                });
            }
            "Log.entryAdded" => {
                let e = &p["entry"];
                let level = match e["level"].as_str().unwrap_or("") {
                    "error" => Level::Error,
                    "warning" => Level::Warning,
                    _ => Level::Info,
                };
                self.console.push(ConsoleMessage {
                    level,
                    source: e["source"].as_str().unwrap_or("browser").into(),
                    text: e["text"].as_str().unwrap_or("").into(),
                    location: location(&e["url"], &e["lineNumber"]),
                });
            }
            "Network.requestWillBeSent" => {
                if let (Some(id), Some(url)) =
                    (p["requestId"].as_str(), p["request"]["url"].as_str())
                {
                    self.requests.insert(id.into(), url.into());
                }
            }
            "Network.loadingFailed" => {
                if p["canceled"].as_bool() == Some(true) {
                    return;
                }
                let url = p["requestId"]
                    .as_str()
                    .and_then(|id| self.requests.get(id).cloned())
                    .unwrap_or_else(|| "(unknown URL)".into());
                self.failed.push(FailedLoad {
                    url,
                    error: p["errorText"].as_str().unwrap_or("failed").into(),
                });
            }
            _ => {}
        }
    }
}

fn remote_object_text(o: &Value) -> String {
    match &o["value"] {
        Value::String(s) => s.clone(),
        Value::Null => o["unserializableValue"]
            .as_str()
            .or(o["description"].as_str())
            .or(o["type"].as_str())
            .unwrap_or("")
            .to_string(),
        v => v.to_string(),
    }
}

/// `url:line` (CDP line numbers are 0-based).
fn location(url: &Value, line: &Value) -> Option<String> {
    let url = url.as_str().filter(|u| !u.is_empty())?;
    match line.as_i64() {
        Some(l) => Some(format!("{url}:{}", l + 1)),
        None => Some(url.to_string()),
    }
}

fn run_check(
    browser: &mut cdp::Browser,
    url: &str,
    html: &Path,
    opts: &CheckOptions,
) -> Result<CheckOutput> {
    let target = browser.call(None, "Target.createTarget", json!({ "url": "about:blank" }))?;
    let target_id = target["targetId"]
        .as_str()
        .ok_or_else(|| anyhow!("Target.createTarget returned no targetId"))?
        .to_string();
    let attached = browser.call(
        None,
        "Target.attachToTarget",
        json!({ "targetId": target_id, "flatten": true }),
    )?;
    let session = attached["sessionId"]
        .as_str()
        .ok_or_else(|| anyhow!("Target.attachToTarget returned no sessionId"))?
        .to_string();
    let s = Some(session.as_str());
    let mut col = Collector::default();

    // listen before loading, so messages from the first script are caught
    for domain in [
        "Page.enable",
        "Runtime.enable",
        "Log.enable",
        "Network.enable",
    ] {
        browser.call(s, domain, json!({}))?;
    }
    browser.call(
        s,
        "Emulation.setDeviceMetricsOverride",
        json!({ "width": opts.width, "height": opts.height, "deviceScaleFactor": 1, "mobile": false }),
    )?;
    // anything queued so far belongs to about:blank
    browser.drain_events();

    let nav = browser.call(s, "Page.navigate", json!({ "url": url }))?;
    if let Some(err) = nav["errorText"].as_str() {
        bail!("Chromium could not open {}: {err}", html.display());
    }
    loop {
        while !col.loaded {
            let ev = browser.next_event("the page's load event")?;
            col.take(&ev, &session);
        }
        // make sure that load event was the report's, not a late one of about:blank
        let state = browser.call(
            s,
            "Runtime.evaluate",
            json!({ "expression": "location.href + ' ' + document.readyState", "returnByValue": true }),
        )?;
        let state = state["result"]["value"].as_str().unwrap_or("");
        if !state.starts_with("about:") && state.ends_with(" complete") {
            break;
        }
        col.loaded = false;
    }
    // web fonts, then two animation frames so layout and paint are final
    browser.call(
        s,
        "Runtime.evaluate",
        json!({
            "expression": "document.fonts.ready.then(() => new Promise(r => requestAnimationFrame(() => requestAnimationFrame(r))))",
            "awaitPromise": true,
        }),
    )?;
    let probe = browser.call(
        s,
        "Runtime.evaluate",
        json!({ "expression": include_str!("probe.js"), "returnByValue": true, "awaitPromise": true }),
    )?;
    if let Some(ex) = probe.get("exceptionDetails") {
        bail!("the page probe failed: {ex}");
    }
    let probe: Probe = serde_json::from_value(probe["result"]["value"].clone())
        .context("reading the page probe's result")?;

    let stem = html
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "page".into());
    let viewport = opts.screenshot_dir.join(format!(
        "{stem}-viewport-{}x{}.png",
        opts.width, opts.height
    ));
    let shot = browser.call(s, "Page.captureScreenshot", json!({ "format": "png" }))?;
    write_png(&shot, &viewport)?;

    let full_page = opts
        .screenshot_dir
        .join(format!("{stem}-full-page-{}.png", opts.width));
    let full_width = probe.scroll_width.max(probe.client_width);
    let full_height = probe.scroll_height.min(opts.max_full_page_height);
    let shot = browser.call(
        s,
        "Page.captureScreenshot",
        json!({
            "format": "png",
            "captureBeyondViewport": true,
            "clip": { "x": 0, "y": 0, "width": full_width, "height": full_height, "scale": 1 },
        }),
    )?;
    write_png(&shot, &full_page)?;

    let mut widest_element = None;
    if let Some(w) = probe.wide.first() {
        let path = opts
            .screenshot_dir
            .join(format!("{stem}-widest-element-{}.png", opts.width));
        let top = (w.top - 10.0).max(0.0);
        let shot = browser.call(
            s,
            "Page.captureScreenshot",
            json!({
                "format": "png",
                "captureBeyondViewport": true,
                "clip": { "x": 0, "y": top, "width": full_width, "height": (w.height + 20.0).min(4000.0), "scale": 1 },
            }),
        )?;
        write_png(&shot, &path)?;
        widest_element = Some(path);
    }

    for ev in browser.drain_events() {
        col.take(&ev, &session);
    }
    let version = browser.version.clone();
    let full_page_truncated = probe.scroll_height > opts.max_full_page_height;
    Ok((
        probe,
        col.console,
        col.failed,
        Screenshots {
            viewport,
            full_page,
            full_page_truncated,
            widest_element,
        },
        version,
    ))
}

fn write_png(result: &Value, path: &Path) -> Result<()> {
    let data = result["data"]
        .as_str()
        .ok_or_else(|| anyhow!("Page.captureScreenshot returned no data"))?;
    let bytes = data_encoding::BASE64
        .decode(data.as_bytes())
        .context("decoding the screenshot")?;
    fs::write(path, bytes).with_context(|| format!("writing {}", path.display()))
}

/// `file://` URL of an absolute path, percent-encoding what URLs do not allow.
fn file_url(path: &Path) -> String {
    use std::os::unix::ffi::OsStrExt;
    let mut url = String::from("file://");
    for &b in path.as_os_str().as_bytes() {
        if b.is_ascii_alphanumeric() || b"/-._~!$&'()*+,;=:@".contains(&b) {
            url.push(b as char);
        } else {
            url += &format!("%{b:02X}");
        }
    }
    url
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn file_urls_are_percent_encoded() {
        assert_eq!(
            file_url(Path::new("/tmp/a b/r#1.html")),
            "file:///tmp/a%20b/r%231.html"
        );
    }
}
