//! Linear RGB float images: the type ([`Image`]), its files ([`io`]: EXR, PFM,
//! PNG, HDR, TGA, written atomically; [`meta`]: any of them read with its
//! metadata), the project's comparison metrics ([`compare`]) and the golden
//! verdict built on them ([`verdict`]). The film develops into one; the loader reads texture
//! and reference images with [`io`].

use glam::Vec3;

pub mod compare;
pub mod io;
pub mod meta;
pub mod verdict;

/// Largest image (width × height) any reader accepts: 2^27 texels, e.g. a
/// 16384 × 8192 environment map, 1.5 GiB as RGB f32. Checked against the
/// file's declared size before anything is allocated.
pub const MAX_IMAGE_PIXELS: u64 = 1 << 27;

/// `v / 255` for every byte value: what the 8-bit readers make of a byte
/// (and what the inverse sRGB curve's table is keyed on).
pub fn unorm8_table() -> [f32; 256] {
    std::array::from_fn(|i| i as f32 / 255.0)
}

/// A linear RGB image: `data` holds `width * height` RGB triples, rows from
/// top to bottom.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub data: Vec<f32>,
}

impl Image {
    pub fn new(width: u32, height: u32) -> Image {
        Image {
            width,
            height,
            data: vec![0.0; width as usize * height as usize * 3],
        }
    }

    #[inline]
    pub fn pixel(&self, x: u32, y: u32) -> Vec3 {
        let i = 3 * (y as usize * self.width as usize + x as usize);
        Vec3::new(self.data[i], self.data[i + 1], self.data[i + 2])
    }

    #[inline]
    pub fn set_pixel(&mut self, x: u32, y: u32, v: Vec3) {
        let i = 3 * (y as usize * self.width as usize + x as usize);
        self.data[i..i + 3].copy_from_slice(&v.to_array());
    }
}
