//! ROS 2 bags in SQLite storage (issue 32): the bags under tests/data/ros2 (written by PyPI
//! `rosbags`, tests/data/ros2/make_bags.py) read as the MCAP of the same messages is, through
//! the command line — `report --json` the same apart from `format` and the name, `check` with
//! the same exit code, `--reference`, several at once — and every bad input located.

use std::path::{Path, PathBuf};

use serde_json::Value;

mod posecov_cli;
use posecov_cli::run;

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ros2");
const BAGS: [&str; 6] = [
    "arc_v9",
    "arc_v9/arc_v9.db3",
    "arc_v8_split",
    "arc_zstd_file",
    "arc_zstd_message",
    "arc_humble",
];

fn data(name: &str) -> String {
    format!("{DATA}/{name}")
}

/// A report with its name and format taken out (the rest must not depend on the container).
fn report(path: &str, extra: &[&str]) -> (Value, String) {
    let mut args = vec!["report", path, "--json"];
    args.extend(extra);
    let (code, out, err) = run(&args);
    assert_eq!(code, Some(0), "{path}: {err}");
    let mut v: Value = serde_json::from_str(&out).expect("JSON");
    let format = v["format"].as_str().unwrap().to_owned();
    let o = v.as_object_mut().unwrap();
    o.remove("format");
    o.remove("scenario");
    o["meta"].as_object_mut().unwrap().remove("title");
    (v, format)
}

/// A scratch directory of its own per test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("posecov-db3-{name}-{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A copy of the bag directory `name` under `to`.
fn copy_bag(name: &str, to: &Path) -> PathBuf {
    let out = to.join(name);
    std::fs::create_dir_all(&out).unwrap();
    for entry in std::fs::read_dir(data(name)).unwrap() {
        let p = entry.unwrap().path();
        std::fs::copy(&p, out.join(p.file_name().unwrap())).unwrap();
    }
    out
}

fn edit_metadata(bag: &Path, from: &str, to: &str) {
    let path = bag.join("metadata.yaml");
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains(from), "{from} in {text}");
    std::fs::write(&path, text.replace(from, to)).unwrap();
}

#[test]
fn every_db3_bag_reports_what_the_mcap_of_the_same_messages_reports() {
    for reference in [&[][..], &["--reference", "/truth"][..]] {
        let (mcap, format) = report(&data("arc.mcap"), reference);
        assert_eq!(format, "mcap");
        for bag in BAGS {
            let (db3, format) = report(&data(bag), reference);
            assert_eq!(format, "ros2_sqlite", "{bag}");
            assert_eq!(db3, mcap, "{bag} {reference:?}");
        }
        if !reference.is_empty() {
            let odom = mcap["topics"]
                .as_array()
                .unwrap()
                .iter()
                .find(|t| t["name"] == "/odom")
                .unwrap();
            assert_eq!(odom["consistency"]["messages"], 100);
        }
    }
}

#[test]
fn check_and_several_bags_at_once_work_as_for_mcap() {
    let (code, out, err) = run(&["check", &data("arc_humble")]);
    assert_eq!(code, Some(0), "{err}");
    assert!(
        out.contains("ok (2 pose topic(s), 2 sensor topic(s), 245 messages"),
        "{out}"
    );
    let (mcap_code, ..) = run(&["check", &data("arc.mcap")]);
    assert_eq!(code, mcap_code);
    // The directory holds five bag directories and arc.mcap: six logs, one line each.
    let (code, out, err) = run(&["report", DATA, "--json"]);
    assert_eq!(code, Some(0), "{err}");
    let lines: Vec<Value> = out
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 6, "{out}");
    let sqlite = lines
        .iter()
        .filter(|l| l["format"] == "ros2_sqlite")
        .count();
    assert_eq!(sqlite, 5);
}

#[test]
fn a_bag_directory_in_mcap_storage_is_read_through_its_metadata() {
    let dir = scratch("mcap-storage");
    let bag = dir.join("arc_mcap");
    std::fs::create_dir_all(&bag).unwrap();
    std::fs::copy(data("arc.mcap"), bag.join("arc_mcap_0.mcap")).unwrap();
    let meta = std::fs::read_to_string(data("arc_v9/metadata.yaml"))
        .unwrap()
        .replace("sqlite3", "mcap")
        .replace("arc_v9.db3", "arc_mcap_0.mcap");
    std::fs::write(bag.join("metadata.yaml"), meta).unwrap();
    let (v, format) = report(bag.to_str().unwrap(), &[]);
    assert_eq!(format, "mcap");
    assert_eq!(v, report(&data("arc.mcap"), &[]).0);
}

#[test]
fn a_file_that_is_not_sqlite_or_is_damaged_is_located() {
    let dir = scratch("damaged");
    // Not SQLite at all, named .db3.
    let text = dir.join("notes.db3");
    std::fs::write(&text, "a text file\n").unwrap();
    let (code, _, err) = run(&["check", text.to_str().unwrap()]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("notes.db3"), "{err}");
    // SQLite's magic, then nothing a database holds.
    let stub = dir.join("stub.db3");
    std::fs::write(&stub, b"SQLite format 3\0rest of the file").unwrap();
    let (code, _, err) = run(&["check", stub.to_str().unwrap()]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("stub.db3: ") && err.contains("SQLite"),
        "{err}"
    );
    // A real bag with a page of its messages overwritten: the table, the last row read and
    // SQLite's check of the file.
    let mut bytes = std::fs::read(data("arc_v9/arc_v9.db3")).unwrap();
    let page = 4096;
    let at = bytes.len() / page / 2 * page;
    bytes[at..at + page].fill(0xa5);
    let damaged = dir.join("damaged.db3");
    std::fs::write(&damaged, &bytes).unwrap();
    let (code, _, err) = run(&["report", damaged.to_str().unwrap()]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("damaged.db3: "), "{err}");
    assert!(err.contains("table messages, after row id "), "{err}");
    assert!(
        err.contains(&format!("damaged: page {} (table messages)", at / page + 1)),
        "{err}"
    );
    // Cut short in the middle.
    let cut = dir.join("cut.db3");
    let whole = std::fs::read(data("arc_v9/arc_v9.db3")).unwrap();
    std::fs::write(&cut, &whole[..whole.len() / 2]).unwrap();
    let (code, _, err) = run(&["report", cut.to_str().unwrap()]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("cut.db3: ") && err.contains("the file is cut short"),
        "{err}"
    );
}

#[test]
fn metadata_naming_missing_files_or_another_storage_is_located() {
    let dir = scratch("metadata");
    let bag = copy_bag("arc_v9", &dir);
    edit_metadata(&bag, "- arc_v9.db3", "- arc_v9_gone.db3");
    let (code, _, err) = run(&["check", bag.to_str().unwrap()]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains(
            "metadata.yaml: line 16, relative_file_paths[0]: arc_v9_gone.db3: no such file"
        ),
        "{err}"
    );
    let bag = copy_bag("arc_humble", &dir);
    edit_metadata(
        &bag,
        "storage_identifier: sqlite3",
        "storage_identifier: rosbag_v2",
    );
    let (code, _, err) = run(&["report", bag.to_str().unwrap(), "--json"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("metadata.yaml: line 18, storage_identifier: \"rosbag_v2\": posecov reads rosbag2 storage sqlite3 or mcap"),
        "{err}"
    );
    // A split bag whose middle file is missing: named before anything is read.
    let bag = copy_bag("arc_v8_split", &dir);
    std::fs::rename(
        bag.join("arc_v8_split_1.db3"),
        bag.join("arc_v8_split_2.db3"),
    )
    .unwrap();
    edit_metadata(
        &bag,
        "- arc_v8_split_1.db3\n",
        "- arc_v8_split_1.db3\n  - arc_v8_split_2.db3\n",
    );
    let (code, _, err) = run(&["check", bag.to_str().unwrap()]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("relative_file_paths[1]: arc_v8_split_1.db3: no such file")
            && err.contains("file 2 of 3: a middle file of this bag is missing"),
        "{err}"
    );
}

#[test]
fn an_unknown_compression_is_located() {
    let dir = scratch("compression");
    let bag = copy_bag("arc_zstd_message", &dir);
    edit_metadata(&bag, "compression_format: zstd", "compression_format: lz4");
    let (code, _, err) = run(&["check", bag.to_str().unwrap()]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("metadata.yaml: line 2, compression_format: \"lz4\""),
        "{err}"
    );
    let bag = dir.join("mode");
    std::fs::rename(copy_bag("arc_zstd_file", &dir), &bag).unwrap();
    edit_metadata(&bag, "compression_mode: file", "compression_mode: chunk");
    let (code, _, err) = run(&["check", bag.to_str().unwrap()]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("compression_mode: \"chunk\""), "{err}");
    // Metadata that says zstd messages over a bag whose messages are not.
    let bag = copy_bag("arc_v9", &dir);
    edit_metadata(&bag, "compression_mode: ''", "compression_mode: message");
    edit_metadata(&bag, "compression_format: ''", "compression_format: zstd");
    let (code, _, err) = run(&["check", bag.to_str().unwrap()]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("arc_v9.db3: table messages, row id 1 (topic /truth): ")
            && err.contains("not a zstd frame"),
        "{err}"
    );
}

#[test]
fn rows_that_do_not_decode_are_counted_and_named_as_in_mcap() {
    let dir = scratch("rows");
    let bag = copy_bag("arc_v9", &dir);
    let db = rusqlite::Connection::open(bag.join("arc_v9.db3")).unwrap();
    // The fourth /odom message: four bytes that are no Odometry.
    db.execute(
        "UPDATE messages SET data = x'00010000' WHERE id = (SELECT m.id FROM messages m \
         JOIN topics t ON m.topic_id = t.id WHERE t.name = '/odom' ORDER BY m.id LIMIT 1 OFFSET 3)",
        [],
    )
    .unwrap();
    drop(db);
    let (code, out, err) = run(&["check", bag.to_str().unwrap()]);
    assert_eq!(code, Some(1), "{out}{err}");
    assert!(
        err.contains("topic /odom, message 3") && err.contains("undecodable"),
        "{err}"
    );
    // A row on a topic id the topics table does not declare: located at its row.
    let bag = dir.join("orphan");
    std::fs::rename(copy_bag("arc_humble", &dir), &bag).unwrap();
    let db = rusqlite::Connection::open(bag.join("arc_humble_0.db3")).unwrap();
    db.execute("UPDATE messages SET topic_id = 99 WHERE id = 7", [])
        .unwrap();
    drop(db);
    let (code, _, err) = run(&["report", bag.to_str().unwrap()]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains(
            "arc_humble_0.db3: table messages, row id 7: a message on topic id 99 that the file never declares"
        ),
        "{err}"
    );
}

#[test]
fn a_file_compressed_bag_cut_short_inside_is_located_at_its_own_file() {
    // rosbag2's `file` compression: the database is decompressed in memory (no temporary
    // file). A database cut short inside its zstd stream is named by the bag's own file.
    let dir = scratch("zstd-file-cut");
    let bag = copy_bag("arc_zstd_file", &dir);
    let file = bag.join("arc_zstd_file.db3.zstd");
    let image = zstd::decode_all(std::fs::File::open(&file).unwrap()).unwrap();
    let cut = &image[..image.len() / 2];
    std::fs::write(&file, zstd::encode_all(cut, 3).unwrap()).unwrap();
    let (code, _, err) = run(&["check", bag.to_str().unwrap()]);
    assert_eq!(code, Some(2), "{err}");
    // Named by the bag's file, not a decompressed copy.
    let named = format!("error: {}: ", file.display());
    assert!(
        err.starts_with(&named) && err.contains("the file is cut short"),
        "{err}"
    );
    // A zstd stream cut short itself: said as such.
    let packed = std::fs::read(&file).unwrap();
    std::fs::write(&file, &packed[..packed.len() / 2]).unwrap();
    let (code, _, err) = run(&["check", bag.to_str().unwrap()]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.starts_with(&named) && err.contains("does not decompress"),
        "{err}"
    );
}

#[test]
fn a_bag_of_many_batches_is_read_whole_in_order_and_ctrl_c_stops_it() {
    use posecov::input::log::{LogOptions, read_log};
    use std::sync::atomic::{AtomicBool, Ordering};
    // arc_v9 doubled six times over (245 × 64 = 15 680 rows, stamps shifted): many of the
    // batches the SQLite thread hands to the decoding one (512 rows each).
    let dir = scratch("batches");
    let bag = copy_bag("arc_v9", &dir);
    let file = bag.join("arc_v9.db3");
    let db = rusqlite::Connection::open(&file).unwrap();
    for k in 0..6 {
        db.execute(
            &format!(
                "INSERT INTO messages (topic_id, timestamp, data) SELECT topic_id, \
                 timestamp + {} * 1000000000, data FROM messages ORDER BY id",
                100 << k
            ),
            [],
        )
        .unwrap();
    }
    drop(db);
    let whole = read_log(&file, &LogOptions::default(), &mut |_, _| {}, None).unwrap();
    assert!(!whole.cancelled);
    assert_eq!(whole.messages_total, 245 * 64);
    let counts: Vec<(&str, u64)> = whole
        .topics
        .iter()
        .map(|t| (t.name.as_str(), t.count))
        .collect();
    assert_eq!(counts, [("/amcl_pose", 25 * 64), ("/odom", 100 * 64)]);
    // Ctrl-C at the first progress report (row 4 096): what was read is kept, the reading
    // thread stops (the read returns), nothing after is read.
    let cancel = AtomicBool::new(false);
    let part = read_log(
        &file,
        &LogOptions::default(),
        &mut |done, _| {
            if done > 0 {
                cancel.store(true, Ordering::Relaxed)
            }
        },
        Some(&cancel),
    )
    .unwrap();
    assert!(part.cancelled);
    assert!(
        part.messages_total >= 4096 && part.messages_total < 245 * 64,
        "{}",
        part.messages_total
    );
    std::fs::remove_dir_all(&dir).ok();
}
