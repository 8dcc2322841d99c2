//! Image files: EXR (float32 RGB), PFM (little-endian, rows bottom to top as
//! the format specifies), PNG (8-bit sRGB, clamped, as pbrt-v3 writes it),
//! and for `pbrs img convert` Radiance HDR (RGBE) and TGA (8-bit sRGB).
//! EXR and PNG files can carry [`Metadata`] (EXR text attributes, PNG text
//! chunks).
//! Writes are atomic: the file is written under a temporary name in the same
//! directory and renamed into place, so a failure never leaves a partial
//! image behind.

use super::Image;
use std::fs;
use std::io::{Cursor, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    Exr,
    Pfm,
    Png,
    Hdr,
    Tga,
}

impl ImageFormat {
    pub fn name(self) -> &'static str {
        match self {
            ImageFormat::Exr => "EXR",
            ImageFormat::Pfm => "PFM",
            ImageFormat::Png => "PNG",
            ImageFormat::Hdr => "HDR",
            ImageFormat::Tga => "TGA",
        }
    }

    /// Whether the format stores 8-bit sRGB values (clamped to [0, 1]).
    pub fn is_8bit(self) -> bool {
        matches!(self, ImageFormat::Png | ImageFormat::Tga)
    }
}

/// Text metadata written into an image: `(key, value)` pairs, as EXR text
/// attributes or PNG text chunks (other formats have no place for it).
pub type Metadata = [(String, String)];

/// The format implied by the extension (case-insensitive).
pub fn format_for_path(path: &Path) -> Result<ImageFormat, String> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    match ext.as_deref() {
        Some("exr") => Ok(ImageFormat::Exr),
        Some("pfm") => Ok(ImageFormat::Pfm),
        Some("png") => Ok(ImageFormat::Png),
        Some("hdr") => Ok(ImageFormat::Hdr),
        Some("tga") => Ok(ImageFormat::Tga),
        Some(e) => Err(format!(
            "{}: unsupported image format \".{e}\" (use .exr, .pfm, .png, .hdr or .tga)",
            path.display()
        )),
        None => Err(format!(
            "{}: no file extension to choose the image format (use .exr, .pfm, .png, .hdr or .tga)",
            path.display()
        )),
    }
}

fn parent_dir(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

static TEMP_COUNTER: AtomicU64 = AtomicU64::new(0);

fn temp_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "image".into());
    let n = TEMP_COUNTER.fetch_add(1, Ordering::Relaxed);
    parent_dir(path).join(format!(".{name}.{}-{n}.tmp", std::process::id()))
}

/// Checks, before rendering, that `path` can be written: a known extension
/// and an existing, writable directory (probed with a temporary file that is
/// removed again). Does not touch `path` itself.
pub fn check_output_path(path: &Path) -> Result<(), String> {
    format_for_path(path)?;
    let dir = parent_dir(path);
    if !dir.is_dir() {
        return Err(format!(
            "{}: directory {} does not exist",
            path.display(),
            dir.display()
        ));
    }
    if path.is_dir() {
        return Err(format!("{}: is a directory", path.display()));
    }
    let probe = temp_path(path);
    match fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&probe)
    {
        Ok(f) => {
            drop(f);
            let _ = fs::remove_file(&probe);
            Ok(())
        }
        Err(e) => Err(format!(
            "{}: cannot write in {}: {e}",
            path.display(),
            dir.display()
        )),
    }
}

/// Writes `img` in the format given by the extension of `path`, atomically.
pub fn write_image(path: &Path, img: &Image) -> Result<(), String> {
    write_image_with(path, img, &[])
}

/// [`write_image`] with `metadata` in the header (EXR and PNG; ignored by
/// the other formats). Empty metadata writes exactly [`write_image`]'s bytes.
pub fn write_image_with(path: &Path, img: &Image, metadata: &Metadata) -> Result<(), String> {
    let format = format_for_path(path)?;
    check_image(img)?;
    let bytes = match format {
        ImageFormat::Pfm => Ok(encode_pfm(img)),
        ImageFormat::Png => encode_png(img, metadata),
        ImageFormat::Exr => encode_exr(img, metadata),
        ImageFormat::Hdr => encode_hdr(img),
        ImageFormat::Tga => encode_tga(img),
    }
    .map_err(|e| format!("{}: {e}", path.display()))?;
    write_atomic(path, &bytes)
}

fn check_image(img: &Image) -> Result<(), String> {
    let n = img.width as usize * img.height as usize * 3;
    if img.data.len() != n {
        return Err(format!(
            "image of {}x{} has {} values, expected {n}",
            img.width,
            img.height,
            img.data.len()
        ));
    }
    Ok(())
}

/// Writes `bytes` to a temporary file next to `path`, then renames it over
/// `path`. On any error the temporary file is removed and `path` is untouched.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), String> {
    let tmp = temp_path(path);
    let result = (|| -> std::io::Result<()> {
        let mut f = fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        drop(f);
        fs::rename(&tmp, path)
    })();
    result.map_err(|e| {
        let _ = fs::remove_file(&tmp);
        format!("{}: cannot write image: {e}", path.display())
    })
}

fn encode_pfm(img: &Image) -> Vec<u8> {
    let (w, h) = (img.width as usize, img.height as usize);
    let header = format!("PF\n{w} {h}\n-1.0\n");
    let mut out = Vec::with_capacity(header.len() + w * h * 12);
    out.extend_from_slice(header.as_bytes());
    for y in (0..h).rev() {
        for v in &img.data[y * w * 3..(y + 1) * w * 3] {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    out
}

/// pbrt-v3's `GammaCorrect` (the sRGB curve).
#[inline]
pub fn srgb_encode(v: f32) -> f32 {
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// pbrt-v3's 8-bit conversion: `clamp(255 · gamma(v) + 0.5, 0, 255)`.
#[inline]
pub fn to_8bit(v: f32) -> u8 {
    let v = if v.is_nan() { 0.0 } else { v };
    (255.0 * srgb_encode(v) + 0.5).clamp(0.0, 255.0) as u8
}

fn encode_png(img: &Image, metadata: &Metadata) -> Result<Vec<u8>, String> {
    use image::ImageEncoder;
    let rgb: Vec<u8> = img.data.iter().map(|&v| to_8bit(v)).collect();
    let mut out = Vec::new();
    if metadata.is_empty() {
        image::codecs::png::PngEncoder::new(&mut out)
            .write_image(&rgb, img.width, img.height, image::ExtendedColorType::Rgb8)
            .map_err(|e| e.to_string())?;
        return Ok(out);
    }
    let mut enc = png::Encoder::new(&mut out, img.width, img.height);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    for (k, v) in metadata {
        // tEXt holds Latin-1; other text goes in a UTF-8 iTXt chunk.
        if v.is_ascii() {
            enc.add_text_chunk(k.clone(), v.clone())
        } else {
            enc.add_itxt_chunk(k.clone(), v.clone())
        }
        .map_err(|e| e.to_string())?;
    }
    let mut w = enc.write_header().map_err(|e| e.to_string())?;
    w.write_image_data(&rgb).map_err(|e| e.to_string())?;
    w.finish().map_err(|e| e.to_string())?;
    Ok(out)
}

fn encode_tga(img: &Image) -> Result<Vec<u8>, String> {
    use image::ImageEncoder;
    let rgb: Vec<u8> = img.data.iter().map(|&v| to_8bit(v)).collect();
    let mut out = Vec::new();
    image::codecs::tga::TgaEncoder::new(&mut out)
        .write_image(&rgb, img.width, img.height, image::ExtendedColorType::Rgb8)
        .map_err(|e| e.to_string())?;
    Ok(out)
}

fn encode_hdr(img: &Image) -> Result<Vec<u8>, String> {
    // RGBE holds no negative or non-finite value: those are written as 0.
    let px: Vec<image::Rgb<f32>> = img
        .data
        .chunks_exact(3)
        .map(|c| {
            let f = |v: f32| if v.is_finite() { v.max(0.0) } else { 0.0 };
            image::Rgb([f(c[0]), f(c[1]), f(c[2])])
        })
        .collect();
    let mut out = Vec::new();
    image::codecs::hdr::HdrEncoder::new(&mut out)
        .encode(&px, img.width as usize, img.height as usize)
        .map_err(|e| e.to_string())?;
    Ok(out)
}

fn encode_exr(img: &Image, metadata: &Metadata) -> Result<Vec<u8>, String> {
    use exr::prelude::{AttributeValue, Image as ExrImage, SpecificChannels, Text, WritableImage};
    let w = img.width as usize;
    let channels = SpecificChannels::rgb(|exr::math::Vec2(x, y): exr::math::Vec2<usize>| {
        let i = 3 * (y * w + x);
        (img.data[i], img.data[i + 1], img.data[i + 2])
    });
    let mut image = ExrImage::from_channels((img.width as usize, img.height as usize), channels);
    for (k, v) in metadata {
        let (Some(k), Some(v)) = (Text::new_or_none(k), Text::new_or_none(v)) else {
            return Err(format!("metadata {k:?} cannot be written as EXR text"));
        };
        image
            .layer_data
            .attributes
            .other
            .insert(k, AttributeValue::Text(v));
    }
    let mut cursor = Cursor::new(Vec::new());
    // Sequential: the exr crate's parallel compression writes blocks in
    // completion order, which would make the file depend on timing.
    image
        .write()
        .non_parallel()
        .to_buffered(&mut cursor)
        .map_err(|e| e.to_string())?;
    Ok(cursor.into_inner())
}

/// Reads an image by extension (`.pfm`, `.exr` or `.png`; the others
/// through [`super::meta::read_any`]).
pub fn read_image(path: &Path) -> Result<Image, String> {
    match format_for_path(path)? {
        ImageFormat::Pfm => read_pfm(path),
        ImageFormat::Exr => read_exr(path),
        ImageFormat::Png => read_png(path),
        ImageFormat::Hdr | ImageFormat::Tga => super::meta::read_any(path).map(|r| r.image),
    }
}

/// Reads a PFM (`PF` colour or `Pf` grey, either endianness) into an image
/// with rows top to bottom.
pub fn read_pfm(path: &Path) -> Result<Image, String> {
    let bytes = fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    parse_pfm(&bytes).map_err(|e| format!("{}: {e}", path.display()))
}

/// Parses PFM bytes (see [`read_pfm`]).
pub fn parse_pfm(bytes: &[u8]) -> Result<Image, String> {
    // Three whitespace-separated header fields after the magic, then exactly
    // one whitespace byte before the data.
    let mut pos = 0;
    let mut token = || -> Result<String, String> {
        while pos < bytes.len() && bytes[pos].is_ascii_whitespace() {
            pos += 1;
        }
        let start = pos;
        while pos < bytes.len() && !bytes[pos].is_ascii_whitespace() {
            pos += 1;
        }
        if start == pos {
            return Err("truncated PFM header".into());
        }
        let t = String::from_utf8_lossy(&bytes[start..pos]).into_owned();
        Ok(t)
    };
    let magic = token()?;
    let channels = match magic.as_str() {
        "PF" => 3,
        "Pf" => 1,
        m => return Err(format!("not a PFM file (magic {m:?})")),
    };
    let w: u64 = token()?.parse().map_err(|_| "bad PFM width".to_string())?;
    let h: u64 = token()?.parse().map_err(|_| "bad PFM height".to_string())?;
    let scale: f32 = token()?.parse().map_err(|_| "bad PFM scale".to_string())?;
    let data_start = pos + 1;
    if w == 0 || h == 0 {
        return Err(format!("the image is empty ({w}×{h} pixels)"));
    }
    // Bounded before anything is allocated (the header is untrusted).
    let max = super::MAX_IMAGE_PIXELS;
    if w.checked_mul(h).is_none_or(|n| n > max) {
        return Err(format!(
            "the image declares {w}×{h} pixels, more than pbrs reads ({max} pixels)"
        ));
    }
    let (w, h) = (w as usize, h as usize);
    let n = w * h * channels;
    if bytes.len() < data_start + n * 4 {
        return Err(format!(
            "PFM data truncated: {w}x{h}x{channels} floats expected"
        ));
    }
    // pbrt-v3 scales the values by |scale| unless it is 1.
    let mag = if scale.abs() != 1.0 && scale.is_finite() {
        scale.abs()
    } else {
        1.0
    };
    let little = scale < 0.0;
    let mut data = vec![0.0f32; w * h * 3];
    for row in 0..h {
        // File rows go bottom to top.
        let y = h - 1 - row;
        for x in 0..w {
            for c in 0..3 {
                let src_c = if channels == 3 { c } else { 0 };
                let o = data_start + 4 * ((row * w + x) * channels + src_c);
                let b = [bytes[o], bytes[o + 1], bytes[o + 2], bytes[o + 3]];
                let v = if little {
                    f32::from_le_bytes(b)
                } else {
                    f32::from_be_bytes(b)
                };
                data[3 * (y * w + x) + c] = v * mag;
            }
        }
    }
    Ok(Image {
        width: w as u32,
        height: h as u32,
        data,
    })
}

/// Reads the first RGB(A) layer of an EXR (alpha dropped).
pub fn read_exr(path: &Path) -> Result<Image, String> {
    // The declared size is bounded before the pixels are allocated.
    let meta = exr::meta::MetaData::read_from_file(path, false)
        .map_err(|e| format!("{}: {e}", path.display()))?;
    for h in meta.headers.iter() {
        let (w, hh) = (h.layer_size.width() as u64, h.layer_size.height() as u64);
        if w.checked_mul(hh)
            .is_none_or(|n| n > super::MAX_IMAGE_PIXELS)
        {
            return Err(format!(
                "{}: the image declares {w}×{hh} pixels, more than pbrs reads ({} pixels)",
                path.display(),
                super::MAX_IMAGE_PIXELS
            ));
        }
    }
    // Decoded on this thread (the exr crate's parallel decoder aborts the
    // process when a worker panics on corrupt data; here a panic is this
    // file's error).
    let read = || {
        use exr::prelude::traits::*;
        exr::prelude::read()
            .no_deep_data()
            .largest_resolution_level()
            .rgba_channels(
                |res, _| Image::new(res.width() as u32, res.height() as u32),
                |img: &mut Image, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
                    let i = 3 * (pos.y() * img.width as usize + pos.x());
                    img.data[i] = r;
                    img.data[i + 1] = g;
                    img.data[i + 2] = b;
                },
            )
            .first_valid_layer()
            .all_attributes()
            .non_parallel()
            .from_file(path)
    };
    match std::panic::catch_unwind(read) {
        Ok(Ok(img)) => Ok(img.layer_data.channel_data.pixels),
        Ok(Err(e)) => Err(format!("{}: {e}", path.display())),
        Err(_) => Err(format!(
            "{}: the EXR decoder failed on this file (corrupt data)",
            path.display()
        )),
    }
}

/// Reads an 8-bit PNG back to linear RGB (inverse sRGB curve), for tests.
pub fn read_png(path: &Path) -> Result<Image, String> {
    let dynimg = image::open(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let rgb = dynimg.to_rgb8();
    let data = rgb
        .as_raw()
        .iter()
        .map(|&b| {
            let v = b as f32 / 255.0;
            if v <= 0.04045 {
                v / 12.92
            } else {
                ((v + 0.055) / 1.055).powf(2.4)
            }
        })
        .collect();
    Ok(Image {
        width: rgb.width(),
        height: rgb.height(),
        data,
    })
}
