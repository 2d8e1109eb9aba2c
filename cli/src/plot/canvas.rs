//! The drawing surface: palette, the vendored font, and a white canvas encoded as PNG.

use super::{HEIGHT, WIDTH};
use plotters::prelude::*;
use plotters::style::{FontStyle, register_font};
use projfluid::Error;
use std::path::Path;
use std::sync::OnceLock;

/// Colours of series 0, 1, … (repeating): the Tableau 10 palette.
const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// The family name the vendored font is registered under.
pub(super) const FONT: &str = "sans-serif";

pub(super) fn colour(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// Registers the vendored DejaVu Sans with plotters, once per process.
fn ensure_font() -> Result<(), Error> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| {
        let bytes: &'static [u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");
        register_font(FONT, FontStyle::Normal, bytes).is_ok()
    });
    if ok {
        Ok(())
    } else {
        Err(Error::Io(
            "the vendored chart font could not be loaded".into(),
        ))
    }
}

pub(super) type Area<'a> = DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>;

/// Draws with `draw` on a white 800×500 canvas and writes the PNG to `path`.
pub(super) fn render(
    path: &Path,
    draw: impl FnOnce(&Area) -> Result<(), String>,
) -> Result<(), Error> {
    ensure_font()?;
    let mut rgb = vec![0u8; (WIDTH * HEIGHT * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (WIDTH, HEIGHT)).into_drawing_area();
        let drawn = root
            .fill(&WHITE)
            .map_err(|e| e.to_string())
            .and_then(|()| draw(&root))
            .and_then(|()| root.present().map_err(|e| e.to_string()));
        drawn.map_err(|e| Error::Io(format!("cannot draw chart {}: {e}", path.display())))?;
    }
    let png = encode_png(&rgb)
        .map_err(|e| Error::Io(format!("cannot encode chart {}: {e}", path.display())))?;
    std::fs::write(path, png)
        .map_err(|e| Error::Io(format!("cannot write chart {}: {e}", path.display())))
}

/// Encodes an 8-bit RGB buffer of the chart size as PNG.
fn encode_png(rgb: &[u8]) -> Result<Vec<u8>, png::EncodingError> {
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, WIDTH, HEIGHT);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_compression(png::Compression::Best);
    let mut writer = encoder.write_header()?;
    writer.write_image_data(rgb)?;
    writer.finish()?;
    Ok(out)
}
