//! Sinks: where a [`Scene`](crate::scene::Scene) goes. Only this module knows Rerun.
//!
//! - [`rerun`]: scene → Rerun 0.36 archetypes (batched, one entity per item).
//! - [`blueprint`]: the default layout, with each 3-D view's camera and hidden entities
//!   ([`send_layout`]).
//! - [`legend`]: the legend view's tiles, a swatch and the words per legend entry.
//! - [`stream`]: opening a [`Sink`] (viewer, file, stdout, web viewer, memory) with
//!   deterministic content, and finishing it cleanly ([`SinkGuard::finish`]).
//! - [`restream`]: logging a new scene in place of the last one in the same recording (live
//!   mode, `--watch`), leaving nothing stale.
//! - [`viewer`]: finding a native `rerun` 0.36 viewer and rendering PNGs with it.
//! - [`figure`]: static figures (SVG, PNG, PDF) drawn by posecov itself, no viewer needed:
//!   the only sink built without the `viewer` feature (the figure benchmark runs so, in
//!   release).
//!
//! # Deterministic content
//! For a given scene, every run writes the same *content*: the recording id is derived from
//! the scenario name and seed ([`RecordingIds::for_scenario`]), no wall-clock time is logged,
//! recording properties (start time) are not sent, and every item becomes exactly one chunk
//! sent in a fixed order (so chunking cannot depend on timing). Row and chunk ids and the
//! blueprint's ids still differ between runs — compare with `rerun rrd compare`, or decode
//! and compare the chunks as `tests/sink.rs` does.
//!
//! # Example
//! ```
//! # #[cfg(feature = "viewer")] {
//! use posecov::app::{Overrides, load, pipeline};
//! use posecov::sink::{RecordingIds, scene_to_rrd_bytes};
//! let loaded = load("camera_on_robot")?;
//! let (_, scene) = pipeline(&loaded, &Overrides { samples: Some(50), ..Default::default() }, None)?;
//! let bytes = scene_to_rrd_bytes(&scene, &RecordingIds::for_scenario("camera_on_robot", 1))?;
//! assert!(bytes.len() > 1000);
//! # }
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! # What this folder owns
//!
//! `figure/`: Scene → a static figure without Rerun (the one sink built without the `viewer`
//! feature; `svg.rs` the SVG writer, `mod.rs` the figure's layout (the world panels, the legend and
//! plots beside), `panel.rs` one world panel per 3-D view and their grid, `world.rs` the plane
//! projection of every item kind, `region.rs` a surface as the outline of its projected triangles'
//! union, `chart.rs` axes, scale bar, legend and plots, `raster.rs` PNG through resvg and PDF
//! through svg2pdf with the bundled font `assets/fonts/`); Scene → Rerun archetypes (`rerun.rs`)
//! and the layout (`blueprint.rs`: blueprint archetypes written directly, with each view's
//! `EyeControls3D` and hidden entities); .rrd files (written whole or not at all), stdout, spawn,
//! connect, the embedded web viewer on loopback; `restream.rs`: a new scene in place of the last in
//! the same recording (clears of every entity position touched before, frames overwritten instead;
//! plots under a generation path, earlier ones shadowed by static empty scalars; the layout sent
//! again only when the views change).
//!
//! It does not decide what to draw.

#[cfg(feature = "viewer")]
pub mod blueprint;
pub mod figure;
#[cfg(feature = "viewer")]
pub mod legend;
#[cfg(feature = "viewer")]
pub mod rerun;
#[cfg(feature = "viewer")]
pub mod restream;
#[cfg(feature = "viewer")]
mod rows;
#[cfg(feature = "viewer")]
pub mod stream;
#[cfg(feature = "viewer")]
pub mod viewer;

use std::path::PathBuf;

#[cfg(feature = "viewer")]
pub use self::blueprint::send_layout;
#[cfg(feature = "viewer")]
pub use self::rerun::{
    LogOutcome, STEP_TIMELINE, log_part_cancellable, log_points, log_scene, log_scene_cancellable,
};
#[cfg(feature = "viewer")]
pub use self::restream::Restream;
#[cfg(feature = "viewer")]
pub use self::stream::{SinkGuard, open_stream, scene_to_rrd_bytes};
#[cfg(feature = "viewer")]
pub use self::viewer::{NativeViewer, find_native_viewer, render_png};

/// Application id of every posecov recording (the viewer groups recordings by it).
pub const APPLICATION_ID: &str = "posecov";

/// Where a recording goes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Sink {
    /// Write an .rrd file. Written to a temporary file next to it and renamed when complete.
    Save(PathBuf),
    /// Write .rrd bytes to stdout (for `| rerun -`).
    Stdout,
    /// Spawn a native `rerun` viewer from `PATH` (or `$POSECOV_RERUN`) and stream to it.
    Spawn,
    /// Stream to a running viewer or server, e.g. `rerun+http://127.0.0.1:9876/proxy`.
    Connect(String),
    /// Host a gRPC server and the embedded web viewer on 127.0.0.1.
    Serve {
        /// HTTP port of the web viewer (0 = any free port).
        web_port: u16,
        /// Port of the gRPC server the web viewer connects to.
        grpc_port: u16,
        /// Open the viewer URL in the default browser.
        open_browser: bool,
    },
    /// Keep everything in memory (tests); read it with [`SinkGuard::finish`].
    Memory,
}

/// Identity of a recording: stable across runs so that two runs can be compared.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RecordingIds {
    /// Recording id, fixed for a scenario and seed (the application id is always
    /// [`APPLICATION_ID`]).
    pub recording_id: String,
}

impl RecordingIds {
    /// Ids for `scenario` run with `seed`: `posecov/<scenario>/seed-<seed>`.
    ///
    /// ```
    /// let ids = posecov::sink::RecordingIds::for_scenario("se2_odometry", 7);
    /// assert_eq!(ids.recording_id, "posecov/se2_odometry/seed-7");
    /// ```
    pub fn for_scenario(scenario: &str, seed: u64) -> Self {
        Self {
            recording_id: format!("{APPLICATION_ID}/{scenario}/seed-{seed}"),
        }
    }
}

/// What can go wrong on the way to a viewer or file.
#[derive(Debug, thiserror::Error)]
pub enum SinkError {
    /// The scene failed [`Scene::validate`](crate::scene::Scene::validate).
    #[error("invalid scene: {0}")]
    Scene(#[from] crate::scene::SceneError),
    /// The Rerun SDK refused (bad URL, spawn failure, serialization).
    #[cfg(feature = "viewer")]
    #[error("rerun: {0}")]
    Rerun(#[from] ::rerun::RecordingStreamError),
    /// A chunk could not be built (a bug: validation should have caught it).
    #[error("building a rerun chunk for {path}: {message}")]
    Chunk {
        /// Entity path.
        path: String,
        /// The SDK's message.
        message: String,
    },
    /// Flushing to the sink failed or timed out.
    #[error("flushing the recording: {0}")]
    Flush(String),
    /// A file operation failed.
    #[error("{action} {path}: {source}")]
    Io {
        /// What was being done ("creating", "renaming to", …).
        action: &'static str,
        /// Which file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// The web viewer could not be served.
    #[error("serving the web viewer: {0}")]
    WebViewer(String),
    /// A port the served viewer needs cannot be had.
    #[error(
        "{flag} {port}: 127.0.0.1:{port} cannot be served ({reason}); another viewer or posecov may be serving there: give another port with {flag}"
    )]
    Port {
        /// The flag that sets it (`--web-port`, `--grpc-port`).
        flag: &'static str,
        /// The port.
        port: u16,
        /// The OS error.
        reason: String,
    },
    /// No native viewer of the right version was found.
    #[error(
        "no rerun 0.36 viewer found{found}; install one with `pip install rerun-sdk==0.36.3` \
         (or point $POSECOV_RERUN at a rerun 0.36 binary)"
    )]
    NoViewer {
        /// What was found instead, e.g. " (PATH has rerun 0.24.1)", or empty.
        found: String,
    },
    /// The headless viewer did not produce a screenshot.
    #[error("rendering {png} with {viewer} failed ({status}): {stderr}")]
    Screenshot {
        /// Output file.
        png: PathBuf,
        /// Viewer binary.
        viewer: PathBuf,
        /// Exit status.
        status: String,
        /// The tail of its stderr.
        stderr: String,
    },
}
