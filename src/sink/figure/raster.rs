//! PNG and PDF from a figure's SVG: resvg renders, svg2pdf converts, both with the bundled font
//! only (no system fonts are read, so every machine gives the same bytes).

use super::FigureError;

/// The bundled font (Liberation Sans Regular, SIL Open Font License 1.1; `assets/fonts/`).
#[cfg(feature = "figure")]
const FONT: &[u8] = include_bytes!("../../../assets/fonts/LiberationSans-Regular.ttf");

/// Parses the SVG with the bundled font as the only one.
#[cfg(feature = "figure")]
fn tree(svg: &str) -> Result<resvg::usvg::Tree, FigureError> {
    let mut options = resvg::usvg::Options {
        font_family: super::svg::FONT_FAMILY.to_owned(),
        ..Default::default()
    };
    options.fontdb_mut().load_font_data(FONT.to_vec());
    resvg::usvg::Tree::from_str(svg, &options).map_err(|e| FigureError::Render(e.to_string()))
}

/// The SVG rendered to PNG, one pixel per SVG pixel.
#[cfg(feature = "figure")]
pub(super) fn png(svg: &str) -> Result<Vec<u8>, FigureError> {
    let tree = tree(svg)?;
    let size = tree.size().to_int_size();
    let mut pixmap =
        resvg::tiny_skia::Pixmap::new(size.width(), size.height()).ok_or_else(|| {
            FigureError::Render(format!("no {}×{} image", size.width(), size.height()))
        })?;
    resvg::render(
        &tree,
        resvg::tiny_skia::Transform::identity(),
        &mut pixmap.as_mut(),
    );
    pixmap
        .encode_png()
        .map_err(|e| FigureError::Render(e.to_string()))
}

/// The SVG converted to a one-page PDF (one SVG pixel = one point).
#[cfg(feature = "figure")]
pub(super) fn pdf(svg: &str) -> Result<Vec<u8>, FigureError> {
    let tree = tree(svg)?;
    let pdf = svg2pdf::to_pdf(
        &tree,
        svg2pdf::ConversionOptions::default(),
        svg2pdf::PageOptions::default(),
    )
    .map_err(|e| FigureError::Render(e.to_string()))?;
    Ok(sorted_references(pdf))
}

/// The PDF with every run of dictionary lines `/name N 0 R` sorted: svg2pdf writes resource
/// dictionaries in hash order, which differs between runs. Sorting lines within a run keeps
/// every object's length and offset (the cross-reference table stays right) and the meaning
/// (a dictionary has no order), and makes the same figure the same bytes.
#[cfg(feature = "figure")]
fn sorted_references(pdf: Vec<u8>) -> Vec<u8> {
    let reference = |line: &[u8]| {
        let Ok(text) = std::str::from_utf8(line) else {
            return false;
        };
        let mut parts = text.trim_start().split(' ');
        matches!(
            (parts.next(), parts.next(), parts.next(), parts.next(), parts.next()),
            (Some(name), Some(n), Some("0"), Some("R"), None)
                if name.starts_with('/') && !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit())
        )
    };
    let mut out: Vec<&[u8]> = Vec::new();
    let mut run: Vec<&[u8]> = Vec::new();
    for line in pdf.split(|b| *b == b'\n') {
        if reference(line) {
            run.push(line);
            continue;
        }
        run.sort_unstable();
        out.append(&mut run);
        out.push(line);
    }
    run.sort_unstable();
    out.append(&mut run);
    out.join(&b'\n')
}

#[cfg(not(feature = "figure"))]
pub(super) fn png(_: &str) -> Result<Vec<u8>, FigureError> {
    Err(FigureError::NoRenderer)
}

#[cfg(not(feature = "figure"))]
pub(super) fn pdf(_: &str) -> Result<Vec<u8>, FigureError> {
    Err(FigureError::NoRenderer)
}
