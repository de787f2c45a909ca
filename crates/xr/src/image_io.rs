//! RGBA8 images as the renderer reads them back, and their PNG files (through the `png`
//! crate itself: `image` would add its colour-management crates, moxcms and pxfm, to every
//! build for a format this needs only one of).

use std::path::Path;

use crate::error::RenderError;

/// An 8-bit sRGB RGBA image, rows top to bottom.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RgbaImage {
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
    /// `width × height × 4` bytes.
    pub pixels: Vec<u8>,
}

impl RgbaImage {
    /// A `width × height` image filled with `rgba`.
    pub fn filled(width: u32, height: u32, rgba: [u8; 4]) -> Self {
        RgbaImage {
            width,
            height,
            pixels: rgba.repeat((width * height) as usize),
        }
    }

    /// The pixel at (`x`, `y`).
    pub fn get(&self, x: u32, y: u32) -> [u8; 4] {
        let i = ((y * self.width + x) * 4) as usize;
        [
            self.pixels[i],
            self.pixels[i + 1],
            self.pixels[i + 2],
            self.pixels[i + 3],
        ]
    }

    /// Set the pixel at (`x`, `y`).
    pub fn set(&mut self, x: u32, y: u32, rgba: [u8; 4]) {
        let i = ((y * self.width + x) * 4) as usize;
        self.pixels[i..i + 4].copy_from_slice(&rgba);
    }

    /// Write as PNG (parent folder must exist).
    pub fn save_png(&self, path: &Path) -> Result<(), RenderError> {
        let err = |msg: String| RenderError::Image {
            path: path.into(),
            msg,
        };
        let mut png = Vec::new();
        let mut encoder = png::Encoder::new(&mut png, self.width, self.height);
        encoder.set_color(png::ColorType::Rgba);
        encoder.set_depth(png::BitDepth::Eight);
        // The compression and filter `image`'s PNG encoder chose.
        encoder.set_compression(png::Compression::Balanced);
        encoder.set_filter(png::Filter::Adaptive);
        let mut writer = encoder.write_header().map_err(|e| err(e.to_string()))?;
        writer
            .write_image_data(&self.pixels)
            .map_err(|e| err(e.to_string()))?;
        writer.finish().map_err(|e| err(e.to_string()))?;
        // Written to a sibling and renamed: a process killed mid-write leaves the old
        // file or none, never half a PNG (issue 11).
        incise_sim::io::write_atomic(path, &png).map_err(|e| err(e.to_string()))
    }

    /// Read a PNG (any colour type, converted to RGBA8: palettes and grey expanded, a
    /// `tRNS` chunk made alpha, 16-bit samples cut to their high byte).
    pub fn load_png(path: &Path) -> Result<Self, RenderError> {
        let err = |msg: String| RenderError::Image {
            path: path.into(),
            msg,
        };
        let file = std::fs::File::open(path).map_err(|e| err(e.to_string()))?;
        let mut decoder = png::Decoder::new(std::io::BufReader::new(file));
        decoder.set_transformations(png::Transformations::normalize_to_color8());
        let mut reader = decoder.read_info().map_err(|e| err(e.to_string()))?;
        let size = reader
            .output_buffer_size()
            .ok_or_else(|| err("image too large".into()))?;
        let mut buf = vec![0; size];
        let frame = reader
            .next_frame(&mut buf)
            .map_err(|e| err(e.to_string()))?;
        buf.truncate(frame.buffer_size());
        let pixels = match frame.color_type {
            png::ColorType::Rgba => buf,
            png::ColorType::Rgb => buf
                .chunks_exact(3)
                .flat_map(|p| [p[0], p[1], p[2], 255])
                .collect(),
            png::ColorType::GrayscaleAlpha => buf
                .chunks_exact(2)
                .flat_map(|p| [p[0], p[0], p[0], p[1]])
                .collect(),
            png::ColorType::Grayscale => buf.iter().flat_map(|&g| [g, g, g, 255]).collect(),
            png::ColorType::Indexed => return Err(err("palette left unexpanded".into())),
        };
        Ok(RgbaImage {
            width: frame.width,
            height: frame.height,
            pixels,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn png_round_trip_and_a_clear_error() {
        let dir = std::env::temp_dir().join(format!("incise-xr-png-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut img = RgbaImage::filled(5, 3, [10, 20, 30, 255]);
        img.set(4, 2, [200, 100, 0, 255]);
        let p = dir.join("a.png");
        img.save_png(&p).unwrap();
        assert_eq!(RgbaImage::load_png(&p).unwrap(), img);
        // Other colour types come back as RGBA8.
        for (color, pixel, rgba) in [
            (png::ColorType::Rgb, &[10u8, 20, 30][..], [10, 20, 30, 255]),
            (png::ColorType::Grayscale, &[7][..], [7, 7, 7, 255]),
            (png::ColorType::GrayscaleAlpha, &[7, 9][..], [7, 7, 7, 9]),
        ] {
            let mut bytes = Vec::new();
            let mut encoder = png::Encoder::new(&mut bytes, 1, 1);
            encoder.set_color(color);
            encoder.set_depth(png::BitDepth::Eight);
            let mut writer = encoder.write_header().unwrap();
            writer.write_image_data(pixel).unwrap();
            writer.finish().unwrap();
            let p = dir.join("other.png");
            std::fs::write(&p, &bytes).unwrap();
            assert_eq!(
                RgbaImage::load_png(&p).unwrap(),
                RgbaImage::filled(1, 1, rgba),
                "{color:?}"
            );
        }
        let err = RgbaImage::load_png(&dir.join("missing.png")).unwrap_err();
        assert!(err.to_string().contains("missing.png"), "{err}");
    }
}
