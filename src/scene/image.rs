//! Images read from files (textures, environment maps), as scene data.
//!
//! **Public API (stable; textures and lights build on it):**
//!
//! - [`RgbImage`]: `width() / height()` (both ≥ 1), `pixels()` (row-major
//!   `Vec3` RGB, **top row first, as stored in the file**: pbrt-v3's
//!   `ReadImage` order; image textures flip it themselves, as pbrt-v3 does,
//!   the infinite light does not), `get(x, y)`, `depth()` (what the file
//!   stored: [`SampleDepth`]), `RgbImage::new`, `RgbImage::constant`,
//!   `flipped_y()`.
//! - [`Decode`]: how values are converted when read. `Raw` is pbrt-v3's
//!   `ReadImage`: 8-bit files give `v / 255` (still sRGB-encoded), float
//!   files their values. `SrgbToLinear` also applies pbrt-v3's
//!   `InverseGammaCorrect` to every channel (an image texture's `gamma`,
//!   which defaults to true for `.png` and `.tga`, whatever the bit depth).
//!   pbrt-v3's infinite light reads `Raw` (no decoding, even for PNG).
//! - [`srgb_to_linear`] (pbrt-v3's `InverseGammaCorrect`), for conversions
//!   the cache does not do (a float image texture linearises the luminance
//!   of the raw values, not each channel).
//! - [`MAX_IMAGE_PIXELS`]: the memory bound every reader checks against a
//!   file's declared size before allocating.
//!
//! Reading files (formats, the per-scene cache, errors) is in
//! `loader::image`; filtering (MIP maps) is in the render core.

use glam::Vec3;

pub use crate::image::MAX_IMAGE_PIXELS;

/// How a file stored its samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SampleDepth {
    /// 8 bits per channel (PNG, TGA; 16-bit PNGs are reduced to their high
    /// byte, as pbrt-v3's PNG reader does).
    U8,
    /// Half floats (EXR).
    F16,
    /// 32-bit floats (EXR, PFM, and Radiance HDR's shared-exponent RGB).
    F32,
}

/// Conversion applied to the values read from a file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Decode {
    /// As pbrt-v3's `ReadImage` returns them.
    Raw,
    /// `srgb_to_linear` on every channel of the raw values.
    SrgbToLinear,
}

/// An RGB image of f32 values, at least 1 × 1.
#[derive(Clone, Debug, PartialEq)]
pub struct RgbImage {
    width: u32,
    height: u32,
    pixels: Vec<Vec3>,
    depth: SampleDepth,
}

impl RgbImage {
    /// `None` unless `pixels.len() == width * height` and both are ≥ 1.
    pub fn new(width: u32, height: u32, pixels: Vec<Vec3>, depth: SampleDepth) -> Option<Self> {
        let n = (width as u64).checked_mul(height as u64)?;
        (width > 0 && height > 0 && pixels.len() as u64 == n).then_some(RgbImage {
            width,
            height,
            pixels,
            depth,
        })
    }

    /// A 1 × 1 image.
    pub fn constant(v: Vec3) -> Self {
        RgbImage {
            width: 1,
            height: 1,
            pixels: vec![v],
            depth: SampleDepth::F32,
        }
    }

    #[inline]
    pub fn width(&self) -> u32 {
        self.width
    }

    #[inline]
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Row-major, top row first.
    #[inline]
    pub fn pixels(&self) -> &[Vec3] {
        &self.pixels
    }

    #[inline]
    pub fn depth(&self) -> SampleDepth {
        self.depth
    }

    /// Pixel `(x, y)`, `y = 0` the top row. Panics out of range.
    #[inline]
    pub fn get(&self, x: u32, y: u32) -> Vec3 {
        assert!(x < self.width && y < self.height);
        self.pixels[(y as usize) * (self.width as usize) + x as usize]
    }

    /// The image upside down (pbrt-v3's image textures put (0, 0) at the
    /// lower left).
    pub fn flipped_y(&self) -> RgbImage {
        let w = self.width as usize;
        let mut pixels = Vec::with_capacity(self.pixels.len());
        for row in self.pixels.chunks_exact(w).rev() {
            pixels.extend_from_slice(row);
        }
        RgbImage { pixels, ..*self }
    }

    /// The image with `f` applied to every channel.
    pub fn map_channels(&self, f: impl Fn(f32) -> f32) -> RgbImage {
        RgbImage {
            pixels: self
                .pixels
                .iter()
                .map(|p| Vec3::new(f(p.x), f(p.y), f(p.z)))
                .collect(),
            ..*self
        }
    }

    /// The image converted as `decode` says.
    pub fn decoded(&self, decode: Decode) -> RgbImage {
        match decode {
            Decode::Raw => self.clone(),
            Decode::SrgbToLinear => self.map_channels(srgb_to_linear),
        }
    }
}

/// pbrt-v3's `InverseGammaCorrect`: the sRGB curve from encoded to linear.
#[inline]
pub fn srgb_to_linear(v: f32) -> f32 {
    if v <= 0.04045 {
        v * (1.0 / 12.92)
    } else {
        ((v + 0.055) * (1.0 / 1.055)).powf(2.4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn new_checks_the_size() {
        assert!(RgbImage::new(2, 1, vec![Vec3::ZERO; 2], SampleDepth::U8).is_some());
        assert!(RgbImage::new(2, 1, vec![Vec3::ZERO; 3], SampleDepth::U8).is_none());
        assert!(RgbImage::new(0, 0, vec![], SampleDepth::U8).is_none());
    }

    #[test]
    fn flip_and_decode() {
        let img = RgbImage::new(
            1,
            2,
            vec![Vec3::splat(0.5), Vec3::splat(0.02)],
            SampleDepth::U8,
        )
        .unwrap();
        let f = img.flipped_y();
        assert_eq!(f.get(0, 0), Vec3::splat(0.02));
        assert_eq!(f.get(0, 1), Vec3::splat(0.5));
        let d = img.decoded(Decode::SrgbToLinear);
        assert!((d.get(0, 0).x - 0.214_041_14).abs() < 1e-6);
        assert!((d.get(0, 1).x - 0.02 / 12.92).abs() < 1e-9);
        assert_eq!(img.decoded(Decode::Raw), img);
    }
}
