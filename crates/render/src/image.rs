//! [`Image`]: the linear grey frame buffer, its tone mapping and its PNG / EXR encoders.

use crate::RenderError;
use std::path::Path;

/// A grey image of linear radiance values, row-major, origin top-left.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width · height` linear values; pixel `(x, y)` is at `y · width + x`.
    pub pixels: Vec<f32>,
}

/// The sRGB transfer function (IEC 61966-2-1) of a linear value in `[0, 1]`.
pub fn srgb_encode(linear: f32) -> f32 {
    if linear <= 0.003_130_8 {
        12.92 * linear
    } else {
        1.055 * linear.powf(1.0 / 2.4) - 0.055
    }
}

impl Image {
    /// A black image.
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            pixels: vec![0.0; width as usize * height as usize],
        }
    }

    /// The value of pixel `(x, y)`.
    pub fn get(&self, x: u32, y: u32) -> f32 {
        self.pixels[y as usize * self.width as usize + x as usize]
    }

    /// Tone mapping to 8-bit sRGB: clamp to `[0, 1]` (NaN → 0), sRGB transfer function,
    /// round to nearest.
    pub fn to_srgb8(&self) -> Vec<u8> {
        self.pixels
            .iter()
            .map(|&v| {
                let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
                (srgb_encode(v) * 255.0 + 0.5) as u8
            })
            .collect()
    }

    /// Encodes the tone-mapped image as an 8-bit greyscale PNG (with an sRGB chunk).
    pub fn encode_png<W: std::io::Write>(&self, out: W) -> Result<(), png::EncodingError> {
        let mut enc = png::Encoder::new(out, self.width, self.height);
        enc.set_color(png::ColorType::Grayscale);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
        let mut w = enc.write_header()?;
        w.write_image_data(&self.to_srgb8())?;
        w.finish()
    }

    /// Writes the tone-mapped image as a PNG file.
    pub fn write_png(&self, path: &Path) -> Result<(), RenderError> {
        let err = |message: String| RenderError::Write {
            path: path.to_path_buf(),
            message,
        };
        let file = std::fs::File::create(path).map_err(|e| err(e.to_string()))?;
        self.encode_png(std::io::BufWriter::new(file))
            .map_err(|e| err(e.to_string()))
    }

    /// Writes the linear values as an RGB f32 OpenEXR file (grey: r = g = b).
    pub fn write_exr(&self, path: &Path) -> Result<(), RenderError> {
        exr::prelude::write_rgb_file(path, self.width as usize, self.height as usize, |x, y| {
            let v = self.pixels[y * self.width as usize + x];
            (v, v, v)
        })
        .map_err(|e| RenderError::Write {
            path: path.to_path_buf(),
            message: e.to_string(),
        })
    }

    /// Writes a PNG or an EXR, chosen by the extension of `path` ([`ImageFormat::from_path`]).
    pub fn write(&self, path: &Path) -> Result<(), RenderError> {
        match ImageFormat::from_path(path)? {
            ImageFormat::Png => self.write_png(path),
            ImageFormat::Exr => self.write_exr(path),
        }
    }
}

/// The output formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    /// Tone-mapped 8-bit sRGB PNG.
    Png,
    /// Linear f32 OpenEXR.
    Exr,
}

impl ImageFormat {
    /// The format named by the extension of `path` (`.png` or `.exr`, case-insensitive), so a
    /// caller can reject a bad output name before rendering.
    pub fn from_path(path: &Path) -> Result<Self, RenderError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase());
        match ext.as_deref() {
            Some("png") => Ok(ImageFormat::Png),
            Some("exr") => Ok(ImageFormat::Exr),
            _ => Err(RenderError::UnknownFormat {
                path: path.to_path_buf(),
            }),
        }
    }
}
