//! Writes the figure gallery: one PNG per bundled example into `docs/gallery/` (or the folder
//! given), each as `posecov figure NAME -o NAME.png` would write it, with the inputs' own seeds.
//!
//! ```text
//! cargo run --release --example gallery [-- DIR]
//! ```

use std::path::PathBuf;

use posecov::sink::figure::FigureOptions;

fn main() -> anyhow::Result<()> {
    let dir = std::env::args_os()
        .nth(1)
        .map_or_else(|| PathBuf::from("docs/gallery"), PathBuf::from);
    let options = FigureOptions {
        size: (1200, 750),
        ..FigureOptions::default()
    };
    for path in posecov::app::figure::gallery(&dir, &options)? {
        println!("{}", path.display());
    }
    Ok(())
}
