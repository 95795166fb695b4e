//! `posecov figure`: the SVG's structure against a golden summary, same seed same bytes (SVG,
//! PNG, PDF), a rendered PNG that shows the drawing, `--step`, `--plane`, the command line and
//! the gallery.
//!
//! Re-bless the golden summaries after an intended change with
//! `POSECOV_BLESS=1 cargo test --test figure`.

use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

use posecov::app::Overrides;
use posecov::app::figure::scene_of;
use posecov::scene::Scene;
use posecov::scene::layout::text_width;
use posecov::sink::figure::{FigureFormat, FigureOptions, Plane, Steps, render, svg};

#[path = "common/graph.rs"]
mod graph_common;

const BIN: &str = env!("CARGO_BIN_EXE_posecov");

fn scene(name: &str, samples: u64) -> Scene {
    let overrides = Overrides {
        samples: Some(samples),
        ..Default::default()
    };
    scene_of(name, &overrides).expect("scene")
}

/// What the SVG is made of: each element with its class, counted; every text.
fn structure(svg: &str) -> String {
    let mut counts: BTreeMap<String, usize> = BTreeMap::new();
    let mut class = Vec::<Option<String>>::new();
    let mut texts = Vec::new();
    let mut rest = svg;
    while let Some(start) = rest.find('<') {
        let end = rest[start..].find('>').expect("tag closes") + start;
        let tag = &rest[start + 1..end];
        if let Some(name) = tag.strip_prefix('/') {
            if name == "g" {
                class.pop();
            }
        } else {
            let name = tag.split([' ', '/']).next().unwrap_or_default();
            let own = tag
                .split("class=\"")
                .nth(1)
                .and_then(|c| c.split('"').next())
                .map(str::to_owned);
            if name == "g" {
                let inherited = class.last().cloned().flatten();
                class.push(own.clone().or(inherited));
            }
            let key = match own.or_else(|| class.last().cloned().flatten()) {
                Some(c) => format!("{name}.{c}"),
                None => name.to_owned(),
            };
            *counts.entry(key).or_default() += 1;
            if name == "text" {
                let body_end = rest[end..].find("</text>").expect("text closes") + end;
                texts.push(rest[end + 1..body_end].to_owned());
            }
        }
        rest = &rest[end + 1..];
    }
    let mut out = String::new();
    for (k, v) in counts {
        out.push_str(&format!("{k} {v}\n"));
    }
    for t in texts {
        out.push_str(&format!("text: {t}\n"));
    }
    out
}

fn golden(name: &str, actual: &str) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/golden")
        .join(name);
    if std::env::var_os("POSECOV_BLESS").is_some() {
        std::fs::write(&path, actual).expect("bless");
        return;
    }
    let expected = std::fs::read_to_string(&path).unwrap_or_default();
    assert_eq!(
        actual,
        expected,
        "{} differs (POSECOV_BLESS=1 to accept)",
        path.display()
    );
}

#[test]
fn camera_on_robot_has_its_legend_scale_and_regions() {
    let s = scene("camera_on_robot", 500);
    let text = svg(&s, &FigureOptions::default());
    let summary = structure(&text);
    // What every figure carries.
    assert!(text.starts_with("<svg") && text.ends_with("</svg>\n"));
    for needed in [
        "text: Camera on a robot: T_MC = T_MR · T_RC bends into a banana (SE(2))",
        "regions at 95 % confidence",
        "text: x (m)",
        "text: y (m)",
        "rect.frame",
        "g.scale-bar",
        "path.ellipse",
        "g.region",
        "path.cloud",
        "text: Monte Carlo samples (500)",
        "text: given (input): Exp-mapped 95 % region",
        "text: vector space (SSC): 95 % ellipse",
    ] {
        assert!(summary.contains(needed), "{needed:?} missing in\n{summary}");
    }
    golden("figure_camera_on_robot.txt", &summary);
}

#[test]
fn same_seed_same_bytes() {
    let options = FigureOptions {
        size: (400, 300),
        ..Default::default()
    };
    for format in [FigureFormat::Svg, FigureFormat::Png, FigureFormat::Pdf] {
        let a = render(&scene("vector_space_vs_lie", 300), &options, format).expect("a");
        let b = render(&scene("vector_space_vs_lie", 300), &options, format).expect("b");
        assert!(a == b, "{format:?} differs between two runs");
    }
    let pdf = render(&scene("camera_on_robot", 100), &options, FigureFormat::Pdf).expect("pdf");
    assert!(pdf.starts_with(b"%PDF"));
}

#[test]
fn the_png_shows_the_drawing() {
    let s = scene("camera_on_robot", 2000);
    let options = FigureOptions {
        size: (640, 400),
        ..Default::default()
    };
    let png = render(&s, &options, FigureFormat::Png).expect("png");
    let pixmap = resvg::tiny_skia::Pixmap::decode_png(&png).expect("decode");
    assert_eq!((pixmap.width(), pixmap.height()), (640, 400));
    let pixels = pixmap.pixels();
    let white = pixels
        .iter()
        .filter(|p| p.red() > 250 && p.green() > 250 && p.blue() > 250)
        .count();
    let distinct: std::collections::BTreeSet<[u8; 3]> = pixels
        .iter()
        .map(|p| [p.red(), p.green(), p.blue()])
        .collect();
    let ink = 1.0 - white as f64 / pixels.len() as f64;
    assert!(ink > 0.05 && ink < 0.8, "{:.1} % ink", 100.0 * ink);
    assert!(distinct.len() > 50, "{} colours", distinct.len());
    // The first-order region's colour (sky blue, under the region's opacity) is on the page.
    let bluish = pixels
        .iter()
        .filter(|p| {
            let (r, g, b) = (
                i32::from(p.red()),
                i32::from(p.green()),
                i32::from(p.blue()),
            );
            b > r + 30 && b > 180 && g > r
        })
        .count();
    assert!(bluish > 200, "{bluish} sky-blue pixels");
}

#[test]
fn all_steps_are_numbered_and_one_step_is_the_viewers_state() {
    let s = scene("na568_se2_odometry", 200);
    let all = structure(&svg(&s, &FigureOptions::default()));
    let one = structure(&svg(
        &s,
        &FigureOptions {
            steps: Steps::At(3),
            ..Default::default()
        },
    ));
    let count = |summary: &str, key: &str| {
        summary
            .lines()
            .find_map(|l| l.strip_prefix(&format!("{key} ")))
            .map_or(0, |n| n.parse::<usize>().expect("count"))
    };
    assert!(all.contains("steps 0–7 at once"), "{all}");
    assert!(one.contains("step 3"), "{one}");
    assert!(count(&all, "path.ellipse") > count(&one, "path.ellipse"));
    // Every step's frame is numbered in the all-steps figure.
    for k in 0..=7 {
        assert!(all.contains(&format!("text: {k}\n")), "step {k}:\n{all}");
    }
    assert!(count(&one, "text.label") < count(&all, "text.label"));
    // The plots are drawn beside it.
    assert!(all.contains("trace"), "{all}");
}

#[test]
fn a_log_has_a_panel_per_view_and_its_last_message_once() {
    // test2.bag (robot_localization): one Odometry topic in `odom`, 200 drawn messages. The
    // viewer shows two views: the whole log, and the robot scale at the time cursor, where
    // each message is drawn at the origin. A figure gives each view its own panel and, of
    // each message's drawing, the last (where the viewer opens): one σ label, not 200 of them
    // piled at the origin.
    let s = scene_of(
        "tests/data/robot_localization/test2.bag",
        &Overrides::default(),
    )
    .expect("scene");
    // A third: the IMU's orientation spray (issue 32).
    assert_eq!(
        s.views.len(),
        3,
        "{:?}",
        s.views.iter().map(|v| &v.name).collect::<Vec<_>>()
    );
    let text = svg(&s, &FigureOptions::default());
    let summary = structure(&text);
    for view in &s.views {
        let shown = summary
            .lines()
            .any(|l| l.starts_with(&format!("text: {}", view.name.split(':').next().unwrap())));
        assert!(
            shown,
            "panel title for {:?} missing in\n{summary}",
            view.name
        );
    }
    assert_eq!(
        text.matches("clip-path=\"url(#world").count(),
        3,
        "{summary}"
    );
    let labels: Vec<&str> = summary
        .lines()
        .filter(|l| l.starts_with("text: message "))
        .collect();
    assert_eq!(labels.len(), 1, "{labels:?}");
    assert!(labels[0].contains("σx 31.6"), "{labels:?}");
    assert!(summary.contains("the last message"), "{summary}");
}

#[test]
fn planes_show_their_axes() {
    let s = scene("se3_global_vs_local", 200);
    for (plane, x, y) in [(Plane::Xz, "x (m)", "z (m)"), (Plane::Yz, "y (m)", "z (m)")] {
        let text = svg(
            &s,
            &FigureOptions {
                plane,
                ..Default::default()
            },
        );
        assert!(
            text.contains(&format!(">{x}<")) && text.contains(&format!(">{y}<")),
            "{plane:?}"
        );
    }
}

#[test]
fn the_command_writes_each_format_and_refuses_others() {
    let dir = std::env::temp_dir().join(format!("posecov-figure-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    for (ext, magic) in [
        ("svg", &b"<svg"[..]),
        ("png", &b"\x89PNG"[..]),
        ("pdf", &b"%PDF"[..]),
    ] {
        let out = dir.join(format!("camera.{ext}"));
        let run = Command::new(BIN)
            .args([
                "figure",
                "camera_on_robot",
                "--samples",
                "200",
                "--size",
                "320x200",
                "-o",
            ])
            .arg(&out)
            .output()
            .expect("run");
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        assert!(std::fs::read(&out).expect("written").starts_with(magic));
    }
    let bad = Command::new(BIN)
        .args(["figure", "camera_on_robot", "-o"])
        .arg(dir.join("camera.jpg"))
        .output()
        .expect("run");
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(
        !bad.status.success() && err.contains(".svg, .png or .pdf"),
        "{err}"
    );
    assert!(!dir.join("camera.jpg").exists());
    let plane = Command::new(BIN)
        .args(["figure", "camera_on_robot", "--plane", "xw", "-o"])
        .arg(dir.join("c.svg"))
        .output()
        .expect("run");
    let err = String::from_utf8_lossy(&plane.stderr);
    assert!(
        !plane.status.success() && err.contains("use xy, xz or yz"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn the_gallery_has_every_bundled_example_and_the_figures_page_shows_it() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let page = std::fs::read_to_string(root.join("docs/guide/figures.md")).expect("figures page");
    for example in posecov::input::examples() {
        let file = format!("docs/gallery/{}.png", example.name);
        assert!(
            root.join(&file).is_file(),
            "{file} missing: cargo run --release --example gallery"
        );
        // The page sits in docs/guide/: it links the picture as ../gallery/NAME.png.
        let link = format!("../gallery/{}.png", example.name);
        assert!(
            page.contains(&link),
            "docs/guide/figures.md does not show {file}"
        );
    }
}

/// A label's box in a figure: (left, top, right, bottom) of one `text.label` line, from its
/// place and font size and the bundled font's advance widths ([`text_width`]).
fn label_boxes(svg: &str) -> Vec<(String, [f64; 4])> {
    let attr = |tag: &str, name: &str| -> f64 {
        let at = tag.find(&format!(" {name}=\"")).expect("attribute") + name.len() + 3;
        tag[at..at + tag[at..].find('"').expect("closes")]
            .parse()
            .expect("number")
    };
    svg.match_indices("<text class=\"label\"")
        .map(|(start, _)| {
            let open = &svg[start..start + svg[start..].find('>').expect("tag closes")];
            let body = &svg[start + open.len() + 1..];
            let words = body[..body.find("</text>").expect("closes")].to_owned();
            let (x, y, f) = (attr(open, "x"), attr(open, "y"), attr(open, "font-size"));
            let w = text_width(&words.replace("&lt;", "<").replace("&amp;", "&"), f);
            (words, [x, y - 0.8 * f, x + w, y + 0.25 * f])
        })
        .collect()
}

/// The figure of a generated graph of benchmark size (g2o text in a temporary file).
fn generated_figure(name: &str, g2o: &str) -> String {
    let dir = std::env::temp_dir().join(format!("posecov-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let path = dir.join(format!("{name}.g2o"));
    std::fs::write(&path, g2o).expect("written");
    let overrides = Overrides {
        samples: Some(64),
        ..Default::default()
    };
    let scene = scene_of(path.to_str().expect("utf-8"), &overrides).expect("scene");
    svg(&scene, &FigureOptions::default())
}

#[test]
fn labels_of_benchmark_size_generated_graphs_never_overlap() {
    for (name, g2o) in [
        (
            "manhattan3500",
            graph_common::to_g2o(&graph_common::manhattan_walk(3500, 11)),
        ),
        (
            "sphere2500",
            graph_common::to_g2o(&graph_common::sphere(50, 50, 11)),
        ),
    ] {
        let text = generated_figure(name, &g2o);
        let boxes = label_boxes(&text);
        // The worst loop closure, the largest marginal, the first and last pose: in the after
        // view and in the close-ups, and the before view's own.
        let words: Vec<&str> = boxes.iter().map(|(w, _)| w.as_str()).collect();
        assert!(
            words.iter().any(|w| w.contains("worst"))
                && words.iter().any(|w| w.contains("largest")),
            "{name}: {words:?}"
        );
        // At most four labels a view (four views), each in at most three lines, besides the
        // chain's step numbers.
        let named = words.iter().filter(|w| w.parse::<u64>().is_err()).count();
        assert!(
            named <= 48,
            "{name}: at most a few labels a panel: {words:?}"
        );
        for (i, (a, p)) in boxes.iter().enumerate() {
            for (b, q) in &boxes[..i] {
                let apart = p[2] <= q[0] || q[2] <= p[0] || p[3] <= q[1] || q[3] <= p[1];
                assert!(apart, "{name}: {a:?} {p:?} overlaps {b:?} {q:?}");
            }
            // Inside the world panels: left of the legend column, below the title.
            assert!(
                p[2] <= 1280.0 * (1.0 - 0.34) && p[1] >= 0.0,
                "{name}: {a:?} at {p:?}"
            );
        }
    }
}
