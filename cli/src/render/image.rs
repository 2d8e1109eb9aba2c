//! An 8-bit RGB image and its PNG file.

use projfluid::Error;
use std::path::Path;

/// An 8-bit RGB image, rows top to bottom.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// `width·height` pixels, row by row from the top.
    pub pixels: Vec<[u8; 3]>,
}

impl Image {
    /// The pixel in column `x` and row `y` (from the top).
    pub fn pixel(&self, x: usize, y: usize) -> [u8; 3] {
        self.pixels[y * self.width + x]
    }

    /// Writes the image as an 8-bit RGB PNG file; errors name the path.
    pub fn write_png(&self, path: &Path) -> Result<(), Error> {
        let fail = |e: String| Error::Io(format!("cannot write {}: {e}", path.display()));
        let file = std::fs::File::create(path).map_err(|e| fail(e.to_string()))?;
        let mut encoder = png::Encoder::new(
            std::io::BufWriter::new(file),
            self.width as u32,
            self.height as u32,
        );
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().map_err(|e| fail(e.to_string()))?;
        let data: Vec<u8> = self.pixels.iter().flatten().copied().collect();
        writer
            .write_image_data(&data)
            .map_err(|e| fail(e.to_string()))?;
        writer.finish().map_err(|e| fail(e.to_string()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::Frame;
    use crate::render::tests::renderer;
    use projfluid::Vec3;

    #[test]
    fn png_files_read_back() {
        let r = renderer();
        let image = r.render(&Frame {
            positions: &[r.camera.target],
            velocities: &[Vec3::zeros()],
            obstacle: &[],
            containers: &[],
        });
        let path =
            std::env::temp_dir().join(format!("projfluid-render-{}.png", std::process::id()));
        image.write_png(&path).unwrap();
        let decoder = png::Decoder::new(std::fs::File::open(&path).unwrap());
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut buf).unwrap();
        std::fs::remove_file(&path).unwrap();
        assert_eq!((info.width, info.height), (160, 90));
        assert_eq!(info.color_type, png::ColorType::Rgb);
        let back: Vec<u8> = image.pixels.iter().flatten().copied().collect();
        assert_eq!(&buf[..info.buffer_size()], &back[..]);
        let err = image
            .write_png(Path::new("/nonexistent/x.png"))
            .unwrap_err();
        assert!(err.to_string().contains("/nonexistent/x.png"), "{err}");
    }
}
