//! Writes the pose-graph pictures of the docs gallery into `docs/gallery/` (or the folder
//! given): `posecov figure` of two generated graphs of benchmark size — a seeded 2-D Manhattan
//! walk of 3 500 poses (`graph_manhattan3500.png`) and a 3-D sphere of 2 500 poses, 50 rings of
//! 50 (`graph_sphere2500.png`) — made by the tests' generators (`tests/common/graph.rs`). The
//! shared benchmark graphs carry no licence: neither they nor pictures of them are in the
//! repository.
//!
//! ```text
//! cargo run --release --example graph_gallery [-- DIR]
//! ```

#[path = "../tests/common/graph.rs"]
mod graph_common;

use std::path::PathBuf;

use posecov::app::Overrides;
use posecov::sink::figure::FigureOptions;

fn main() -> anyhow::Result<()> {
    let dir = std::env::args_os()
        .nth(1)
        .map_or_else(|| PathBuf::from("docs/gallery"), PathBuf::from);
    let dir = std::path::absolute(dir)?;
    std::fs::create_dir_all(&dir)?;
    let options = FigureOptions {
        size: (1200, 750),
        ..FigureOptions::default()
    };
    // The graphs are written to a scratch folder and opened by their file names, so that the
    // figures' titles name no machine's path.
    let scratch =
        std::env::temp_dir().join(format!("posecov-graph-gallery-{}", std::process::id()));
    std::fs::create_dir_all(&scratch)?;
    std::env::set_current_dir(&scratch)?;
    let graphs = [
        (
            "manhattan3500",
            graph_common::to_g2o(&graph_common::manhattan_walk(3500, 11)),
        ),
        (
            "sphere2500",
            graph_common::to_g2o(&graph_common::sphere(50, 50, 11)),
        ),
    ];
    for (name, text) in graphs {
        let file = format!("{name}.g2o");
        std::fs::write(&file, text)?;
        let out = dir.join(format!("graph_{name}.png"));
        posecov::app::figure::figure(&file, &Overrides::default(), &options, &out)?;
        println!("{}", out.display());
    }
    Ok(())
}
