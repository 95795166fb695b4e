//! The native `rerun` viewer: finding one of the right version, and rendering PNGs with it.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use super::SinkError;

/// Environment variable naming a `rerun` binary to use instead of searching `PATH`.
pub const RERUN_ENV: &str = "POSECOV_RERUN";

/// The viewer minor version this crate's SDK speaks (`rerun` crate =0.36.3).
pub const VIEWER_VERSION_PREFIX: &str = "0.36.";

const VERSION_TIMEOUT: Duration = Duration::from_secs(20);
const SCREENSHOT_TIMEOUT: Duration = Duration::from_secs(180);

/// A native Rerun viewer binary of a compatible version.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct NativeViewer {
    /// The executable.
    pub path: PathBuf,
    /// Its version, e.g. `0.36.3`.
    pub version: String,
}

/// Finds a `rerun` 0.36.x viewer: `$POSECOV_RERUN` if set, else the first `rerun` on `PATH`
/// (asked for `--version`, with a timeout so a broken install cannot hang us).
///
/// # Errors
/// [`SinkError::NoViewer`], saying what was found instead, if any.
pub fn find_native_viewer() -> Result<NativeViewer, SinkError> {
    let candidates: Vec<PathBuf> = match std::env::var_os(RERUN_ENV) {
        Some(path) => vec![PathBuf::from(path)],
        None => std::env::var_os("PATH")
            .map(|paths| {
                std::env::split_paths(&paths)
                    .map(|d| d.join("rerun"))
                    .collect()
            })
            .unwrap_or_default(),
    };
    let mut found = String::new();
    for path in candidates.into_iter().filter(|p| p.is_file()) {
        match version_of(&path) {
            Some(version) if version.starts_with(VIEWER_VERSION_PREFIX) => {
                return Ok(NativeViewer { path, version });
            }
            Some(version) => found = format!(" ({} is rerun {version})", path.display()),
            None => found = format!(" ({} did not report a version)", path.display()),
        }
    }
    Err(SinkError::NoViewer { found })
}

/// `rerun --version` prints e.g. `rerun-cli 0.36.3 (…)`: the second word.
fn version_of(path: &Path) -> Option<String> {
    let mut child = Command::new(path)
        .arg("--version")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .ok()?;
    wait_with_timeout(&mut child, VERSION_TIMEOUT)?;
    let mut out = String::new();
    std::io::Read::read_to_string(&mut child.stdout.take()?, &mut out).ok()?;
    out.split_whitespace().nth(1).map(str::to_owned)
}

/// Waits for `child` up to `timeout`; kills it and returns `None` after that.
fn wait_with_timeout(
    child: &mut std::process::Child,
    timeout: Duration,
) -> Option<std::process::ExitStatus> {
    let start = Instant::now();
    loop {
        match child.try_wait() {
            Ok(Some(status)) => return Some(status),
            Ok(None) if start.elapsed() < timeout => std::thread::sleep(Duration::from_millis(50)),
            _ => {
                child.kill().ok();
                child.wait().ok();
                return None;
            }
        }
    }
}

/// Renders `rrd` to `png` (`width`×`height` points; the PNG has 2 px per point) in a
/// headless `viewer` with a fresh, private viewer state (so no earlier layout leaks in):
/// `rerun rrd optimize IN.rrd -o OPT.rrd`, then
/// `rerun --headless --port P OPT.rrd --screenshot-to OUT.png --window-size WxH` (the
/// recording compacted first, so that it loads whole before the viewer's screenshot).
///
/// # Errors
/// [`SinkError::Screenshot`] when the viewer fails, times out or writes nothing.
pub fn render_png(
    viewer: &NativeViewer,
    rrd: &Path,
    png: &Path,
    (width, height): (u32, u32),
) -> Result<(), SinkError> {
    let state = std::env::temp_dir().join(format!("posecov-viewer-{}", std::process::id()));
    let io_err = |action, source| SinkError::Io {
        action,
        path: state.clone(),
        source,
    };
    std::fs::create_dir_all(&state).map_err(|e| io_err("creating", e))?;
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt as _;
        std::fs::set_permissions(&state, std::fs::Permissions::from_mode(0o700))
            .map_err(|e| io_err("restricting", e))?;
    }
    let result = run_screenshot(viewer, rrd, png, (width, height), &state);
    std::fs::remove_dir_all(&state).ok();
    result
}

fn run_screenshot(
    viewer: &NativeViewer,
    rrd: &Path,
    png: &Path,
    (width, height): (u32, u32),
    state: &Path,
) -> Result<(), SinkError> {
    let fail = |status: String, stderr: String| SinkError::Screenshot {
        png: png.to_owned(),
        viewer: viewer.path.clone(),
        status,
        stderr,
    };
    // The viewer takes its screenshot ten frames after it starts, loading or not: a
    // recording of many small chunks (posecov logs one per item and step; Barfoot's 100 steps
    // are thousands) is still loading then, its plots empty and its time at step 75 of 100.
    // Compacted into few large chunks (`rerun rrd optimize`, the same content) it loads whole
    // before the screenshot, and two shots are the same picture.
    let optimized = state.join("optimized.rrd");
    let mut optimize = Command::new(&viewer.path);
    optimize
        .args(["rrd", "optimize"])
        .arg(rrd)
        .arg("-o")
        .arg(&optimized);
    run_viewer(optimize, state, "optimizing the recording").map_err(|(s, e)| fail(s, e))?;
    let port = std::net::TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .map(|a| a.port())
        .map_err(|e| fail("no free port".into(), e.to_string()))?;
    let mut shot = Command::new(&viewer.path);
    shot.args(["--headless", "--port", &port.to_string()])
        .arg(&optimized)
        .arg("--screenshot-to")
        .arg(png)
        .args(["--window-size", &format!("{width}x{height}")]);
    let tail = run_viewer(shot, state, "rendering").map_err(|(s, e)| fail(s, e))?;
    if std::fs::metadata(png).map_or(true, |m| m.len() == 0) {
        return Err(fail("exited without writing the PNG".into(), tail));
    }
    Ok(())
}

/// Runs `command` (the viewer binary) with the private viewer `state`, within
/// [`SCREENSHOT_TIMEOUT`]; its stderr's tail on success, else what failed and that tail.
fn run_viewer(mut command: Command, state: &Path, what: &str) -> Result<String, (String, String)> {
    let stderr_path = state.join("stderr.txt");
    let stderr_file = std::fs::File::create(&stderr_path)
        .map_err(|e| ("cannot capture stderr".to_owned(), e.to_string()))?;
    let mut child = command
        .env("XDG_DATA_HOME", state)
        .env("XDG_RUNTIME_DIR", state)
        // Info/warning toasts would be drawn over the picture.
        .env("RUST_LOG", "error")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(stderr_file)
        .spawn()
        .map_err(|e| (format!("{what}: could not start"), e.to_string()))?;
    let status = wait_with_timeout(&mut child, SCREENSHOT_TIMEOUT);
    let stderr = std::fs::read_to_string(&stderr_path).unwrap_or_default();
    let tail: String = stderr.lines().rev().take(8).collect::<Vec<_>>().join("\n");
    match status {
        None => Err((
            format!("{what}: timed out after {SCREENSHOT_TIMEOUT:?}"),
            tail,
        )),
        Some(s) if !s.success() => Err((format!("{what}: {s}"), tail)),
        Some(_) => Ok(tail),
    }
}
