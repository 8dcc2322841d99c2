//! The film: film tiles, the final image, image
//! files and image comparison metrics.
//!
//! Follows pbrt-v3's `Film`/`FilmTile` (core/film.{h,cpp}): a 16×16 table of
//! the filter over the positive quadrant, the same sample footprint and table
//! lookups, sums in `f64`. Tiles are filled independently and merged by the
//! caller in a fixed order with plain additions, so an image does not depend
//! on the number of threads.

pub mod part;

pub use crate::filters::Filter;

use crate::geometry::Bounds2i;
use crate::image::Image;
use crate::integrators::Splat;
use crate::scene::FilmDesc;
use glam::{DVec3, IVec2, Vec2, Vec3};

/// Width of the precomputed filter table (pbrt-v3's `filterTableWidth`).
pub const FILTER_TABLE_WIDTH: usize = 16;
const TABLE_SIZE: usize = FILTER_TABLE_WIDTH * FILTER_TABLE_WIDTH;

/// How many splats ahead `add_splats` asks for a splat's pixel.
const SPLAT_AHEAD: usize = 8;

pub use crate::geometry::luminance;

/// Running sums of one pixel.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelSums {
    /// Σ filter weight · sample weight · L, per channel.
    pub contrib: [f64; 3],
    /// Σ filter weight.
    pub weight: f64,
}

impl PixelSums {
    /// Adds radiance `lw` (L times the sample weight) with filter weight
    /// `fw`.
    #[inline(always)]
    fn add(&mut self, lw: DVec3, fw: f64) {
        self.contrib[0] += lw.x * fw;
        self.contrib[1] += lw.y * fw;
        self.contrib[2] += lw.z * fw;
        self.weight += fw;
    }
}

#[derive(Clone, Debug)]
pub struct Film {
    full_resolution: IVec2,
    pixel_bounds: Bounds2i,
    filter: Filter,
    filter_table: [f32; TABLE_SIZE],
    /// The filter table's one value when all its entries are equal (the
    /// box filter, pbrt-v3's default): every splat weight is then that
    /// value, with no table offsets to compute.
    uniform_weight: Option<f32>,
    scale: f32,
    max_sample_luminance: f32,
    pixels: Vec<PixelSums>,
    /// Σ splatted radiance per pixel (pbrt-v3's `splatXYZ`, in RGB and
    /// f64); empty until a splat arrives, so images without splats are
    /// what they were.
    splats: Vec<[f64; 3]>,
    /// The extra splat images (layer k > 0 of [`Splat`] is `layers[k − 1]`),
    /// each empty until a splat arrives.
    layers: Vec<Vec<[f64; 3]>>,
    /// Samples per pixel rendered so far: splats are scaled by its inverse
    /// (pbrt-v3's `splatScale` 1/spp).
    splat_spp: u64,
    /// The splats' scale when an integrator sets it (`mlt`: b over the
    /// mutations per pixel) instead of 1/spp.
    splat_scale_set: Option<f64>,
}

impl Film {
    pub fn new(film: &FilmDesc, filter: &Filter) -> Film {
        let res = IVec2::new(film.xresolution as i32, film.yresolution as i32);
        let [cx0, cx1, cy0, cy1] = film.cropwindow;
        // pbrt-v3 computes these in Float.
        let pixel_bounds = Bounds2i::new(
            IVec2::new(
                (res.x as f32 * cx0).ceil() as i32,
                (res.y as f32 * cy0).ceil() as i32,
            ),
            IVec2::new(
                (res.x as f32 * cx1).ceil() as i32,
                (res.y as f32 * cy1).ceil() as i32,
            ),
        );
        let filter = *filter;
        let r = filter.radius();
        let mut filter_table = [0.0f32; TABLE_SIZE];
        for y in 0..FILTER_TABLE_WIDTH {
            for x in 0..FILTER_TABLE_WIDTH {
                let p = Vec2::new(
                    (x as f32 + 0.5) * r.x / FILTER_TABLE_WIDTH as f32,
                    (y as f32 + 0.5) * r.y / FILTER_TABLE_WIDTH as f32,
                );
                filter_table[y * FILTER_TABLE_WIDTH + x] = filter.evaluate(p);
            }
        }
        let max_sample_luminance = if film.max_sample_luminance > 0.0 {
            film.max_sample_luminance
        } else {
            f32::INFINITY
        };
        Film {
            full_resolution: res,
            pixel_bounds,
            filter,
            filter_table,
            uniform_weight: uniform_weight(&filter_table),
            scale: film.scale,
            max_sample_luminance,
            pixels: vec![PixelSums::default(); pixel_bounds.area().max(0) as usize],
            splats: Vec::new(),
            layers: Vec::new(),
            splat_spp: 0,
            splat_scale_set: None,
        }
    }

    pub fn full_resolution(&self) -> IVec2 {
        self.full_resolution
    }

    /// The (cropped) pixels written to the image.
    pub fn pixel_bounds(&self) -> Bounds2i {
        self.pixel_bounds
    }

    pub fn filter(&self) -> &Filter {
        &self.filter
    }

    /// The precomputed filter table (row-major, 16×16, positive quadrant).
    pub fn filter_table(&self) -> &[f32; TABLE_SIZE] {
        &self.filter_table
    }

    /// Pixels whose samples can reach the pixel bounds (pbrt-v3's `GetSampleBounds`).
    pub fn sample_bounds(&self) -> Bounds2i {
        let r = self.filter.radius();
        let min = (self.pixel_bounds.min.as_vec2() + Vec2::splat(0.5) - r).floor();
        let max = (self.pixel_bounds.max.as_vec2() - Vec2::splat(0.5) + r).ceil();
        Bounds2i::new(min.as_ivec2(), max.as_ivec2())
    }

    /// Tiles of `tile_size × tile_size` pixels covering the sample bounds, in
    /// row-major order (the order to render and merge them in).
    pub fn tiles(&self, tile_size: i32) -> Vec<Bounds2i> {
        let ts = tile_size.max(1);
        let sb = self.sample_bounds();
        let (nx, ny) = ((sb.width() + ts - 1) / ts, (sb.height() + ts - 1) / ts);
        let mut out = Vec::with_capacity((nx * ny).max(0) as usize);
        for ty in 0..ny {
            for tx in 0..nx {
                let min = sb.min + IVec2::new(tx * ts, ty * ts);
                let max = (min + IVec2::splat(ts)).min(sb.max);
                out.push(Bounds2i::new(min, max));
            }
        }
        out
    }

    /// A tile for samples taken in `tile_sample_bounds` (pbrt-v3's `GetFilmTile`).
    pub fn tile(&self, tile_sample_bounds: Bounds2i) -> FilmTile {
        self.tile_maker().tile(tile_sample_bounds)
    }

    /// What making a tile needs of the film, without its pixels (so that
    /// tiles can be made while the film is being merged into).
    pub fn tile_maker(&self) -> TileMaker {
        TileMaker {
            radius: self.filter.radius(),
            pixel_bounds: self.pixel_bounds,
            filter_table: self.filter_table,
            uniform_weight: self.uniform_weight,
            max_sample_luminance: self.max_sample_luminance,
        }
    }

    /// Adds a tile's sums into the film (plain additions: merge tiles in a
    /// fixed order for bit-identical images).
    pub fn merge_tile(&mut self, tile: FilmTile) {
        self.add_splats(&tile.splats);
        let fw = self.pixel_bounds.width() as usize;
        let tw = tile.pixel_bounds.width() as usize;
        if tw == 0 {
            return;
        }
        for (ty, row) in tile.pixels.chunks_exact(tw).enumerate() {
            let y = tile.pixel_bounds.min.y + ty as i32;
            let fy = (y - self.pixel_bounds.min.y) as usize;
            let fx0 = (tile.pixel_bounds.min.x - self.pixel_bounds.min.x) as usize;
            let dst = &mut self.pixels[fy * fw + fx0..fy * fw + fx0 + tw];
            for (d, s) in dst.iter_mut().zip(row) {
                for c in 0..3 {
                    d.contrib[c] += s.contrib[c];
                }
                d.weight += s.weight;
            }
        }
    }

    /// `add_splat` of each splat in order. Each lands anywhere in the
    /// image: the pixel of the one `SPLAT_AHEAD` later is asked for (a
    /// hint) while this one is added, so that their cache misses overlap
    /// (the order of the additions, and so the sums, stay the same).
    pub fn add_splats(&mut self, splats: &[Splat]) {
        for (i, sp) in splats.iter().enumerate() {
            if let Some(next) = splats.get(i + SPLAT_AHEAD) {
                self.prefetch_splat(next);
            }
            self.add_splat(sp);
        }
    }

    /// Asks for the cache line `add_splat(sp)` will add to (a hint; only
    /// for the main splat image once it exists).
    #[inline]
    fn prefetch_splat(&self, sp: &Splat) {
        if sp.layer != 0 || self.splats.is_empty() {
            return;
        }
        if let Some(k) = self.splat_pixel(sp.p_film) {
            crate::accel::prefetch(self.splats.as_ptr().wrapping_add(k));
        }
    }

    /// The index (in the splat images) of the pixel `p_film` is in, if it
    /// is inside the film's pixel bounds.
    #[inline]
    fn splat_pixel(&self, p_film: Vec2) -> Option<usize> {
        let pi = p_film.floor().as_ivec2();
        let b = self.pixel_bounds;
        let inside = pi.x >= b.min.x && pi.x < b.max.x && pi.y >= b.min.y && pi.y < b.max.y;
        let o = pi - b.min;
        inside.then(|| (o.y * b.width() + o.x) as usize)
    }

    /// Adds a splat to the pixel its position is in (pbrt-v3's
    /// `Film::AddSplat`: NaN, negative and infinite values are dropped,
    /// bright ones scaled down to `maxsampleluminance`), in f64.
    pub fn add_splat(&mut self, sp: &Splat) {
        let mut v = sp.l;
        let y = luminance(v);
        if v.is_nan() || y < 0.0 || y.is_infinite() {
            return;
        }
        let Some(k) = self.splat_pixel(sp.p_film) else {
            return;
        };
        if y > self.max_sample_luminance {
            v *= self.max_sample_luminance / y;
        }
        let n = self.pixels.len();
        let buf = if sp.layer == 0 {
            &mut self.splats
        } else {
            let layer = sp.layer as usize - 1;
            if self.layers.len() <= layer {
                self.layers.resize_with(layer + 1, Vec::new);
            }
            &mut self.layers[layer]
        };
        if buf.is_empty() {
            buf.resize(n, [0.0; 3]);
        }
        let d = &mut buf[k];
        d[0] += v.x as f64;
        d[1] += v.y as f64;
        d[2] += v.z as f64;
    }

    /// Counts `n` more samples per pixel for the splats' scale.
    pub fn add_splat_samples(&mut self, n: u64) {
        self.splat_spp += n;
    }

    /// Samples per pixel the splats are divided by.
    pub fn splat_samples(&self) -> u64 {
        self.splat_spp
    }

    /// Σ splatted radiance per pixel (row order over the pixel bounds);
    /// empty if nothing was splatted.
    pub fn splat_sums(&self) -> &[[f64; 3]] {
        &self.splats
    }

    /// Extra splat image `layer` (≥ 1) as pbrt-v3 writes bdpt's strategy
    /// images: the splats over the spp, scale 1.
    pub fn layer_image(&self, layer: u32) -> Image {
        let w = self.pixel_bounds.width().max(0) as u32;
        let h = self.pixel_bounds.height().max(0) as u32;
        let mut img = Image::new(w, h);
        let inv = 1.0 / self.splat_spp.max(1) as f64;
        if let Some(buf) = self.layers.get(layer.saturating_sub(1) as usize) {
            for (d, s) in img.data.chunks_exact_mut(3).zip(buf) {
                for c in 0..3 {
                    d[c] = (s[c] * inv) as f32;
                }
            }
        }
        img
    }

    /// Sums of a pixel inside the pixel bounds.
    pub fn pixel_sums(&self, p: IVec2) -> PixelSums {
        debug_assert!(self.pixel_bounds.contains(p));
        let w = self.pixel_bounds.width();
        let o = p - self.pixel_bounds.min;
        self.pixels[(o.y * w + o.x) as usize]
    }

    /// Sets every pixel to `rgb` (row order over the pixel bounds), with
    /// filter weight 1: the image is then `max(0, rgb) × scale` (pbrt-v3's
    /// `Film::SetImage`, for integrators that compute pixels directly).
    pub fn set_pixels(&mut self, rgb: &[Vec3]) {
        for (p, v) in self.pixels.iter_mut().zip(rgb) {
            p.contrib = v.as_dvec3().to_array();
            p.weight = 1.0;
        }
    }

    /// Resets all sums to zero.
    pub fn clear(&mut self) {
        self.pixels.fill(PixelSums::default());
        self.splats.clear();
        self.layers.clear();
        self.splat_spp = 0;
        self.splat_scale_set = None;
    }

    /// Sets the scale of the splats (pbrt-v3's `WriteImage(splatScale)`),
    /// in place of 1/spp.
    pub fn set_splat_scale(&mut self, scale: f64) {
        self.splat_scale_set = Some(scale);
    }

    /// The splat scale: 1/spp (pbrt-v3's `splatScale`).
    fn splat_scale(&self) -> f64 {
        self.splat_scale_set
            .unwrap_or(1.0 / self.splat_spp.max(1) as f64)
    }

    /// The image over the pixel bounds: `max(0, Σ wL / Σ w) × scale` per
    /// channel, 0 where `Σ w == 0`.
    pub fn image(&self) -> Image {
        let w = self.pixel_bounds.width() as u32;
        let h = self.pixel_bounds.height() as u32;
        let mut data = Vec::with_capacity(self.pixels.len() * 3);
        let scale = self.scale as f64;
        if self.splats.is_empty() {
            for p in &self.pixels {
                data.extend(pixel_rgb(p, scale));
            }
        } else {
            let ss = self.splat_scale();
            for (p, sp) in self.pixels.iter().zip(&self.splats) {
                data.extend(pixel_rgb_splat(p, sp, ss, scale));
            }
        }
        Image {
            width: w,
            height: h,
            data,
        }
    }
}

impl Film {
    /// Pixels of `region` (in film pixel coordinates, clipped to the pixel
    /// bounds) as [`Film::image`] computes them: the clipped region and its
    /// RGB triples, rows top to bottom.
    pub fn region_rgb(&self, region: Bounds2i) -> (Bounds2i, Vec<f32>) {
        let r = region.intersect(&self.pixel_bounds);
        let (w, h) = (r.width().max(0), r.height().max(0));
        let mut data = Vec::with_capacity((w * h) as usize * 3);
        let scale = self.scale as f64;
        let fw = self.pixel_bounds.width();
        for y in r.min.y..r.min.y + h {
            let row = ((y - self.pixel_bounds.min.y) * fw - self.pixel_bounds.min.x) as isize;
            for x in r.min.x..r.min.x + w {
                let i = (row + x as isize) as usize;
                let p = &self.pixels[i];
                match self.splats.get(i) {
                    Some(sp) => data.extend(pixel_rgb_splat(p, sp, self.splat_scale(), scale)),
                    None => data.extend(pixel_rgb(p, scale)),
                }
            }
        }
        (r, data)
    }
}

/// One pixel's value: `max(0, Σ wL / Σ w) × scale`, 0 where `Σ w == 0`.
#[inline]
pub(crate) fn pixel_rgb(p: &PixelSums, scale: f64) -> [f32; 3] {
    if p.weight != 0.0 {
        let inv = 1.0 / p.weight;
        p.contrib.map(|c| ((c * inv).max(0.0) * scale) as f32)
    } else {
        [0.0; 3]
    }
}

/// One pixel's value with its splats (pbrt-v3's `WriteImage`):
/// `(max(0, Σ wL / Σ w) + splat · splat_scale) × scale`.
#[inline]
pub(crate) fn pixel_rgb_splat(
    p: &PixelSums,
    splat: &[f64; 3],
    splat_scale: f64,
    scale: f64,
) -> [f32; 3] {
    let inv = if p.weight != 0.0 { 1.0 / p.weight } else { 0.0 };
    let mut out = [0.0f32; 3];
    for c in 0..3 {
        let filtered = if p.weight != 0.0 {
            (p.contrib[c] * inv).max(0.0)
        } else {
            0.0
        };
        out[c] = ((filtered + splat[c] * splat_scale) * scale) as f32;
    }
    out
}

/// Makes film tiles: [`Film::tile`] without a borrow of the film.
#[derive(Clone, Debug)]
pub struct TileMaker {
    radius: Vec2,
    pixel_bounds: Bounds2i,
    filter_table: [f32; TABLE_SIZE],
    uniform_weight: Option<f32>,
    max_sample_luminance: f32,
}

impl TileMaker {
    /// The tile of sample bounds `tile_sample_bounds`: the film pixels its
    /// samples' filter footprints reach.
    pub fn tile(&self, tile_sample_bounds: Bounds2i) -> FilmTile {
        let r = self.radius;
        let half = Vec2::splat(0.5);
        let p0 = (tile_sample_bounds.min.as_vec2() - half - r)
            .ceil()
            .as_ivec2();
        let p1 = (tile_sample_bounds.max.as_vec2() - half + r)
            .floor()
            .as_ivec2()
            + IVec2::ONE;
        let pixel_bounds = Bounds2i::new(p0, p1).intersect(&self.pixel_bounds);
        FilmTile {
            pixel_bounds,
            radius: r,
            inv_radius: Vec2::ONE / r,
            filter_table: self.filter_table,
            uniform_weight: self.uniform_weight,
            max_sample_luminance: self.max_sample_luminance,
            pixels: vec![PixelSums::default(); pixel_bounds.area().max(0) as usize],
            splats: Vec::new(),
        }
    }
}

/// The part of the film that the samples of one tile can touch.
#[derive(Clone, Debug)]
pub struct FilmTile {
    pixel_bounds: Bounds2i,
    radius: Vec2,
    inv_radius: Vec2,
    filter_table: [f32; TABLE_SIZE],
    /// [`Film`]'s `uniform_weight`.
    uniform_weight: Option<f32>,
    max_sample_luminance: f32,
    pixels: Vec<PixelSums>,
    /// The tile's splats in sample order (they land anywhere on the film).
    splats: Vec<Splat>,
}

/// The value of a filter table whose entries are all equal (bit for bit).
fn uniform_weight(table: &[f32; TABLE_SIZE]) -> Option<f32> {
    let w = table[0];
    table
        .iter()
        .all(|v| v.to_bits() == w.to_bits())
        .then_some(w)
}

/// Footprints up to this many pixels per axis use a stack cache of table
/// offsets; larger ones compute offsets inline.
const MAX_CACHED_FOOTPRINT: usize = 32;

impl FilmTile {
    pub fn pixel_bounds(&self) -> Bounds2i {
        self.pixel_bounds
    }

    /// Gives the tile its samples' splats (in sample order), which
    /// [`Film::merge_tile`] adds to the film.
    pub fn set_splats(&mut self, splats: Vec<Splat>) {
        self.splats = splats;
    }

    /// Splats radiance `l` seen through raster position `p_film` onto the
    /// pixels within the filter radius. Non-finite radiance counts as black
    /// (the sample still adds its filter weight), as pbrt-v3's integrator does.
    #[inline(always)]
    pub fn add_sample(&mut self, p_film: Vec2, l: Vec3, sample_weight: f32) {
        let mut l = if l.is_finite() { l } else { Vec3::ZERO };
        let y = luminance(l);
        if y > self.max_sample_luminance {
            l *= self.max_sample_luminance / y;
        }
        let p_discrete = p_film - Vec2::splat(0.5);
        let p0 = ceil_i(p_discrete - self.radius).max(self.pixel_bounds.min);
        let p1 = (floor_i(p_discrete + self.radius) + IVec2::ONE).min(self.pixel_bounds.max);
        if p0.x >= p1.x || p0.y >= p1.y {
            return;
        }
        let n_x = (p1.x - p0.x) as usize;
        let n_y = (p1.y - p0.y) as usize;
        let lw = (l * sample_weight).as_dvec3();
        let width = self.pixel_bounds.width() as usize;
        if let Some(fw) = self.uniform_weight {
            // The weights the table would give, without its offsets.
            let fw = fw as f64;
            for j in 0..n_y {
                let row = (p0.y - self.pixel_bounds.min.y) as usize + j;
                let base = row * width + (p0.x - self.pixel_bounds.min.x) as usize;
                for px in &mut self.pixels[base..base + n_x] {
                    px.add(lw, fw);
                }
            }
            return;
        }
        let scale = FILTER_TABLE_WIDTH as f32;
        let offset = |d: f32, inv_r: f32| -> usize {
            (((d * inv_r * scale).abs()) as usize).min(FILTER_TABLE_WIDTH - 1)
        };
        if n_x <= MAX_CACHED_FOOTPRINT && n_y <= MAX_CACHED_FOOTPRINT {
            let mut ifx = [0usize; MAX_CACHED_FOOTPRINT];
            let mut ify = [0usize; MAX_CACHED_FOOTPRINT];
            for (i, v) in ifx[..n_x].iter_mut().enumerate() {
                *v = offset((p0.x + i as i32) as f32 - p_discrete.x, self.inv_radius.x);
            }
            for (i, v) in ify[..n_y].iter_mut().enumerate() {
                *v = offset((p0.y + i as i32) as f32 - p_discrete.y, self.inv_radius.y)
                    * FILTER_TABLE_WIDTH;
            }
            for (j, &oy) in ify[..n_y].iter().enumerate() {
                let row = (p0.y - self.pixel_bounds.min.y) as usize + j;
                let base = row * width + (p0.x - self.pixel_bounds.min.x) as usize;
                let pixels = &mut self.pixels[base..base + n_x];
                for (px, &ox) in pixels.iter_mut().zip(&ifx[..n_x]) {
                    px.add(lw, self.filter_table[oy + ox] as f64);
                }
            }
        } else {
            for y in p0.y..p1.y {
                let oy = offset(y as f32 - p_discrete.y, self.inv_radius.y) * FILTER_TABLE_WIDTH;
                for x in p0.x..p1.x {
                    let ox = offset(x as f32 - p_discrete.x, self.inv_radius.x);
                    let i = (y - self.pixel_bounds.min.y) as usize * width
                        + (x - self.pixel_bounds.min.x) as usize;
                    self.pixels[i].add(lw, self.filter_table[oy + ox] as f64);
                }
            }
        }
    }

    /// Sums of a pixel inside the tile's pixel bounds.
    pub fn pixel_sums(&self, p: IVec2) -> PixelSums {
        let w = self.pixel_bounds.width();
        let o = p - self.pixel_bounds.min;
        self.pixels[(o.y * w + o.x) as usize]
    }
}

/// `v.floor()` as integers, without a libm call (the x86-64 baseline has no
/// rounding instruction): truncate, then step down where that rounded up.
/// Film coordinates are far inside the i32 range; NaN gives 0.
#[inline(always)]
fn floor_i(v: Vec2) -> IVec2 {
    let t = v.as_ivec2();
    let up = v.cmplt(t.as_vec2());
    t - IVec2::new(up.test(0) as i32, up.test(1) as i32)
}

/// `v.ceil()` as integers (see `floor_i`).
#[inline(always)]
fn ceil_i(v: Vec2) -> IVec2 {
    -floor_i(-v)
}

#[cfg(test)]
mod rounding_tests {
    use super::*;

    #[test]
    fn floor_and_ceil_match_std() {
        for &x in &[
            -2.5f32, -2.0, -1.0e-7, -0.0, 0.0, 1.0e-7, 0.5, 1.0, 1.5, 511.99, 4096.0,
        ] {
            for &y in &[-3.25f32, 0.0, 2.75, 100.0] {
                let v = Vec2::new(x, y);
                assert_eq!(floor_i(v), v.floor().as_ivec2(), "{v}");
                assert_eq!(ceil_i(v), v.ceil().as_ivec2(), "{v}");
            }
        }
    }
}
