//! Reading image files for textures and lights: one cache per scene, so a
//! file is read and decoded once however many textures and lights use it.
//!
//! **Public API (stable):**
//!
//! - [`load_image`]`(ctx, loc, filename, decode) -> Option<Arc<RgbImage>>`:
//!   `filename` as written in the scene (relative paths resolve against the
//!   scene file's directory, as pbrt-v3's `FindOneFilename` does), read
//!   through `ctx.loader`; on any failure a located error at `loc` naming
//!   the file, and `None`. Cached by path (the file) and by path and
//!   [`Decode`] (the converted image).
//! - [`decode_image`]`(bytes, name) -> Result<RgbImage, String>`: the raw
//!   decoding alone (format from `name`'s extension), for tests and fuzzing.
//! - [`ImageCache`]: lives in `Ctx::images`.
//!
//! Formats, as pbrt-v3's `ReadImage` reads them (the format comes from the
//! extension, case-insensitive):
//!
//! | ext | reader | values |
//! |---|---|---|
//! | `.png` | `image` crate | 8-bit: `v/255`; 16-bit: the high byte `/255` (pbrt-v3's lodepng reduces to 8 bits); grey replicated, alpha dropped |
//! | `.tga` | `image` crate | `v/255`, top row first whatever the file's origin, colour maps expanded |
//! | `.exr` | `exr` crate | `R`, `G`, `B` (a missing one is 0, as OpenEXR's RGBA interface fills it), or `Y` alone as grey; half, float or uint samples; the data window of the first flat part, at its largest resolution level |
//! | `.pfm` | `image::io` | `PF` or `Pf`, either byte order, times \|scale\| when it is not 1 |
//! | `.hdr` | `image` crate | Radiance RGBE, linear. **A pbrs extension**: pbrt-v3 reads no `.hdr` |
//!
//! Every reader checks the declared size against [`MAX_IMAGE_PIXELS`]
//! before allocating, and a decoder panic (a bug in a dependency) becomes an
//! error rather than an abort.

use super::Ctx;
use crate::lang::Loc;
use crate::scene::{Decode, RgbImage, SampleDepth, MAX_IMAGE_PIXELS};
use crate::textures::ptex_file::PtexFile;
use glam::Vec3;
use std::collections::HashMap;
use std::io::Cursor;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Files read so far, by path: what each read gave (a value or an error).
type ReadResults<T> = HashMap<PathBuf, Result<Arc<T>, String>>;

/// Images read so far in this scene.
#[derive(Default)]
pub struct ImageCache {
    raw: ReadResults<RgbImage>,
    decoded: HashMap<(PathBuf, Decode), Arc<RgbImage>>,
    /// Ptex files read so far (`ptex` textures).
    ptex: ReadResults<PtexFile>,
    /// Files actually read (for tests of the cache).
    reads: usize,
}

impl ImageCache {
    /// How many files were read and decoded.
    pub fn reads(&self) -> usize {
        self.reads
    }
}

/// The file at `path` read and parsed once per scene: the result, value
/// or error, is kept in the `cache` map of [`ImageCache`] for later uses.
fn read_once<T>(
    ctx: &mut Ctx,
    path: &Path,
    cache: fn(&mut ImageCache) -> &mut ReadResults<T>,
    parse: impl FnOnce(&mut Ctx, Vec<u8>) -> Result<T, String>,
) -> Result<Arc<T>, String> {
    if let Some(r) = cache(&mut ctx.images).get(path) {
        return r.clone();
    }
    ctx.images.reads += 1;
    let r = ctx
        .loader
        .load(path)
        .and_then(|bytes| parse(ctx, bytes))
        .map(Arc::new);
    cache(&mut ctx.images).insert(path.to_path_buf(), r.clone());
    r
}

/// The image `filename` converted as `decode` says, or `None` after a located
/// warning that names the file and says what is used instead (`substitute`).
pub fn load_image(
    ctx: &mut Ctx,
    loc: Loc,
    filename: &str,
    decode: Decode,
    substitute: &str,
) -> Option<Arc<RgbImage>> {
    let path = ctx.resolve(loc, filename);
    if let Some(img) = ctx.images.decoded.get(&(path.clone(), decode)) {
        return Some(img.clone());
    }
    let raw = read_once(
        ctx,
        &path,
        |c| &mut c.raw,
        |ctx, bytes| {
            let (img, bad) = clamp_texels(decode_image(&bytes, &path)?);
            if bad > 0 {
                ctx.warn(
                loc,
                format!("image \"{}\" has {bad} texel values that are NaN, infinite or negative: they are read as 0", path.display()),
                "texels clamped",
            );
            }
            Ok(img)
        },
    );
    match raw {
        Ok(raw) => {
            let img = match decode {
                Decode::Raw => raw,
                _ => Arc::new(raw.decoded(decode)),
            };
            ctx.images.decoded.insert((path, decode), img.clone());
            Some(img)
        }
        Err(e) => {
            ctx.warn(
                loc,
                format!(
                    "cannot read image \"{}\": {e}: {substitute} (as pbrt-v3, which renders on)",
                    path.display()
                ),
                "this image",
            );
            None
        }
    }
}

/// The Ptex file `filename` (read once per scene), or `None` after a
/// located warning that names the file and says what is used instead: a
/// file that cannot be read or is malformed, or (as pbrt-v3) one with
/// other than 1 or 3 channels. A triangle-mesh file warns that it is
/// point-sampled.
pub fn load_ptex(
    ctx: &mut Ctx,
    loc: Loc,
    filename: &str,
    substitute: &str,
) -> Option<Arc<PtexFile>> {
    let path = ctx.resolve(loc, filename);
    let file = read_once(
        ctx,
        &path,
        |c| &mut c.ptex,
        |_, bytes| PtexFile::parse(&bytes),
    );
    let file = match file {
        Ok(f) if f.nchannels == 1 || f.nchannels == 3 => f,
        Ok(f) => {
            ctx.warn(loc, format!("Ptex file \"{}\" has {} channels: only one and three channel ptex textures are supported (as pbrt-v3): {substitute}", path.display(), f.nchannels), "this Ptex file");
            return None;
        }
        Err(e) => {
            ctx.warn(
                loc,
                format!(
                    "cannot read Ptex file \"{}\": {e}: {substitute} (as pbrt-v3, which renders on)",
                    path.display()
                ),
                "this Ptex file",
            );
            return None;
        }
    };
    if file.triangles {
        ctx.warn(loc, format!("Ptex file \"{}\" is of a triangle mesh: pbrs point-samples it (pbrt-v3 uses the Ptex library's triangle filter)", path.display()), "point-sampled");
    }
    Some(file)
}

/// The image with every NaN, infinite or negative value set to 0 (such
/// values would become dropped samples, or break a light's sampling
/// distribution), and how many there were.
fn clamp_texels(img: RgbImage) -> (RgbImage, usize) {
    let ok = |v: f32| v.is_finite() && v >= 0.0;
    let bad: usize = img
        .pixels()
        .iter()
        .map(|p| p.to_array().into_iter().filter(|&v| !ok(v)).count())
        .sum();
    if bad == 0 {
        return (img, 0);
    }
    (img.map_channels(|v| if ok(v) { v } else { 0.0 }), bad)
}

/// Decodes an image file's bytes; the format comes from `name`'s extension.
pub fn decode_image(bytes: &[u8], name: &Path) -> Result<RgbImage, String> {
    let ext = name
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .unwrap_or_default();
    if bytes.is_empty() {
        return Err("the file is empty".into());
    }
    let run = || {
        match ext.as_str() {
        "png" => check_png_chunks(bytes).and_then(|()| decode_with_image_crate(bytes, image::ImageFormat::Png)),
        "tga" => check_tga_runs(bytes).and_then(|()| decode_with_image_crate(bytes, image::ImageFormat::Tga)),
        "hdr" => decode_with_image_crate(bytes, image::ImageFormat::Hdr),
        "exr" => decode_exr(bytes),
        "pfm" => decode_pfm(bytes),
        "" => Err("no file extension to tell the image format (pbrs reads .png, .tga, .exr, .pfm and .hdr)".into()),
        e => Err(format!(
            "image format \".{e}\" is not supported (pbrs reads .png, .tga, .exr, .pfm and .hdr)"
        )),
    }
    };
    // The decoders are third-party code fed untrusted bytes: a panic in one
    // is reported as this file's error.
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(run)) {
        Ok(r) => r,
        Err(_) => Err("the image decoder failed on this file (corrupt data)".into()),
    }
}

/// Images above this many pixels must not claim more than
/// [`MAX_COMPRESSION`] decoded bytes per byte of file.
const BOMB_PIXELS: u64 = 1 << 24;

/// The most decoded bytes (3 a pixel) per file byte of an image above
/// [`BOMB_PIXELS`]: photographs and rendered maps compress 2–20×; a file
/// beyond this is a decompression bomb (a small file that claims a huge
/// flat image), refused before anything is decoded.
const MAX_COMPRESSION: u64 = 256;

/// [`check_size`] and the decompression-bomb test against the file's size.
fn check_claim(w: u64, h: u64, file_bytes: usize) -> Result<(), String> {
    check_size(w, h)?;
    let n = w * h;
    if n > BOMB_PIXELS && n * 3 > MAX_COMPRESSION * file_bytes as u64 {
        return Err(format!(
            "the image claims {w}×{h} pixels from a file of {file_bytes} bytes (more than {MAX_COMPRESSION}× compression): refused as a decompression bomb"
        ));
    }
    Ok(())
}

/// PNG's chunk structure and CRCs (the decoder ignores a bad CRC): a
/// corrupt file is an error, not an image of whatever the bytes decode to.
fn check_png_chunks(bytes: &[u8]) -> Result<(), String> {
    const SIG: &[u8] = b"\x89PNG\r\n\x1a\n";
    if !bytes.starts_with(SIG) {
        return Err("not a PNG file (no PNG signature)".into());
    }
    let mut at = SIG.len();
    while at + 12 <= bytes.len() {
        let len =
            u32::from_be_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]) as usize;
        let name = String::from_utf8_lossy(&bytes[at + 4..at + 8]).into_owned();
        let end = at + 8 + len;
        if len > i32::MAX as usize || end + 4 > bytes.len() {
            return Err(format!(
                "chunk {name} at byte {at} runs past the end of the file (truncated or corrupt)"
            ));
        }
        let stored =
            u32::from_be_bytes([bytes[end], bytes[end + 1], bytes[end + 2], bytes[end + 3]]);
        if crc32(&bytes[at + 4..end]) != stored {
            return Err(format!(
                "chunk {name} at byte {at} has a bad CRC (the file is corrupt)"
            ));
        }
        if name == "IEND" {
            return Ok(());
        }
        at = end + 4;
    }
    Err("the file ends before its IEND chunk (truncated)".into())
}

/// The CRC-32 of PNG chunks.
fn crc32(bytes: &[u8]) -> u32 {
    let mut c = !0u32;
    for &b in bytes {
        c ^= b as u32;
        for _ in 0..8 {
            c = if c & 1 != 0 {
                (c >> 1) ^ 0xEDB8_8320
            } else {
                c >> 1
            };
        }
    }
    !c
}

/// A run-length encoded TGA's packets (the decoder lets a run overrun the
/// image and truncates it): every packet must fit in the image's pixels,
/// and the data must hold them all.
fn check_tga_runs(bytes: &[u8]) -> Result<(), String> {
    if bytes.len() < 18 {
        return Err(format!("truncated TGA header ({} bytes)", bytes.len()));
    }
    let u16_at = |i: usize| u16::from_le_bytes([bytes[i], bytes[i + 1]]) as u64;
    let image_type = bytes[2];
    if !matches!(image_type, 9..=11) {
        return Ok(());
    }
    let (w, h) = (u16_at(12), u16_at(14));
    check_claim(w, h, bytes.len())?;
    let pixel_bytes = (bytes[16] as usize).div_ceil(8).max(1);
    let map_bytes = if bytes[1] != 0 {
        u16_at(5) as usize * (bytes[7] as usize).div_ceil(8)
    } else {
        0
    };
    let mut at = 18 + bytes[0] as usize + map_bytes;
    let (total, mut done) = (w * h, 0u64);
    while done < total {
        let Some(&head) = bytes.get(at) else {
            return Err(format!(
                "the run-length data ends after {done} of {total} pixels (truncated)"
            ));
        };
        let count = (head & 0x7f) as u64 + 1;
        if done + count > total {
            return Err(format!(
                "a run-length packet at byte {at} runs past the image's {total} pixels (corrupt)"
            ));
        }
        at += 1 + if head & 0x80 != 0 {
            pixel_bytes
        } else {
            count as usize * pixel_bytes
        };
        done += count;
    }
    if at > bytes.len() {
        return Err(format!(
            "the run-length data ends before its last packet ({at} bytes needed, the file has {})",
            bytes.len()
        ));
    }
    Ok(())
}

fn check_size(w: u64, h: u64) -> Result<(), String> {
    if w == 0 || h == 0 {
        return Err(format!("the image is empty ({w}×{h} pixels)"));
    }
    match w.checked_mul(h) {
        // Decoded to f32 RGBA at most, plus the MIP pyramid (a third more).
        Some(n) if n <= MAX_IMAGE_PIXELS => crate::scene::memory::check_budget(
            &format!("the image ({w}×{h} pixels)"),
            n * 16 * 4 / 3,
        ),
        _ => Err(format!(
            "the image declares {w}×{h} pixels, more than pbrs reads ({MAX_IMAGE_PIXELS} pixels)"
        )),
    }
}

fn decode_with_image_crate(bytes: &[u8], format: image::ImageFormat) -> Result<RgbImage, String> {
    use image::{DynamicImage, ImageDecoder};
    let mut reader = image::ImageReader::with_format(Cursor::new(bytes), format);
    let mut limits = image::Limits::default();
    // 16 bytes a pixel: the largest decoded form (RGBA f32).
    limits.max_alloc = Some(MAX_IMAGE_PIXELS * 16);
    reader.limits(limits);
    let decoder = reader.into_decoder().map_err(|e| e.to_string())?;
    let (w, h) = decoder.dimensions();
    check_claim(w as u64, h as u64, bytes.len())?;
    let img = DynamicImage::from_decoder(decoder).map_err(|e| e.to_string())?;
    let n = w as usize * h as usize;
    let lut = crate::image::unorm8_table();
    let (pixels, depth): (Vec<Vec3>, SampleDepth) = match &img {
        DynamicImage::ImageRgb32F(b) => (
            b.as_raw()
                .chunks_exact(3)
                .map(|c| Vec3::new(c[0], c[1], c[2]))
                .collect(),
            SampleDepth::F32,
        ),
        DynamicImage::ImageRgba32F(b) => (
            b.as_raw()
                .chunks_exact(4)
                .map(|c| Vec3::new(c[0], c[1], c[2]))
                .collect(),
            SampleDepth::F32,
        ),
        DynamicImage::ImageLuma16(_)
        | DynamicImage::ImageLumaA16(_)
        | DynamicImage::ImageRgb16(_)
        | DynamicImage::ImageRgba16(_) => {
            let rgb = img.to_rgb16();
            (
                rgb.as_raw()
                    .chunks_exact(3)
                    .map(|c| Vec3::from_array(c.map_ref(|v| lut[(v >> 8) as usize])))
                    .collect(),
                SampleDepth::U8,
            )
        }
        _ => {
            let rgb = img.to_rgb8();
            (
                rgb.as_raw()
                    .chunks_exact(3)
                    .map(|c| Vec3::new(lut[c[0] as usize], lut[c[1] as usize], lut[c[2] as usize]))
                    .collect(),
                SampleDepth::U8,
            )
        }
    };
    if pixels.len() != n {
        return Err("the decoded image has the wrong number of pixels".into());
    }
    RgbImage::new(w, h, pixels, depth).ok_or_else(|| "the image is empty".to_string())
}

/// `[T; 3]::map` by reference, for the 16-bit rows above.
trait MapRef<T> {
    fn map_ref<U>(&self, f: impl Fn(T) -> U) -> [U; 3];
}

impl<T: Copy> MapRef<T> for [T] {
    fn map_ref<U>(&self, f: impl Fn(T) -> U) -> [U; 3] {
        [f(self[0]), f(self[1]), f(self[2])]
    }
}

fn decode_exr(bytes: &[u8]) -> Result<RgbImage, String> {
    use exr::prelude::traits::*;
    use exr::prelude::{AnyChannel, FlatSamples};
    let meta = exr::meta::MetaData::read_from_buffered(Cursor::new(bytes), false)
        .map_err(|e| e.to_string())?;
    if meta.headers.iter().all(|h| h.deep) {
        return Err("the file holds only deep data (pbrs reads flat images)".into());
    }
    for h in meta.headers.iter() {
        let (w, hh) = (h.layer_size.width() as u64, h.layer_size.height() as u64);
        check_claim(w, hh, bytes.len())?;
        let channels = h.channels.list.len() as u64;
        // Every channel is held as one sample a pixel while reading.
        if w * hh * channels.max(1) > 4 * MAX_IMAGE_PIXELS {
            return Err(format!(
                "the image declares {w}×{hh} pixels of {channels} channels, more than pbrs reads"
            ));
        }
    }
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .non_parallel()
        .from_buffered(Cursor::new(bytes))
        .map_err(|e| e.to_string())?;
    let layer = image.layer_data;
    let (w, h) = (layer.size.width(), layer.size.height());
    check_size(w as u64, h as u64)?;
    let n = w * h;
    let channels = &layer.channel_data.list;
    let find = |name: &str| channels.iter().find(|c| c.name.eq(name));
    let mut depth = SampleDepth::F16;
    let mut values = |c: &AnyChannel<FlatSamples>| -> Result<Vec<f32>, String> {
        let v: Vec<f32> = match &c.sample_data {
            FlatSamples::F16(s) => s.iter().map(|x| x.to_f32()).collect(),
            FlatSamples::F32(s) => {
                depth = SampleDepth::F32;
                s.clone()
            }
            FlatSamples::U32(s) => {
                depth = SampleDepth::F32;
                s.iter().map(|&x| x as f32).collect()
            }
        };
        if v.len() == n {
            Ok(v)
        } else {
            Err(format!("channel {} has {} samples for {n} pixels (subsampled channels are not supported by pbrs)", c.name, v.len()))
        }
    };
    let pixels: Vec<Vec3> = match (find("R"), find("G"), find("B"), find("Y")) {
        (None, None, None, Some(y)) => values(y)?.into_iter().map(Vec3::splat).collect(),
        (None, None, None, None) => {
            let names: Vec<String> = channels.iter().map(|c| c.name.to_string()).collect();
            return Err(format!(
                "no R, G, B or Y channel (channels: {})",
                names.join(", ")
            ));
        }
        (r, g, b, _) => {
            let mut get = |c: Option<&AnyChannel<FlatSamples>>| -> Result<Vec<f32>, String> {
                match c {
                    Some(c) => values(c),
                    None => Ok(vec![0.0; n]),
                }
            };
            let (r, g, b) = (get(r)?, get(g)?, get(b)?);
            (0..n).map(|i| Vec3::new(r[i], g[i], b[i])).collect()
        }
    };
    RgbImage::new(w as u32, h as u32, pixels, depth).ok_or_else(|| "the image is empty".to_string())
}

fn decode_pfm(bytes: &[u8]) -> Result<RgbImage, String> {
    let img = crate::image::io::parse_pfm(bytes)?;
    let pixels = img
        .data
        .chunks_exact(3)
        .map(|c| Vec3::new(c[0], c[1], c[2]))
        .collect();
    RgbImage::new(img.width, img.height, pixels, SampleDepth::F32)
        .ok_or_else(|| "the image is empty".to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn png_bytes(w: u32, h: u32, data: &[u8], ty: image::ExtendedColorType) -> Vec<u8> {
        use image::ImageEncoder;
        let mut out = Vec::new();
        image::codecs::png::PngEncoder::new(&mut out)
            .write_image(data, w, h, ty)
            .unwrap();
        out
    }

    fn tga_bytes(w: u32, h: u32, data: &[u8], ty: image::ExtendedColorType) -> Vec<u8> {
        use image::ImageEncoder;
        let mut out = Vec::new();
        image::codecs::tga::TgaEncoder::new(&mut out)
            .write_image(data, w, h, ty)
            .unwrap();
        out
    }

    fn hdr_bytes(w: usize, h: usize, data: &[image::Rgb<f32>]) -> Vec<u8> {
        let mut out = Vec::new();
        image::codecs::hdr::HdrEncoder::new(&mut out)
            .encode(data, w, h)
            .unwrap();
        out
    }

    fn exr_bytes_rgb_half(
        w: usize,
        h: usize,
        f: impl Fn(usize, usize) -> [f32; 3] + Sync,
    ) -> Vec<u8> {
        use exr::prelude::*;
        let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
            let v = f(x, y);
            (
                f16::from_f32(v[0]),
                f16::from_f32(v[1]),
                f16::from_f32(v[2]),
            )
        });
        let img = Image::from_channels((w, h), channels);
        let mut c = Cursor::new(Vec::new());
        img.write().non_parallel().to_buffered(&mut c).unwrap();
        c.into_inner()
    }

    fn exr_bytes_y(w: usize, h: usize) -> Vec<u8> {
        use exr::prelude::*;
        let samples: Vec<f32> = (0..w * h).map(|i| i as f32 * 0.5).collect();
        let layer = Layer::new(
            (w, h),
            LayerAttributes::default(),
            Encoding::FAST_LOSSLESS,
            AnyChannels::sort(SmallVec::from_vec(vec![AnyChannel::new(
                "Y",
                FlatSamples::F32(samples),
            )])),
        );
        let img = Image::from_layer(layer);
        let mut c = Cursor::new(Vec::new());
        img.write().non_parallel().to_buffered(&mut c).unwrap();
        c.into_inner()
    }

    fn pfm_bytes(w: u32, h: u32, scale: &str, v: &[f32]) -> Vec<u8> {
        let mut out = format!("PF\n{w} {h}\n{scale}\n").into_bytes();
        for y in (0..h as usize).rev() {
            for x in 0..(w as usize * 3) {
                out.extend_from_slice(&v[y * w as usize * 3 + x].to_le_bytes());
            }
        }
        out
    }

    fn dec(bytes: &[u8], name: &str) -> Result<RgbImage, String> {
        decode_image(bytes, Path::new(name))
    }

    #[test]
    fn png_8_and_16_bit_grey_and_alpha() {
        use image::ExtendedColorType as T;
        let rgb = png_bytes(2, 1, &[0, 128, 255, 10, 20, 30], T::Rgb8);
        let img = dec(&rgb, "a.PNG").unwrap();
        assert_eq!(
            (img.width(), img.height(), img.depth()),
            (2, 1, SampleDepth::U8)
        );
        assert_eq!(img.get(0, 0), Vec3::new(0.0, 128.0 / 255.0, 1.0));
        assert_eq!(img.get(1, 0), Vec3::new(10.0, 20.0, 30.0) / 255.0);
        let grey_alpha = png_bytes(1, 2, &[51, 0, 102, 255], T::La8);
        let img = dec(&grey_alpha, "a.png").unwrap();
        assert_eq!(img.get(0, 0), Vec3::splat(0.2));
        assert_eq!(img.get(0, 1), Vec3::splat(0.4));
        // 16 bit (the encoder takes native-endian samples): the high byte, as
        // lodepng's 8-bit conversion.
        let v16: Vec<u8> = [0x80ffu16, 0x0100, 0xffff]
            .iter()
            .flat_map(|v| v.to_ne_bytes())
            .collect();
        let img = dec(&png_bytes(1, 1, &v16, T::Rgb16), "a.png").unwrap();
        assert_eq!(img.get(0, 0), Vec3::new(128.0, 1.0, 255.0) / 255.0);
    }

    #[test]
    fn tga_rows_top_first() {
        use image::ExtendedColorType as T;
        let t = tga_bytes(1, 2, &[255, 0, 0, 0, 0, 255], T::Rgb8);
        let img = dec(&t, "x.tga").unwrap();
        assert_eq!(img.get(0, 0), Vec3::X);
        assert_eq!(img.get(0, 1), Vec3::Z);
    }

    #[test]
    fn hdr_is_linear_float() {
        let px = [image::Rgb([1.0f32, 0.5, 0.25]), image::Rgb([8.0, 2.0, 0.0])];
        let img = dec(&hdr_bytes(2, 1, &px), "sky.hdr").unwrap();
        assert_eq!(img.depth(), SampleDepth::F32);
        assert_eq!(img.get(0, 0), Vec3::new(1.0, 0.5, 0.25));
        assert_eq!(img.get(1, 0), Vec3::new(8.0, 2.0, 0.0));
    }

    #[test]
    fn exr_half_rgb_and_luminance_only() {
        let e = exr_bytes_rgb_half(3, 2, |x, y| [x as f32, y as f32, 0.5]);
        let img = dec(&e, "a.exr").unwrap();
        assert_eq!(
            (img.width(), img.height(), img.depth()),
            (3, 2, SampleDepth::F16)
        );
        assert_eq!(img.get(2, 1), Vec3::new(2.0, 1.0, 0.5));
        let y = dec(&exr_bytes_y(2, 2), "y.exr").unwrap();
        assert_eq!(y.depth(), SampleDepth::F32);
        assert_eq!(y.get(1, 1), Vec3::splat(1.5));
    }

    #[test]
    fn pfm_scale_and_order() {
        let v = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        let img = dec(&pfm_bytes(1, 2, "-1.0", &v), "a.pfm").unwrap();
        assert_eq!(img.get(0, 0), Vec3::new(1.0, 2.0, 3.0));
        let img = dec(&pfm_bytes(1, 2, "-2.0", &v), "a.pfm").unwrap();
        assert_eq!(img.get(0, 1), Vec3::new(8.0, 10.0, 12.0));
    }

    fn valid_files() -> Vec<(&'static str, Vec<u8>)> {
        use image::ExtendedColorType as T;
        let px: Vec<u8> = (0..8 * 5 * 3).map(|i| (i * 7) as u8).collect();
        let hdr: Vec<image::Rgb<f32>> = (0..8 * 5)
            .map(|i| image::Rgb([i as f32, 1.0, 0.5]))
            .collect();
        let pfm: Vec<f32> = (0..8 * 5 * 3).map(|i| i as f32).collect();
        vec![
            ("a.png", png_bytes(8, 5, &px, T::Rgb8)),
            ("a.tga", tga_bytes(8, 5, &px, T::Rgb8)),
            ("a.hdr", hdr_bytes(8, 5, &hdr)),
            (
                "a.exr",
                exr_bytes_rgb_half(8, 5, |x, y| [x as f32, y as f32, 1.0]),
            ),
            ("a.pfm", pfm_bytes(8, 5, "-1", &pfm)),
        ]
    }

    /// Every prefix of a valid file, and the file with bytes flipped, gives
    /// an image or an error, never a panic; a prefix that leaves out
    /// pixel data is an error (no silent zeros).
    #[test]
    fn truncated_and_corrupt_files_are_errors() {
        for (name, bytes) in valid_files() {
            let full = dec(&bytes, name).unwrap();
            for len in 0..bytes.len() {
                let r = dec(&bytes[..len], name);
                if let Ok(img) = &r {
                    // Some formats end with optional bytes (a TGA footer, PNG's IEND).
                    assert_eq!(
                        img,
                        &full,
                        "{name} cut at {len} of {} decoded differently",
                        bytes.len()
                    );
                }
            }
            // A cut at 60% of the file always loses pixels.
            assert!(dec(&bytes[..bytes.len() * 3 / 5], name).is_err(), "{name}");
            let mut rng = crate::sampling::Pcg32::with_sequence(7);
            for _ in 0..300 {
                let mut b = bytes.clone();
                for _ in 0..1 + rng.uniform_u32() % 4 {
                    let i = rng.uniform_u32() as usize % b.len();
                    b[i] ^= 1 << (rng.uniform_u32() % 8);
                }
                let _ = dec(&b, name);
            }
        }
    }

    #[test]
    fn declared_sizes_beyond_the_bound_or_the_data_are_errors() {
        // PFM: a header claiming 2^20 × 2^20 pixels over a few bytes.
        let e = dec(b"PF\n1048576 1048576\n-1\n\0\0\0\0", "a.pfm").unwrap_err();
        assert!(e.contains("more than pbrs reads"), "{e}");
        let e = dec(b"PF\n18446744073709551615 3\n-1\n\0\0\0\0", "a.pfm").unwrap_err();
        assert!(
            e.contains("more than pbrs reads") || e.contains("bad PFM"),
            "{e}"
        );
        let e = dec(b"PF\n4 4\n-1\n\0\0\0\0", "a.pfm").unwrap_err();
        assert!(e.contains("truncated"), "{e}");
        let e = dec(b"PF\n0 4\n-1\n", "a.pfm").unwrap_err();
        assert!(e.contains("empty"), "{e}");
        // PNG: patch the IHDR's width and height (and its CRC) to 2^16 × 2^16.
        use image::ExtendedColorType as T;
        let mut png = png_bytes(2, 2, &[0; 12], T::Rgb8);
        png[16..20].copy_from_slice(&65536u32.to_be_bytes());
        png[20..24].copy_from_slice(&65536u32.to_be_bytes());
        let crc = crc32(&png[12..29]);
        png[29..33].copy_from_slice(&crc.to_be_bytes());
        let e = dec(&png, "a.png").unwrap_err();
        assert!(e.contains("more than pbrs reads"), "{e}");
        // Same size, real pixels missing.
        let mut png = png_bytes(2, 2, &[0; 12], T::Rgb8);
        png[16..20].copy_from_slice(&64u32.to_be_bytes());
        let crc = crc32(&png[12..29]);
        png[29..33].copy_from_slice(&crc.to_be_bytes());
        assert!(dec(&png, "a.png").is_err());
        // TGA: width and height fields at 12 and 14.
        let mut tga = tga_bytes(2, 2, &[0; 12], T::Rgb8);
        tga[12..14].copy_from_slice(&65535u16.to_le_bytes());
        tga[14..16].copy_from_slice(&65535u16.to_le_bytes());
        assert!(dec(&tga, "a.tga").is_err());
        // EXR: the data window's corners patched to 2^20 × 2^20 pixels.
        let mut exr = exr_bytes_rgb_half(2, 2, |_, _| [1.0; 3]);
        let key = b"dataWindow\0box2i\0";
        let at = exr.windows(key.len()).position(|w| w == key).unwrap() + key.len() + 4;
        exr[at + 8..at + 12].copy_from_slice(&(1i32 << 20).to_le_bytes());
        exr[at + 12..at + 16].copy_from_slice(&(1i32 << 20).to_le_bytes());
        let e = dec(&exr, "a.exr").unwrap_err();
        assert!(e.contains("more than pbrs reads"), "{e}");
        // Zero-sized and unknown.
        assert!(dec(b"", "a.exr").unwrap_err().contains("empty"));
        assert!(dec(b"abc", "a.jpg").unwrap_err().contains("not supported"));
        assert!(dec(b"abc", "noext").is_err());
        assert!(dec(
            b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 0 +X 0\n",
            "a.hdr"
        )
        .is_err());
    }
}
