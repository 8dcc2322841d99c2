//! Parts of a frame for a render farm, and their exact merge.
//!
//! Two kinds of part, each an OpenEXR file with one header attribute
//! (`pbrsFarmPart`, text: one `key=value` per line) recording the format
//! version, a hash of the scene, the resolution, the film's pixel bounds
//! (crop window), spp, sampler, seed, filter, film scale and the part itself:
//!
//! * **Tile K of N**: the rows [`tile_rect`] gives of the film's pixel
//!   bounds, as the final f32 RGB values (channels R, G, B), data window =
//!   the rows in image coordinates. The job takes samples in every pixel
//!   whose samples can reach those rows (the filter's radius, plus one pixel
//!   of margin), in the full render's tile, pixel, sample and merge order, so
//!   each of its pixels has the full render's f64 sums bit for bit and
//!   merging is assembly: the merged image equals the single-machine one.
//! * **Samples [A, B)**: sample indices A..B of every pixel, as the film's
//!   f64 weighted sums (Σ w·L per channel, Σ w) stored losslessly: each f64's
//!   bit pattern as two UINT channels (`<sum>.hi`, `<sum>.lo`, the high and
//!   low 32 bits), for R, G, B and the weight. Merging adds the parts' sums
//!   in f64 in the order of A and divides; the full render adds the same
//!   terms in another order (see [`merge`] for the bound). A film with
//!   splats (bdpt's light tracing) also stores its f64 splat sums
//!   (`splat.R.hi`, ... `splat.B.lo`), added the same way and divided by
//!   the spp. bdpt refuses tiles: its splats from any pixel reach every
//!   tile.

use super::{pixel_rgb, pixel_rgb_splat, Film, Image, PixelSums};
use crate::geometry::Bounds2i;
use crate::scene::SceneDescription;
use glam::{IVec2, Vec2};
use std::fmt::Write as _;
use std::io::Cursor;
use std::path::{Path, PathBuf};

/// Version of the part format (the `version` key).
pub const FORMAT_VERSION: u32 = 1;

/// Name of the header attribute holding the part's description.
pub const ATTRIBUTE: &str = "pbrsFarmPart";

/// What a part holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PartKind {
    /// Rows [`tile_rect`]`(bounds, index, count)` of the image, final values.
    Tile { index: u32, count: u32 },
    /// Sample indices `start..end` of every pixel, as f64 sums.
    Samples { start: u32, end: u32 },
}

impl std::fmt::Display for PartKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PartKind::Tile { index, count } => write!(f, "tile {index} of {count}"),
            PartKind::Samples { start, end } => write!(f, "samples [{start}, {end})"),
        }
    }
}

/// The settings every part of one frame shares (ordered `key`, `value`
/// pairs) and the part itself.
#[derive(Clone, Debug, PartialEq)]
pub struct PartHeader {
    pub settings: Vec<(String, String)>,
    pub kind: PartKind,
}

impl PartHeader {
    /// The header of a part of `desc` (after command-line overrides) rendered
    /// with `seed`.
    pub fn new(desc: &SceneDescription, film: &Film, seed: u64, kind: PartKind) -> PartHeader {
        let pb = film.pixel_bounds();
        let settings = [
            ("version", FORMAT_VERSION.to_string()),
            (
                "resolution",
                format!("{} {}", desc.film.xresolution, desc.film.yresolution),
            ),
            (
                "pixelbounds",
                format!("{} {} {} {}", pb.min.x, pb.max.x, pb.min.y, pb.max.y),
            ),
            ("spp", desc.sampler.pixel_samples.to_string()),
            (
                "sampler",
                format!(
                    "{:?} samplepixelcenter={}",
                    desc.sampler.kind, desc.sampler.sample_pixel_center
                ),
            ),
            ("seed", seed.to_string()),
            ("filter", desc.filter.describe()),
            ("scale", format!("{:08x}", desc.film.scale.to_bits())),
            // Last: the hash covers the settings above too, and the merge
            // names the first setting that differs.
            ("scene", scene_hash(desc)),
        ];
        PartHeader {
            settings: settings
                .into_iter()
                .map(|(k, v)| (k.to_string(), v))
                .collect(),
            kind,
        }
    }

    fn setting(&self, key: &str) -> Option<&str> {
        self.settings
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }

    fn to_text(&self) -> String {
        let mut s = String::new();
        for (k, v) in &self.settings {
            let _ = writeln!(s, "{k}={v}");
        }
        match self.kind {
            PartKind::Tile { index, count } => {
                let _ = writeln!(s, "part=tile {index} {count}");
            }
            PartKind::Samples { start, end } => {
                let _ = writeln!(s, "part=samples {start} {end}");
            }
        }
        s
    }

    fn parse(text: &str) -> Result<PartHeader, String> {
        let mut settings = Vec::new();
        let mut kind = None;
        for line in text.lines() {
            let (k, v) = line
                .split_once('=')
                .ok_or_else(|| format!("malformed {ATTRIBUTE} line {line:?}"))?;
            if k == "part" {
                let w: Vec<&str> = v.split_whitespace().collect();
                let num = |s: &str| {
                    s.parse::<u32>()
                        .map_err(|_| format!("malformed part description {v:?}"))
                };
                kind = Some(match w.as_slice() {
                    ["tile", a, b] => PartKind::Tile {
                        index: num(a)?,
                        count: num(b)?,
                    },
                    ["samples", a, b] => PartKind::Samples {
                        start: num(a)?,
                        end: num(b)?,
                    },
                    _ => return Err(format!("malformed part description {v:?}")),
                });
            } else {
                settings.push((k.to_string(), v.to_string()));
            }
        }
        let kind = kind.ok_or_else(|| format!("{ATTRIBUTE} names no part"))?;
        let h = PartHeader { settings, kind };
        match h.setting("version") {
            Some(v) if v == FORMAT_VERSION.to_string() => Ok(h),
            Some(v) => Err(format!(
                "part format version {v}; this pbrs reads version {FORMAT_VERSION}"
            )),
            None => Err("the part records no format version".into()),
        }
    }
}

/// A 64-bit FNV-1a hash (hex) of the scene as pbrs compiled it: the
/// description's debug text (every shape, mesh, material, light, camera and
/// setting; Includes are already spliced) with the output file name left
/// out, so all parts of one frame agree.
pub fn scene_hash(desc: &SceneDescription) -> String {
    struct Fnv(u64);
    impl std::fmt::Write for Fnv {
        fn write_str(&mut self, s: &str) -> std::fmt::Result {
            for &b in s.as_bytes() {
                self.0 ^= b as u64;
                self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
            }
            Ok(())
        }
    }
    let mut d = desc.clone();
    d.film.filename = PathBuf::new();
    let mut h = Fnv(0xcbf2_9ce4_8422_2325);
    let _ = write!(h, "{d:?}");
    format!("{:016x}", h.0)
}

/// Rows of tile `k` of `n` of `bounds`: rows `y0 + h·k/n .. y0 + h·(k+1)/n`
/// (every row in exactly one tile; N must not exceed the height).
pub fn tile_rect(bounds: Bounds2i, k: u32, n: u32) -> Bounds2i {
    let h = bounds.height().max(0) as u64;
    let row = |k: u32| bounds.min.y + (h * k as u64 / n.max(1) as u64) as i32;
    Bounds2i::new(
        IVec2::new(bounds.min.x, row(k)),
        IVec2::new(bounds.max.x, row(k + 1)),
    )
}

/// Checks a tile request against the film: K < N and N ≤ the image's rows.
pub fn check_tile(film: &Film, k: u32, n: u32) -> Result<(), String> {
    let h = film.pixel_bounds().height().max(0) as u32;
    if n == 0 {
        return Err("--tiles must be at least 1".into());
    }
    if k >= n {
        return Err(format!(
            "--tile {k} is not a tile of --tiles {n} (tiles are numbered 0 to {})",
            n - 1
        ));
    }
    if n > h {
        return Err(format!(
            "--tiles {n} is more than the {h} rows of the image (tiles are bands of rows)"
        ));
    }
    Ok(())
}

/// The pixels whose samples can reach `rect` (pbrt-v3's sample bounds of a
/// rectangle, one pixel wider each way for samples that f32 rounding puts on
/// a pixel's far edge), within the film's sample bounds.
pub fn sample_region(film: &Film, rect: Bounds2i) -> Bounds2i {
    let r = film.filter().radius();
    let min = (rect.min.as_vec2() + Vec2::splat(0.5) - r)
        .floor()
        .as_ivec2()
        - IVec2::ONE;
    let max = (rect.max.as_vec2() - Vec2::splat(0.5) + r)
        .ceil()
        .as_ivec2()
        + IVec2::ONE;
    Bounds2i::new(min, max).intersect(&film.sample_bounds())
}

/// A part as read from a file.
#[derive(Clone, Debug)]
pub struct Part {
    pub path: PathBuf,
    pub header: PartHeader,
    /// The data window (image pixel coordinates, exclusive max).
    pub window: Bounds2i,
    pub data: PartData,
    /// A sample range's splat sums over the window (bdpt's light
    /// tracing), if it has any.
    pub splats: Option<Vec<[f64; 3]>>,
}

#[derive(Clone, Debug)]
pub enum PartData {
    /// Final RGB triples over the window, rows top to bottom.
    Rgb(Vec<f32>),
    /// The film's sums over the window.
    Sums(Vec<PixelSums>),
}

const SUM_CHANNELS: [&str; 4] = ["R", "G", "B", "W"];

/// The channels of a sample range's splat sums (present only when the
/// film has splats).
const SPLAT_CHANNELS: [&str; 3] = ["splat.R", "splat.G", "splat.B"];

/// `v`'s f64 bit patterns as the two UINT channels `<name>.hi`, `.lo`.
fn f64_channels(
    name: &str,
    v: impl Iterator<Item = f64>,
    out: &mut Vec<exr::prelude::AnyChannel<exr::prelude::FlatSamples>>,
) {
    use exr::prelude::{AnyChannel, FlatSamples};
    let bits: Vec<u64> = v.map(f64::to_bits).collect();
    let hi = bits.iter().map(|b| (b >> 32) as u32).collect();
    let lo = bits.iter().map(|&b| b as u32).collect();
    out.push(AnyChannel::new(
        format!("{name}.hi").as_str(),
        FlatSamples::U32(hi),
    ));
    out.push(AnyChannel::new(
        format!("{name}.lo").as_str(),
        FlatSamples::U32(lo),
    ));
}

fn exr_bounds(b: Bounds2i) -> exr::meta::attribute::IntegerBounds {
    exr::meta::attribute::IntegerBounds::new(
        exr::math::Vec2(b.min.x, b.min.y),
        exr::math::Vec2(b.width().max(0) as usize, b.height().max(0) as usize),
    )
}

fn encode_part(
    header: &PartHeader,
    display: Bounds2i,
    window: Bounds2i,
    channels: Vec<exr::prelude::AnyChannel<exr::prelude::FlatSamples>>,
) -> Result<Vec<u8>, String> {
    use exr::prelude::*;
    let text = Text::new_or_none(header.to_text())
        .ok_or("the part header cannot be written as EXR text")?;
    let mut la = LayerAttributes {
        layer_position: Vec2(window.min.x, window.min.y),
        ..Default::default()
    };
    la.other
        .insert(Text::new_or_panic(ATTRIBUTE), AttributeValue::Text(text));
    let size = (window.width() as usize, window.height() as usize);
    let layer = Layer::new(
        size,
        la,
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(channels.into()),
    );
    let image = exr::image::Image::new(ImageAttributes::new(exr_bounds(display)), layer);
    let mut cursor = Cursor::new(Vec::new());
    image
        .write()
        .non_parallel()
        .to_buffered(&mut cursor)
        .map_err(|e| e.to_string())?;
    Ok(cursor.into_inner())
}

/// Writes tile `header.kind` of `film` (rendered with at least the samples
/// of [`sample_region`]) to `path`, atomically.
pub fn write_tile_part(path: &Path, header: &PartHeader, film: &Film) -> Result<(), String> {
    use exr::prelude::{AnyChannel, FlatSamples};
    let PartKind::Tile { index, count } = header.kind else {
        return Err("not a tile part".into());
    };
    let rect = tile_rect(film.pixel_bounds(), index, count);
    let (rect, rgb) = film.region_rgb(rect);
    let channels = (0..3)
        .map(|c| {
            let v: Vec<f32> = rgb.iter().skip(c).step_by(3).copied().collect();
            AnyChannel::new(["R", "G", "B"][c], FlatSamples::F32(v))
        })
        .collect();
    let bytes = encode_part(header, film.pixel_bounds(), rect, channels)
        .map_err(|e| format!("{}: {e}", path.display()))?;
    crate::image::io::write_atomic(path, &bytes)
}

/// Writes the sums of every pixel of `film` as part `header.kind`
/// (samples A..B) to `path`, atomically.
pub fn write_samples_part(path: &Path, header: &PartHeader, film: &Film) -> Result<(), String> {
    let pb = film.pixel_bounds();
    let sums: Vec<PixelSums> = pb.iter().map(|p| film.pixel_sums(p)).collect();
    let mut channels = Vec::with_capacity(8);
    for (c, name) in SUM_CHANNELS.iter().enumerate() {
        let v = sums
            .iter()
            .map(|s| if c < 3 { s.contrib[c] } else { s.weight });
        f64_channels(name, v, &mut channels);
    }
    let splats = film.splat_sums();
    if !splats.is_empty() {
        for (c, name) in SPLAT_CHANNELS.iter().enumerate() {
            f64_channels(name, splats.iter().map(|s| s[c]), &mut channels);
        }
    }
    let bytes =
        encode_part(header, pb, pb, channels).map_err(|e| format!("{}: {e}", path.display()))?;
    crate::image::io::write_atomic(path, &bytes)
}

/// A part's declared data windows, bounded before any pixel is read: at
/// most a film's largest resolution (32768 × 32768) and within the memory
/// budget for its channels (held as f32 or u32 while reading, and then as
/// the part's sums).
fn check_part_size(path: &Path) -> Result<(), String> {
    let meta = exr::meta::MetaData::read_from_file(path, false)
        .map_err(|e| format!("cannot read the part (missing, truncated or corrupt EXR): {e}"))?;
    for h in meta.headers.iter() {
        let (w, hh) = (h.layer_size.width() as u64, h.layer_size.height() as u64);
        let n = w * hh;
        if w > 32768 || hh > 32768 {
            return Err(format!(
                "the part's data window is {w}×{hh} pixels, larger than a film can be (32768×32768)"
            ));
        }
        let channels = h.channels.list.len() as u64;
        crate::scene::memory::check_budget(
            &format!("the part ({w}×{hh} pixels of {channels} channels)"),
            n * (4 * channels + std::mem::size_of::<PixelSums>() as u64),
        )?;
    }
    Ok(())
}

/// Reads a part file; an error names the file and says what is wrong
/// (unreadable, truncated or corrupt, not a pbrs part, missing channels).
pub fn read_part(path: &Path) -> Result<Part, String> {
    use exr::prelude::*;
    let fail = |e: String| format!("{}: {e}", path.display());
    check_part_size(path).map_err(fail)?;
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .non_parallel()
        .from_file(path)
        .map_err(|e| {
            fail(format!(
                "cannot read the part (missing, truncated or corrupt EXR): {e}"
            ))
        })?;
    let layer = &image.layer_data;
    let text = match layer.attributes.other.get(&Text::new_or_panic(ATTRIBUTE)) {
        Some(AttributeValue::Text(t)) => t.to_string(),
        _ => {
            return Err(fail(format!(
                "not a pbrs farm part (no {ATTRIBUTE} attribute)"
            )))
        }
    };
    let header = PartHeader::parse(&text).map_err(fail)?;
    let pos = layer.attributes.layer_position;
    let window = Bounds2i::new(
        IVec2::new(pos.0, pos.1),
        IVec2::new(pos.0 + layer.size.0 as i32, pos.1 + layer.size.1 as i32),
    );
    let n = layer.size.0 * layer.size.1;
    let channel = |name: &str| {
        layer
            .channel_data
            .list
            .iter()
            .find(|c| c.name.to_string() == name)
            .map(|c| &c.sample_data)
            .filter(|s| s.len() == n)
            .ok_or_else(|| fail(format!("the part has no channel {name} of {n} samples")))
    };
    // The f64 sums `name` from its bit patterns (the channels
    // `f64_channels` writes).
    let f64_channel = |name: &str| -> std::result::Result<Vec<f64>, String> {
        let (FlatSamples::U32(hi), FlatSamples::U32(lo)) = (
            channel(&format!("{name}.hi"))?,
            channel(&format!("{name}.lo"))?,
        ) else {
            return Err(fail(format!("channels {name}.hi/.lo are not UINT")));
        };
        Ok(hi
            .iter()
            .zip(lo)
            .map(|(&h, &l)| f64::from_bits(((h as u64) << 32) | l as u64))
            .collect())
    };
    let data = match header.kind {
        PartKind::Tile { .. } => {
            let mut rgb = vec![0.0f32; 3 * n];
            for (c, name) in ["R", "G", "B"].iter().enumerate() {
                let FlatSamples::F32(v) = channel(name)? else {
                    return Err(fail(format!("channel {name} is not float32")));
                };
                for (i, &x) in v.iter().enumerate() {
                    rgb[3 * i + c] = x;
                }
            }
            PartData::Rgb(rgb)
        }
        PartKind::Samples { .. } => {
            let mut sums = vec![PixelSums::default(); n];
            for (c, name) in SUM_CHANNELS.iter().enumerate() {
                for (s, v) in sums.iter_mut().zip(f64_channel(name)?) {
                    if c < 3 {
                        s.contrib[c] = v;
                    } else {
                        s.weight = v;
                    }
                }
            }
            PartData::Sums(sums)
        }
    };
    let has_splats = layer
        .channel_data
        .list
        .iter()
        .any(|c| c.name.to_string() == format!("{}.hi", SPLAT_CHANNELS[0]));
    let splats = if has_splats && matches!(header.kind, PartKind::Samples { .. }) {
        let mut v = vec![[0.0f64; 3]; n];
        for (c, name) in SPLAT_CHANNELS.iter().enumerate() {
            for (s, x) in v.iter_mut().zip(f64_channel(name)?) {
                s[c] = x;
            }
        }
        Some(v)
    } else {
        None
    };
    Ok(Part {
        path: path.to_path_buf(),
        header,
        window,
        data,
        splats,
    })
}

fn parse_bounds(s: Option<&str>) -> Option<Bounds2i> {
    let v: Vec<i32> = s?
        .split_whitespace()
        .map(|w| w.parse().ok())
        .collect::<Option<_>>()?;
    match v.as_slice() {
        &[x0, x1, y0, y1] => Some(Bounds2i::new(IVec2::new(x0, y0), IVec2::new(x1, y1))),
        _ => None,
    }
}

/// Merges a complete set of parts of one frame into its image.
///
/// Tiles are assembled: the image is the single-machine render's, bit for
/// bit. Sample ranges are added in the order of their first index: per pixel
/// and channel the f64 sum then adds the same n terms (one per sample that
/// reaches the pixel) as the full render, in another order, so the two sums
/// differ by at most 2·γ(n−1)·Σ|term| (γ(k) = k·u/(1 − k·u), u = 2⁻⁵³; the
/// standard bound for recursive summation, once per order), a relative
/// error of about 2n·2⁻⁵³ where the terms share a sign (non-negative
/// filters); the f32 pixel (the ratio of two such sums) is then the same
/// value or its neighbour (1 ulp), unless negative filter lobes cancel.
///
/// Refused, with an error naming the files: an empty set, parts of
/// different kinds, scenes or settings, a duplicate or overlapping part, a
/// missing part (gap), a part whose data window is not its own.
pub fn merge(parts: &[Part]) -> Result<Image, String> {
    let first = parts.first().ok_or("no parts to merge")?;
    check_same_render(first, &parts[1..])?;
    let display = parse_bounds(first.header.setting("pixelbounds"))
        .filter(|b| b.width() > 0 && b.height() > 0)
        .ok_or_else(|| format!("{}: malformed pixelbounds", name(first)))?;
    let (w, h) = (display.width() as u32, display.height() as u32);
    if w as u64 * h as u64 > crate::scene::MAX_IMAGE_PIXELS {
        return Err(format!("{}: the image is too large", name(first)));
    }
    let mut img = Image::new(w, h);
    match first.header.kind {
        PartKind::Tile { count, .. } => merge_tiles(parts, first, display, count, &mut img)?,
        PartKind::Samples { .. } => merge_samples(parts, first, display, &mut img)?,
    }
    Ok(img)
}

/// A part's file, in messages.
fn name(p: &Part) -> String {
    p.path.display().to_string()
}

/// Refuses `rest` unless each is of `first`'s kind (tiles or sample
/// ranges) with the same recorded settings.
fn check_same_render(first: &Part, rest: &[Part]) -> Result<(), String> {
    for p in rest {
        if std::mem::discriminant(&p.header.kind) != std::mem::discriminant(&first.header.kind) {
            return Err(format!(
                "{} is {} but {} is {}: tiles and sample ranges cannot be merged together",
                name(p),
                p.header.kind,
                name(first),
                first.header.kind
            ));
        }
        for (k, v) in &first.header.settings {
            let other = p.header.setting(k);
            if other != Some(v.as_str()) {
                return Err(format!(
                    "{} and {} are parts of different renders: {k} is {:?} in one and {:?} in the other",
                    name(first),
                    name(p),
                    v,
                    other.unwrap_or("missing")
                ));
            }
        }
        if p.header.settings.len() != first.header.settings.len() {
            return Err(format!(
                "{} and {} record different settings",
                name(first),
                name(p)
            ));
        }
    }
    Ok(())
}

/// Assembles the `count` tiles of `display` into `img`, refusing a
/// different split, a duplicate, a gap or a wrong data window.
fn merge_tiles(
    parts: &[Part],
    first: &Part,
    display: Bounds2i,
    count: u32,
    img: &mut Image,
) -> Result<(), String> {
    let w = display.width() as u32;
    let mut seen: Vec<Option<&Part>> = vec![None; count as usize];
    for p in parts {
        let PartKind::Tile { index, count: n } = p.header.kind else {
            unreachable!("kinds checked above")
        };
        if n != count {
            return Err(format!(
                "{} is {} but {} is {}: the frame was split differently",
                name(p),
                p.header.kind,
                name(first),
                first.header.kind
            ));
        }
        if index >= count {
            return Err(format!("{}: {} does not exist", name(p), p.header.kind));
        }
        if let Some(q) = seen[index as usize] {
            return Err(format!(
                "overlap: {} and {} are both {}",
                name(q),
                name(p),
                p.header.kind
            ));
        }
        let want = tile_rect(display, index, count);
        if p.window != want {
            return Err(format!(
                "{}: its data window (rows {}..{}, columns {}..{}) is not {}'s (rows {}..{}, columns {}..{})",
                name(p), p.window.min.y, p.window.max.y, p.window.min.x, p.window.max.x,
                p.header.kind, want.min.y, want.max.y, want.min.x, want.max.x
            ));
        }
        seen[index as usize] = Some(p);
    }
    let missing: Vec<String> = seen
        .iter()
        .enumerate()
        .filter(|(_, s)| s.is_none())
        .map(|(k, _)| {
            let r = tile_rect(display, k as u32, count);
            format!("tile {k} (rows {}..{})", r.min.y, r.max.y)
        })
        .collect();
    if !missing.is_empty() {
        return Err(format!(
            "gap: of {count} tiles, {} missing: {}",
            if missing.len() == 1 {
                "this is"
            } else {
                "these are"
            },
            missing.join(", ")
        ));
    }
    for p in parts {
        let PartData::Rgb(rgb) = &p.data else {
            unreachable!("tile parts hold RGB")
        };
        let row = 3 * w as usize;
        let y0 = (p.window.min.y - display.min.y) as usize;
        let n = rgb.len();
        img.data[y0 * row..y0 * row + n].copy_from_slice(rgb);
    }
    Ok(())
}

/// Adds the sample ranges' sums in the order of their first sample and
/// writes the pixels into `img`, refusing an overlap, a gap or a wrong data
/// window.
fn merge_samples(
    parts: &[Part],
    first: &Part,
    display: Bounds2i,
    img: &mut Image,
) -> Result<(), String> {
    let (w, h) = (display.width() as u32, display.height() as u32);
    let spp: u32 = first
        .header
        .setting("spp")
        .and_then(|s| s.parse().ok())
        .ok_or_else(|| format!("{}: malformed spp", name(first)))?;
    let scale = first
        .header
        .setting("scale")
        .and_then(|s| u32::from_str_radix(s, 16).ok())
        .map(f32::from_bits)
        .ok_or_else(|| format!("{}: malformed scale", name(first)))?;
    let mut order: Vec<(u32, u32, &Part)> = parts
        .iter()
        .map(|p| match p.header.kind {
            PartKind::Samples { start, end } => (start, end, p),
            PartKind::Tile { .. } => unreachable!("kinds checked above"),
        })
        .collect();
    order.sort_by_key(|&(a, b, _)| (a, b));
    let mut next = 0u32;
    let mut prev: Option<&Part> = None;
    for &(a, b, p) in &order {
        if a >= b || b > spp {
            return Err(format!(
                "{}: {} is not a range of the {spp} samples per pixel",
                name(p),
                p.header.kind
            ));
        }
        if a < next {
            return Err(format!(
                "overlap: {} ({}) and {} ({}) share samples",
                name(prev.unwrap_or(p)),
                prev.map_or(String::new(), |q| q.header.kind.to_string()),
                name(p),
                p.header.kind
            ));
        }
        if a > next {
            return Err(format!(
                "gap: samples [{next}, {a}) of the {spp} per pixel are in no part"
            ));
        }
        if p.window != display {
            return Err(format!(
                "{}: its data window is not the film's pixel bounds",
                name(p)
            ));
        }
        next = b;
        prev = Some(p);
    }
    if next != spp {
        return Err(format!(
            "gap: samples [{next}, {spp}) of the {spp} per pixel are in no part"
        ));
    }
    let mut sums = vec![PixelSums::default(); (w * h) as usize];
    for &(_, _, p) in &order {
        let PartData::Sums(s) = &p.data else {
            unreachable!("sample parts hold sums")
        };
        for (d, s) in sums.iter_mut().zip(s) {
            for c in 0..3 {
                d.contrib[c] += s.contrib[c];
            }
            d.weight += s.weight;
        }
    }
    // Splats (bdpt's light tracing) are added in the same order and
    // divided by the spp, as the film does.
    let mut splats: Vec<[f64; 3]> = Vec::new();
    for &(_, _, p) in &order {
        if let Some(sp) = &p.splats {
            if splats.is_empty() {
                splats = vec![[0.0; 3]; sums.len()];
            }
            for (d, s) in splats.iter_mut().zip(sp) {
                for c in 0..3 {
                    d[c] += s[c];
                }
            }
        }
    }
    let scale = scale as f64;
    if splats.is_empty() {
        for (i, s) in sums.iter().enumerate() {
            img.data[3 * i..3 * i + 3].copy_from_slice(&pixel_rgb(s, scale));
        }
    } else {
        let ss = 1.0 / spp as f64;
        for (i, (s, sp)) in sums.iter().zip(&splats).enumerate() {
            img.data[3 * i..3 * i + 3].copy_from_slice(&pixel_rgb_splat(s, sp, ss, scale));
        }
    }
    Ok(())
}
