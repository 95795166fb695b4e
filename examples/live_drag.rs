//! What a fast slider drag streams in live mode (BENCHMARKS.md §6): edits every 8 ms (a mouse
//! at ~120 events a second) for 2 s through [`Live::apply`], into a memory sink; prints the
//! pictures finished during the drag and the bytes a viewer received.
//!
//! ```text
//! cargo run --release --example live_drag                       # the two cases of BENCHMARKS §6
//! cargo run --release --example live_drag -- camera_on_robot 'pose[0].cov.std_deg[2]' 20 40
//! ```

use std::collections::BTreeSet;
use std::time::{Duration, Instant};

use posecov::app::live::{Edit, EditValue, Live, LiveDocument};
use posecov::scene::Scene;
use posecov::sink::{RecordingIds, Sink, open_stream};

const DRAG: Duration = Duration::from_secs(2);
const EVENT: Duration = Duration::from_millis(8);

fn drag(name: &str, id: &str, from: f64, to: f64) {
    let doc = LiveDocument::open(name).expect("a bundled scenario or a scenario file");
    let (rec, guard) = open_stream(
        &Sink::Memory,
        &RecordingIds::for_scenario(name, 0),
        &Scene::new(name, ""),
    )
    .expect("memory sink");
    let live = Live::start(doc, rec, guard, Default::default());
    live.wait_done(0, Duration::from_secs(120));
    let start = Instant::now();
    let (mut edits, mut last) = (0u32, 0);
    let mut shown = BTreeSet::new();
    while start.elapsed() < DRAG {
        let t = start.elapsed().as_secs_f64() / DRAG.as_secs_f64();
        let edit = Edit {
            id: id.to_owned(),
            value: EditValue::Number(from + (to - from) * t),
        };
        last = live.apply(&edit).expect("the edit is valid");
        edits += 1;
        std::thread::sleep(EVENT);
        shown.extend(live.status().shown.filter(|&g| g > 0));
    }
    let status = live.wait_done(last, Duration::from_secs(120));
    let bytes = live
        .finish()
        .expect("the thread ends")
        .expect("memory bytes");
    println!(
        "{name}: {edits} edits of {id} in {:.1} s; {} pictures seen during the drag; {:.1} MB streamed; the last value's final picture {:.0} ms after its edit",
        DRAG.as_secs_f64(),
        shown.len(),
        bytes.len() as f64 / 1e6,
        status.final_picture_ms.unwrap_or(f64::NAN),
    );
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.as_slice() {
        [] => {
            drag("camera_on_robot", "pose[0].cov.std_deg[2]", 20.0, 40.0);
            drag(
                "na568_se2_odometry",
                "operation[0].noise.std[2]",
                0.05,
                0.15,
            );
        }
        [name, id, from, to] => drag(
            name,
            id,
            from.parse().expect("FROM is a number"),
            to.parse().expect("TO is a number"),
        ),
        _ => eprintln!("usage: live_drag [SCENARIO CONTROL_ID FROM TO]"),
    }
}
