//! Live mode (`posecov live`): a control page beside the viewer. Each change edits the
//! scenario document ([`LiveDocument`], comments and layout kept), is loaded exactly like a
//! file, evaluated (a quick preview, then the full sample) and re-streamed into the same
//! recording ([`crate::sink::Restream`]). `--watch` runs the same machinery without a page.
//!
//! - [`controls`]: the controls, generated from the document and the lowering's key table.
//! - [`document`]: edits, reset, the text to save.
//! - `worker` (viewer feature): the evaluation thread and its status.
//! - `server` (viewer feature): the page and its JSON API on loopback.
//! - `proxy` (viewer feature): the served web viewer through the page (same origin).
//! - `run` (viewer feature): the `live` command and `--watch`.
//!
//! # What this folder owns
//!
//! - live mode and `--watch` on a viewer: `controls.rs` (the controls, generated from the TOML
//!   document and `OPERATION_KINDS`: no second list of keys; the methods offered are those an
//!   evaluation with every method ran, `AnyEvaluation::methods_that_ran`: no second list of which
//!   method applies)
//! - `document.rs` (edits on a `toml_edit` document, comments kept, each loaded with
//!   `app::load_text` so validation is the file's; reset; the text to save)
//! - `worker.rs` (the evaluation thread: newest change only, `passes` — a preview with fewer
//!   samples and steps kept, then the full picture — a newer change cancels the refinement, never a
//!   first picture; status)
//! - `server.rs` (the page and JSON API on loopback, Host/Origin checked; the page itself is
//!   `assets/live/`)
//! - `proxy.rs` (the served web viewer and its gRPC-web stream forwarded through the page, same
//!   origin; the viewer's servers stay on loopback)
//! - `prose.rs` (the title's and description's typed values restated when edited)
//! - `run.rs` (the `live` command, `--watch`)
//!
//! Not here: math, drawing, Rerun archetypes.

pub mod controls;
pub mod document;
mod prose;
#[cfg(feature = "viewer")]
mod proxy;
#[cfg(feature = "viewer")]
mod run;
#[cfg(feature = "viewer")]
mod server;
#[cfg(feature = "viewer")]
mod worker;

pub use controls::{Control, ControlKind};
pub use document::{Edit, EditError, EditValue, LiveDocument};
#[cfg(feature = "viewer")]
pub use proxy::{Upstream, VIEWER_PATH};
#[cfg(feature = "viewer")]
pub use run::{LiveOptions, live, watch_in_place};
#[cfg(feature = "viewer")]
pub use server::{PageOptions, bind_page, serve_page};
#[cfg(feature = "viewer")]
pub use worker::{
    Live, MIN_PICTURE_INTERVAL, PREVIEW_SAMPLES, PREVIEW_STEPS, PREVIEW_WORK, Status, passes,
};

#[cfg(test)]
mod tests {
    use super::*;
    use crate::input::scenario::bundled::BUNDLED;

    #[test]
    fn every_bundled_scenario_has_controls_that_round_trip() {
        for b in BUNDLED {
            let mut live = LiveDocument::new(b.text, b.name).unwrap();
            let controls = live.controls();
            assert!(controls.len() > SETTINGS_AND_SWITCHES, "{}", b.name);
            // Writing every number back unchanged keeps the file valid and identical.
            for c in &controls {
                let value = match c.kind {
                    ControlKind::Number { value, .. } => EditValue::Number(value),
                    ControlKind::Toggle { value } => EditValue::Toggle(value),
                };
                if c.id.starts_with("scenario.") || c.id.starts_with("draw.") {
                    continue;
                }
                live.apply(&Edit {
                    id: c.id.clone(),
                    value,
                })
                .unwrap_or_else(|e| panic!("{}: {}: {e}", b.name, c.id));
            }
            assert_eq!(live.text(), b.text, "{}", b.name);
        }
    }

    /// 3 settings and the draw switches (methods: only those that apply).
    const SETTINGS_AND_SWITCHES: usize = 3 + 7;

    #[test]
    fn a_heading_sigma_edit_keeps_the_comment_and_reset_restores_the_file() {
        let text = crate::input::scenario::bundled::find("camera_on_robot")
            .unwrap()
            .text;
        let mut live = LiveDocument::new(text, "camera_on_robot.toml").unwrap();
        let sigma = live
            .controls()
            .into_iter()
            .find(|c| c.id == "pose[0].cov.std_deg[2]")
            .unwrap();
        assert_eq!(sigma.unit, "°");
        assert_eq!(sigma.label, "σ θ");
        let ControlKind::Number {
            value, min, max, ..
        } = sigma.kind
        else {
            panic!("a number")
        };
        assert_eq!((value, min, max), (20.0, 0.0, 80.0));
        live.apply(&Edit {
            id: sigma.id.clone(),
            value: EditValue::Number(40.0),
        })
        .unwrap();
        let edited = live.text();
        assert!(
            edited.contains(
                "cov = { std_deg = [0.05, 0.05, 40.0] }   # x, y in metres; θ in degrees"
            ),
            "{edited}"
        );
        assert_eq!(edited.lines().count(), text.lines().count());
        live.reset().unwrap();
        assert_eq!(live.text(), text);
    }

    #[test]
    fn a_bad_value_names_the_field_and_changes_nothing() {
        let mut live = LiveDocument::open("camera_on_robot").unwrap();
        let before = live.text();
        let e = live
            .apply(&Edit {
                id: "pose[0].cov.std_deg[2]".into(),
                value: EditValue::Number(-4.0),
            })
            .unwrap_err();
        assert_eq!(e.field().as_deref(), Some("pose[0].cov"), "{e}");
        assert!(
            e.to_string().contains("camera_on_robot.toml (bundled):"),
            "{e}"
        );
        // A cleared field, NaN and a text that is no number name the field in words.
        for (value, words) in [
            (EditValue::Empty, "is empty: type a number"),
            (EditValue::Number(f64::NAN), "NaN is not a number"),
            (EditValue::Text("NaN".into()), "NaN is not a number"),
            (EditValue::Text(" ".into()), "is empty: type a number"),
            (EditValue::Text("abc".into()), "`abc` is not a number"),
        ] {
            let e = live
                .apply(&Edit {
                    id: "pose[0].cov.std_deg[2]".into(),
                    value,
                })
                .unwrap_err()
                .to_string();
            assert!(
                e.starts_with("pose[0].cov.std_deg[2]: pose map_from_robot σ θ")
                    && e.contains(words),
                "{e}"
            );
        }
        live.apply(&Edit {
            id: "pose[0].cov.std_deg[2]".into(),
            value: EditValue::Text("25".into()),
        })
        .unwrap();
        live.reset().unwrap();
        let e = live
            .apply(&Edit {
                id: "scenario.samples".into(),
                value: EditValue::Number(1.0),
            })
            .unwrap_err();
        assert_eq!(e.field().as_deref(), Some("scenario.samples"), "{e}");
        let e = live
            .apply(&Edit {
                id: "pose[0].name".into(),
                value: EditValue::Number(1.0),
            })
            .unwrap_err();
        assert!(matches!(e, EditError::Unknown { .. }), "{e}");
        assert_eq!(live.text(), before);
    }

    #[test]
    fn switches_and_methods_are_inserted_where_the_file_has_none() {
        let mut live = LiveDocument::open("camera_on_robot").unwrap();
        live.apply(&Edit {
            id: "draw.clouds".into(),
            value: EditValue::Toggle(false),
        })
        .unwrap();
        assert!(!live.loaded().input.draw.clouds);
        live.apply(&Edit {
            id: "scenario.methods.vector_space".into(),
            value: EditValue::Toggle(false),
        })
        .unwrap();
        assert!(
            !live
                .loaded()
                .input
                .defaults
                .methods
                .contains(&crate::uncertain::Method::VectorSpace)
        );
        let reparsed = crate::app::load_text(&live.text(), "saved.toml").unwrap();
        assert!(!reparsed.input.draw.clouds);
    }

    #[test]
    fn every_draw_switch_is_a_key_of_the_draw_table() {
        use crate::input::scenario::schema::DrawSpec;
        let all_off: String = DrawSpec::SWITCHES
            .iter()
            .map(|s| format!("{s} = false\n"))
            .collect();
        let text = format!("[scenario]\ntitle='t'\ngroup='se2'\n[draw]\n{all_off}");
        let loaded = crate::app::load_text(&text, "t.toml").unwrap();
        let d = &loaded.input.draw;
        // Every boolean of the table is among the switches (all false here).
        assert!(
            ![
                d.axes,
                d.clouds,
                d.sample_axes,
                d.ellipsoids,
                d.bananas,
                d.orientation,
                d.trajectories
            ]
            .contains(&true)
        );
    }

    #[test]
    fn other_inputs_are_refused_with_a_clear_message() {
        let dir = std::env::temp_dir().join(format!("posecov-live-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let bag = dir.join("run.bag");
        std::fs::write(&bag, b"#ROSBAG V2.0\n").unwrap();
        let e = LiveDocument::open(bag.to_str().unwrap()).err().unwrap();
        assert!(e.to_string().contains("scenario files (.toml) only"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
