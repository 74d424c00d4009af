//! A headless Chromium process and a minimal DevTools-protocol (CDP) client.
//!
//! The browser runs with a fresh temporary profile. [`Browser`] owns both:
//! dropping it (also on an error or a panic) kills the main process, then any
//! helper process still alive (found by the profile path on its command
//! line), and removes the profile.
//! Every wait is bounded by one deadline, so nothing here can hang.

use std::collections::VecDeque;
use std::fs;
use std::io::{ErrorKind, Read};
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::thread::sleep;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, anyhow, bail};
use serde_json::{Value, json};
use tungstenite::protocol::WebSocketConfig;
use tungstenite::{Message, WebSocket};

use crate::locate::INSTALL_HINT;

/// The flags every launch uses. The first group is what this machine needs
/// (without the background-networking ones Chromium's own connections are
/// refused en masse); the rest make runs quiet and repeatable.
const FLAGS: &[&str] = &[
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-default-browser-check",
    "--disable-default-apps",
    "--disable-extensions",
    "--disable-breakpad",
    "--disable-crash-reporter",
    "--disable-dev-shm-usage",
    "--disable-features=Translate,MediaRouter,OptimizationHints",
    "--force-color-profile=srgb",
    "--mute-audio",
    "--password-store=basic",
    "--use-mock-keychain",
    // lets the check read an <object>/<embed> SVG's document from file://
    "--allow-file-access-from-files",
    "--remote-debugging-port=0",
    "about:blank",
];

/// A running headless Chromium with its temporary profile, connected over CDP.
pub(crate) struct Browser {
    child: Option<Child>,
    ws: Option<WebSocket<TcpStream>>,
    profile: Option<tempfile::TempDir>,
    profile_path: PathBuf,
    deadline: Instant,
    timeout: Duration,
    next_id: u64,
    /// Events received while waiting for something else, oldest first.
    events: VecDeque<Value>,
    /// The browser's version line (`Browser.getVersion`'s `product`).
    pub version: String,
}

impl Browser {
    /// Starts `binary` headless with a fresh profile and connects to it.
    /// Every later call must finish before `deadline` (`timeout` is only
    /// quoted in error messages).
    /// The profile is a new directory under `profile_parent` (default: the
    /// system's temporary directory).
    pub(crate) fn launch(
        binary: &Path,
        window: (u32, u32),
        profile_parent: Option<&Path>,
        deadline: Instant,
        timeout: Duration,
    ) -> Result<Self> {
        let mut builder = tempfile::Builder::new();
        builder.prefix("browser-check-profile-");
        let profile = match profile_parent {
            Some(dir) => builder.tempdir_in(dir),
            None => builder.tempdir(),
        }
        .context("creating a temporary Chromium profile")?;
        let profile_path = profile.path().to_path_buf();
        let log_path = profile_path.join("chromium-stderr.log");
        let log = fs::File::create(&log_path).context("creating the Chromium log file")?;
        let mut cmd = Command::new(binary);
        cmd.args(FLAGS)
            .arg(format!("--user-data-dir={}", profile_path.display()))
            .arg(format!("--window-size={},{}", window.0, window.1))
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::from(log))
            // the crash handler ignores --user-data-dir and would keep a
            // "Crash Reports" folder in ~/.config/chromium: keep it in the profile
            .env("XDG_CONFIG_HOME", profile_path.join("xdg-config"));
        // Deliberately in the caller's process group: Ctrl-C in a terminal
        // (or a CI runner killing the job's group) reaches Chromium too.
        let child = cmd
            .spawn()
            .with_context(|| format!("starting {}: {INSTALL_HINT}", binary.display()))?;
        let mut browser = Browser {
            child: Some(child),
            ws: None,
            profile: Some(profile),
            profile_path,
            deadline,
            timeout,
            next_id: 0,
            events: VecDeque::new(),
            version: String::new(),
        };
        let ws_url = browser.wait_for_devtools(&log_path)?;
        browser.connect(&ws_url)?;
        let v = browser.call(None, "Browser.getVersion", json!({}))?;
        browser.version = v["product"].as_str().unwrap_or("?").to_string();
        Ok(browser)
    }

    /// The temporary profile directory (removed when the browser is dropped).
    pub(crate) fn profile_path(&self) -> &Path {
        &self.profile_path
    }

    /// Waits for Chromium to write `DevToolsActivePort` into the profile and
    /// returns the browser's WebSocket URL.
    fn wait_for_devtools(&mut self, log_path: &Path) -> Result<String> {
        let port_file = self.profile_path.join("DevToolsActivePort");
        loop {
            if let Ok(text) = fs::read_to_string(&port_file) {
                let mut lines = text.lines();
                // "PORT\n/devtools/browser/UUID"; read again if caught half-written
                if let (Some(Ok(port)), Some(path)) =
                    (lines.next().map(|p| p.trim().parse::<u16>()), lines.next())
                    && path.trim().len() == "/devtools/browser/".len() + 36
                {
                    return Ok(format!("ws://127.0.0.1:{port}{}", path.trim()));
                }
            }
            if let Some(child) = self.child.as_mut()
                && let Some(status) = child.try_wait()?
            {
                bail!(
                    "Chromium exited during start-up ({status}); last lines of its output:\n{}\n({INSTALL_HINT})",
                    tail(log_path, 15)
                );
            }
            if Instant::now() >= self.deadline {
                bail!(
                    "timed out after {:?} waiting for Chromium to open its DevTools port; last lines of its output:\n{}",
                    self.timeout,
                    tail(log_path, 15)
                );
            }
            sleep(Duration::from_millis(25));
        }
    }

    fn connect(&mut self, ws_url: &str) -> Result<()> {
        let addr = ws_url
            .trim_start_matches("ws://")
            .split('/')
            .next()
            .ok_or_else(|| anyhow!("bad DevTools URL {ws_url}"))?
            .to_string();
        let stream = TcpStream::connect(&addr)
            .with_context(|| format!("connecting to Chromium's DevTools at {addr}"))?;
        stream.set_read_timeout(Some(self.remaining()?))?;
        stream.set_write_timeout(Some(self.remaining()?))?;
        stream.set_nodelay(true)?;
        let config = WebSocketConfig::default()
            .max_message_size(Some(512 << 20))
            .max_frame_size(Some(512 << 20));
        let (ws, _) = tungstenite::client::client_with_config(ws_url, stream, Some(config))
            .map_err(|e| anyhow!("WebSocket handshake with Chromium failed: {e}"))?;
        self.ws = Some(ws);
        Ok(())
    }

    fn remaining(&self) -> Result<Duration> {
        let now = Instant::now();
        if now >= self.deadline {
            bail!(
                "timed out: the browser check took longer than {:?}",
                self.timeout
            );
        }
        Ok(self.deadline - now)
    }

    /// Reads one message, waiting at most until the deadline.
    fn read(&mut self, waiting_for: &str) -> Result<Value> {
        loop {
            let remaining = self
                .remaining()
                .with_context(|| format!("while waiting for {waiting_for}"))?;
            let ws = self.ws.as_mut().ok_or_else(|| anyhow!("not connected"))?;
            ws.get_mut().set_read_timeout(Some(remaining))?;
            match ws.read() {
                Ok(Message::Text(t)) => return Ok(serde_json::from_str(t.as_str())?),
                Ok(Message::Binary(b)) => return Ok(serde_json::from_slice(&b)?),
                Ok(_) => continue,
                Err(tungstenite::Error::Io(e))
                    if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) =>
                {
                    bail!(
                        "timed out after {:?} waiting for {waiting_for}",
                        self.timeout
                    )
                }
                Err(e) => {
                    bail!("lost the connection to Chromium while waiting for {waiting_for}: {e}")
                }
            }
        }
    }

    /// Sends a command (to the browser, or to a page `session`) and returns its
    /// result; events that arrive meanwhile are queued for [`Browser::next_event`].
    pub(crate) fn call(
        &mut self,
        session: Option<&str>,
        method: &str,
        params: Value,
    ) -> Result<Value> {
        self.next_id += 1;
        let id = self.next_id;
        let mut msg = json!({ "id": id, "method": method, "params": params });
        if let Some(s) = session {
            msg["sessionId"] = json!(s);
        }
        self.remaining()
            .with_context(|| format!("before sending {method}"))?;
        let ws = self.ws.as_mut().ok_or_else(|| anyhow!("not connected"))?;
        ws.send(Message::text(msg.to_string()))
            .with_context(|| format!("sending {method} to Chromium"))?;
        loop {
            let m = self.read(method)?;
            if m.get("id").and_then(Value::as_u64) == Some(id) {
                if let Some(err) = m.get("error") {
                    bail!("Chromium refused {method}: {err}");
                }
                return Ok(m.get("result").cloned().unwrap_or(Value::Null));
            }
            if m.get("method").is_some() {
                self.events.push_back(m);
            }
        }
    }

    /// The next event (queued or read from the socket), waiting until the deadline.
    pub(crate) fn next_event(&mut self, waiting_for: &str) -> Result<Value> {
        if let Some(e) = self.events.pop_front() {
            return Ok(e);
        }
        loop {
            let m = self.read(waiting_for)?;
            if m.get("method").is_some() {
                return Ok(m);
            }
        }
    }

    /// Events already queued (without waiting).
    pub(crate) fn drain_events(&mut self) -> Vec<Value> {
        self.events.drain(..).collect()
    }

    /// Closes the browser politely, then makes sure nothing of it is left:
    /// kills and reaps the main process, kills leftover helpers, removes the profile.
    pub(crate) fn close(mut self) -> Result<()> {
        if self.ws.is_some() && self.remaining().is_ok() {
            self.next_id += 1;
            let msg = json!({ "id": self.next_id, "method": "Browser.close", "params": {} });
            if let Some(ws) = self.ws.as_mut() {
                let _ = ws.send(Message::text(msg.to_string()));
            }
            // give it up to 5 s to exit on its own (it normally takes ~50 ms)
            let until = Instant::now() + Duration::from_secs(5);
            while Instant::now() < until {
                match self.child.as_mut().map(Child::try_wait) {
                    Some(Ok(None)) => sleep(Duration::from_millis(20)),
                    _ => break,
                }
            }
        }
        self.shutdown()
    }

    fn shutdown(&mut self) -> Result<()> {
        if let Some(mut ws) = self.ws.take() {
            let _ = ws.close(None);
            let _ = ws.get_mut().shutdown(std::net::Shutdown::Both);
        }
        if let Some(mut child) = self.child.take() {
            let _ = child.kill();
            let _ = child.wait();
        }
        // Chromium's helpers (zygotes, renderers, GPU and utility processes,
        // the crash handler) exit on their own within a second or two of the
        // main process; kill any that are still there. Each has the unique
        // profile path on its command line.
        let until = Instant::now() + Duration::from_secs(3);
        loop {
            let left = processes_mentioning(&self.profile_path);
            if left.is_empty() || Instant::now() >= until {
                break;
            }
            for pid in left {
                let _ = rustix::process::kill_process(pid, rustix::process::Signal::KILL);
            }
            sleep(Duration::from_millis(20));
        }
        if let Some(profile) = self.profile.take() {
            let path = profile.path().to_path_buf();
            // a process that was just killed may still be flushing into it
            let mut result = profile.close();
            for _ in 0..20 {
                if result.is_ok() || !path.exists() {
                    return Ok(());
                }
                sleep(Duration::from_millis(50));
                result = fs::remove_dir_all(&path);
            }
            result.with_context(|| format!("removing the temporary profile {}", path.display()))?;
        }
        Ok(())
    }
}

impl Drop for Browser {
    fn drop(&mut self) {
        let _ = self.shutdown();
    }
}

/// Live (not zombie) processes whose command line contains `marker`.
pub(crate) fn processes_mentioning(marker: &Path) -> Vec<rustix::process::Pid> {
    let marker = marker.as_os_str().as_encoded_bytes();
    let mut found = Vec::new();
    let Ok(dir) = fs::read_dir("/proc") else {
        return found;
    };
    for entry in dir.flatten() {
        let Some(pid) = entry
            .file_name()
            .to_str()
            .and_then(|n| n.parse::<i32>().ok())
            .and_then(rustix::process::Pid::from_raw)
        else {
            continue;
        };
        // a zombie's command line is empty, so it never matches
        let Ok(cmdline) = fs::read(entry.path().join("cmdline")) else {
            continue;
        };
        if !marker.is_empty() && cmdline.windows(marker.len()).any(|w| w == marker) {
            found.push(pid);
        }
    }
    found
}

/// The last `n` lines of a log file, for error messages.
fn tail(path: &Path, n: usize) -> String {
    let mut s = String::new();
    if let Ok(mut f) = fs::File::open(path) {
        let _ = f.read_to_string(&mut s);
    }
    let lines: Vec<&str> = s.lines().collect();
    lines[lines.len().saturating_sub(n)..].join("\n")
}
