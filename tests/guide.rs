//! The user guide's commands stay true: every command in a shell code block of `README.md` and
//! `docs/guide/*.md` that writes a file or prints (`posecov report`, `posecov check`,
//! `posecov figure`, `--save`) is run with the built binary, from the repository root, with
//! its output paths (`-o`, `--save`, `> FILE`) moved into a temporary directory; it must exit
//! as the page documents (`check` 0, or 1 on a log with a defect, the exit-code table in
//! `docs/guide/cli.md`; every other command 0) and produce its output (a non-empty file, or
//! non-empty stdout, valid JSON for `--json`).
//!
//! The guide's placeholder inputs stand for committed files: `run.mcap` for
//! `tests/data/mcap/amcl_tf.mcap` (it has `/amcl_pose` and `/odom`), `run.bag` for
//! `tests/data/robot_localization/test2.bag`, `rosbag2_2024_05_01/` for `tests/data/ros2/arc_v9` (a ROS 2 bag directory), `run_0.db3` for its
//! `.db3`, `logs/` for `tests/data/mcap/` and `logs/*.bag`
//! for the bags of `tests/data/robot_localization/`.
//!
//! The CLI reference's `posecov --help` block is compared with what the binary prints.
//!
//! Skipped, and why: commands that open a viewer (no `report`, `check`, `figure` or `--save`:
//! they need `rerun` or a browser), `live` (a server and a viewer), and `--reference` (the
//! guide's reference files and ground-truth topic are the user's; `tests/nees.rs` runs NEES on
//! a generated log). No command reads ../shared.

use std::path::{Path, PathBuf};
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_posecov");

/// One command of a page: its page, its line and its words after `posecov`.
struct GuideCommand {
    page: String,
    line: usize,
    words: Vec<String>,
}

/// The pages whose shell blocks are run: the README and every page of the guide.
fn pages(root: &Path) -> Vec<PathBuf> {
    let mut pages = vec![root.join("README.md")];
    let mut guide: Vec<PathBuf> = std::fs::read_dir(root.join("docs/guide"))
        .expect("docs/guide")
        .map(|entry| entry.expect("entry").path())
        .filter(|path| path.extension().is_some_and(|ext| ext == "md"))
        .collect();
    guide.sort();
    pages.extend(guide);
    pages
}

/// Every `posecov …` or `cargo run --release -- …` line inside a ```sh block, comment cut.
fn commands(root: &Path, page: &Path) -> Vec<GuideCommand> {
    let text = std::fs::read_to_string(page).expect("page");
    let name = page
        .strip_prefix(root)
        .unwrap_or(page)
        .display()
        .to_string();
    let mut found = Vec::new();
    let mut in_sh = false;
    for (i, line) in text.lines().enumerate() {
        let trimmed = line.trim();
        if trimmed.starts_with("```") {
            in_sh = !in_sh && trimmed == "```sh";
            continue;
        }
        if !in_sh {
            continue;
        }
        let code = match trimmed.find(" #") {
            Some(at) => trimmed[..at].trim(),
            None => trimmed,
        };
        let rest = code
            .strip_prefix("cargo run --release -- ")
            .or_else(|| code.strip_prefix("posecov "));
        if let Some(rest) = rest {
            found.push(GuideCommand {
                page: name.clone(),
                line: i + 1,
                words: rest.split_whitespace().map(str::to_string).collect(),
            });
        }
    }
    found
}

/// Why a command is not run here, or `None` when it is.
fn skipped(words: &[String]) -> Option<&'static str> {
    let first = words.first().map(String::as_str);
    if first == Some("live") {
        return Some("live mode serves a page and opens a viewer");
    }
    if words.iter().any(|w| w.starts_with("ws://")) {
        return Some("reads a running robot (tests/live_ws.rs runs these against a real server)");
    }
    if words.iter().any(|w| w == "--reference") {
        return Some("the reference is the user's (tests/nees.rs runs NEES)");
    }
    let writes =
        matches!(first, Some("report" | "check" | "figure")) || words.iter().any(|w| w == "--save");
    if !writes {
        return Some("opens a viewer");
    }
    None
}

/// The committed file a placeholder input stands for, globs expanded.
fn inputs(word: &str, root: &Path) -> Vec<String> {
    let word = match word {
        "run.mcap" => "tests/data/mcap/amcl_tf.mcap",
        "run.bag" => "tests/data/robot_localization/test2.bag",
        "logs/" => "tests/data/mcap/",
        "logs/*.bag" => "tests/data/robot_localization/*.bag",
        "rosbag2_2024_05_01/" => "tests/data/ros2/arc_v9",
        "run_0.db3" => "tests/data/ros2/arc_v9/arc_v9.db3",
        other => other,
    };
    match word.split_once("/*.") {
        Some((dir, ext)) => {
            let mut files: Vec<String> = std::fs::read_dir(root.join(dir))
                .expect("glob directory")
                .map(|entry| entry.expect("entry").path())
                .filter(|path| path.extension().is_some_and(|e| e == ext))
                .map(|path| format!("{dir}/{}", path.file_name().unwrap().to_string_lossy()))
                .collect();
            files.sort();
            assert!(!files.is_empty(), "{word} matches nothing");
            files
        }
        None => vec![word.to_string()],
    }
}

#[test]
fn every_guide_command_that_writes_or_prints_runs() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let tmp = Path::new(env!("CARGO_TARGET_TMPDIR")).join("guide");
    std::fs::remove_dir_all(&tmp).ok();
    std::fs::create_dir_all(&tmp).expect("temp dir");
    let mut ran = Vec::new();
    for page in pages(root) {
        for command in commands(root, &page) {
            let place = format!(
                "{}:{}: posecov {}",
                command.page,
                command.line,
                command.words.join(" ")
            );
            if let Some(why) = skipped(&command.words) {
                eprintln!("skipped ({why}): {place}");
                continue;
            }
            let mut args: Vec<String> = Vec::new();
            let mut outputs: Vec<PathBuf> = Vec::new();
            let mut stdout_file = None;
            let mut words = command.words.iter();
            while let Some(word) = words.next() {
                match word.as_str() {
                    "-o" | "--output" | "--save" => {
                        let file = words.next().expect("an output path");
                        let moved = tmp.join(Path::new(file).file_name().expect("file name"));
                        std::fs::remove_file(&moved).ok();
                        args.push(word.clone());
                        args.push(moved.display().to_string());
                        outputs.push(moved);
                    }
                    ">" => {
                        let file = words.next().expect("a redirect target");
                        stdout_file = Some(tmp.join(file));
                    }
                    _ => args.extend(inputs(word, root)),
                }
            }
            let run = Command::new(BIN)
                .args(&args)
                .current_dir(root)
                .output()
                .unwrap_or_else(|e| panic!("{place}: {e}"));
            let code = run.status.code();
            let stderr = String::from_utf8_lossy(&run.stderr);
            let allowed: &[i32] = if args[0] == "check" { &[0, 1] } else { &[0] };
            assert!(
                code.is_some_and(|c| allowed.contains(&c)),
                "{place}: exit {code:?}, expected one of {allowed:?}\n{stderr}"
            );
            let stdout = String::from_utf8_lossy(&run.stdout).to_string();
            if let Some(file) = &stdout_file {
                std::fs::write(file, &stdout).expect("write the redirect");
                outputs.push(file.clone());
            }
            for file in &outputs {
                let size = std::fs::metadata(file).map(|m| m.len()).unwrap_or(0);
                assert!(
                    size > 0,
                    "{place}: {} not written\n{stderr}",
                    file.display()
                );
            }
            if matches!(args[0].as_str(), "report" | "check") {
                assert!(
                    !stdout.trim().is_empty(),
                    "{place}: printed nothing\n{stderr}"
                );
            }
            if args.iter().any(|a| a == "--json") {
                for value in
                    serde_json::Deserializer::from_str(&stdout).into_iter::<serde_json::Value>()
                {
                    let value = value.unwrap_or_else(|e| panic!("{place}: not JSON: {e}"));
                    assert!(value.get("error").is_none(), "{place}: {value}");
                }
            }
            ran.push(place);
        }
    }
    eprintln!("ran {} guide commands:\n{}", ran.len(), ran.join("\n"));
    // The figures page (4), a graph report, the logs page's report/check/--save lines and the
    // README's --save: a parser that found nothing would pass silently without this floor.
    assert!(
        ran.len() >= 12,
        "only {} guide commands found: {ran:?}",
        ran.len()
    );
    std::fs::remove_dir_all(&tmp).ok();
}

/// The CLI reference's `posecov --help` block is what the binary prints.
#[test]
fn the_cli_reference_shows_the_binarys_help() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let page = std::fs::read_to_string(root.join("docs/guide/cli.md")).expect("cli.md");
    let heading = "## Every option: `posecov --help`";
    let after = &page[page.find(heading).expect("the --help section")..];
    let start = after.find("```text\n").expect("a text block") + "```text\n".len();
    let end = start + after[start..].find("\n```").expect("closed block");
    let help = Command::new(BIN)
        .arg("--help")
        .output()
        .expect("run --help");
    assert!(help.status.success());
    let printed = String::from_utf8_lossy(&help.stdout);
    assert_eq!(
        &after[start..end],
        printed.trim_end_matches('\n'),
        "docs/guide/cli.md: paste `posecov --help` again"
    );
}
