//! RGBA8 images as the renderer reads them back, and their PNG files.

use image::ImageEncoder;
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
        image::codecs::png::PngEncoder::new(&mut png)
            .write_image(
                &self.pixels,
                self.width,
                self.height,
                image::ExtendedColorType::Rgba8,
            )
            .map_err(|e| err(e.to_string()))?;
        // Written to a sibling and renamed: a process killed mid-write leaves the old
        // file or none, never half a PNG (issue 11).
        incise_sim::io::write_atomic(path, &png).map_err(|e| err(e.to_string()))
    }

    /// Read a PNG (any colour type, converted to RGBA8).
    pub fn load_png(path: &Path) -> Result<Self, RenderError> {
        let img = image::open(path).map_err(|e| RenderError::Image {
            path: path.into(),
            msg: e.to_string(),
        })?;
        let rgba = img.to_rgba8();
        Ok(RgbaImage {
            width: rgba.width(),
            height: rgba.height(),
            pixels: rgba.into_raw(),
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
        let err = RgbaImage::load_png(&dir.join("missing.png")).unwrap_err();
        assert!(err.to_string().contains("missing.png"), "{err}");
    }
}
