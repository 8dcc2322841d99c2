//! `infinite` (alias `exinfinite`): the infinite area light (pbrt-v3's
//! `InfiniteAreaLight`): radiance from every direction, from an
//! equal-area-in-(φ, θ) lat-long map times `L` (`L` × `scale`), or `L`
//! alone without a map.
//!
//! | parameter | type | pbrt-v3 default | |
//! |---|---|---|---|
//! | `L` | spectrum | 1 | radiance (times the map) |
//! | `scale` | spectrum | 1 | multiplies `L`; a spectrum only, as pbrt-v3 (a `float scale` is unused) |
//! | `mapname` | string (image file) | none: constant `L` | lat-long map, read raw |
//! | `nsamples` | integer | 1 | shadow samples for `directlighting` "all" |
//! | `samples` | integer | `nsamples` | the same; wins over `nsamples` |
//! | `sampling` | string: `"map"`, `"alias"` or `"uniform"` | `"map"` | how directions are sampled (**pbrs extension**) |
//!
//! As pbrt-v3 does it:
//! - The map is read raw (8-bit files are not sRGB-decoded) and multiplied
//!   by `L`. Light space: direction (x, y, z) has θ = acos z from +z and
//!   φ = atan2(y, x) in [0, 2π); map coordinates (s, t) = (φ/2π, θ/π), so
//!   the top row of the file is +z and s grows with φ.
//! - The map is held as pbrt-v3's `MIPMap` with its defaults (repeat wrap):
//!   a non-power-of-two image is first resampled up to powers of two with
//!   the Lanczos filter (negative values clamped), then box-filtered into
//!   levels. Radiance lookups (`le`, `sample_li`) are bilinear on level 0.
//! - Sampling: a 2D piecewise-constant distribution over (s, t) of twice
//!   the (power-of-two) resolution in each axis, built from `Lookup((s, t),
//!   0.5 / min(2w, 2h))` (a filtered lookup, usually bilinear on level 0)
//!   of the luminance times sin θ; the solid-angle density is
//!   `pdf(s, t) / (2π² sin θ)`, 0 at the poles.
//! - Power: `π r² · Lookup((0.5, 0.5), 0.5)`, r the scene's bounding radius
//!   (set when the scene is built, [`LightModel::preprocess`]).
//! - A one-pixel map is the same as no map: both are a 1 × 1 MIP map. Its
//!   lookups are its value and its distribution is uniform in (s, t), so
//!   pbrs evaluates them as such (equal to pbrt-v3's bilinear lookups and
//!   2 × 2 distribution up to rounding).
//!
//! `sampling "uniform"` samples the sphere uniformly instead (density
//! 1/4π), for comparisons with the importance-sampled map (`pbrs converge`).
//! `sampling "alias"` samples pbrt-v3's density with alias tables: one
//! table entry per dimension instead of two binary searches of CDFs that,
//! for a large map, do not fit in cache; the same density (so the same
//! expected image and MIS weights), other directions for the same sample
//! values. Another value: warning, `"map"`. Directions leave the light's transform
//! normalised (pbrt-v3 leaves them as transformed, which differs only for a
//! transform that scales).

use super::{disk_ray, EmittedRay, LightKind, LightModel, LightSample};
use crate::accel::Aggregate;
use crate::geometry::spawn_ray;
use crate::geometry::{luminance, Ray};
use crate::sampling::alias::Alias2D;
use crate::sampling::{uniform_sample_sphere, uniform_sphere_pdf, Distribution2D};
use crate::scene::RgbImage;
use crate::scene::{Decode, ParamSpec, ParamValues, Report, Support};
use crate::shapes::SurfacePoint;
use glam::{DMat4, Mat3, Vec2, Vec3};
use rayon::prelude::*;
use std::f32::consts::PI;
use std::sync::Arc;

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::spectrum_any("L", [1.0; 3], "radiance, times the map's values"),
    ParamSpec::spectrum_any(
        "scale",
        [1.0; 3],
        "multiplies L (a spectrum only, as pbrt-v3: a float scale is unused)",
    ),
    ParamSpec::image(
        "mapname",
        Decode::Raw,
        "lat-long environment map (values read raw, top row +z); none: constant L",
    ),
    ParamSpec::int(
        "nsamples",
        1,
        "shadow samples for directlighting's \"all\" strategy (at least 1)",
    ),
    ParamSpec::int_opt("samples", "the same as nsamples, which it overrides"),
    ParamSpec::string(
        "sampling",
        "map",
        "pbrs extension: \"map\" (importance by the map, pbrt-v3's), \"alias\" (the same density in constant time by alias tables) or \"uniform\" (the sphere uniformly)",
    ),
];

pub const KIND: LightKind = LightKind {
    name: "infinite",
    aliases: &["exinfinite"],
    support: Support::Supported,
    params: PARAMS,
    doc: "radiance L·scale from every direction, times a lat-long environment map when mapname is given",
    build: |p, ctm, report| Some(InfiniteLight::new(p, ctm, report).into()),
};

/// The most shadow samples a light takes (the loader's sample limit).
const MAX_SAMPLES: i32 = 1 << 24;

/// How an infinite light samples directions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EnvSampling {
    /// pbrt-v3's: the map's luminance times sin θ.
    Map,
    /// Uniformly over the sphere: the pbrs extension `"string sampling"
    /// "uniform"`, to compare against importance sampling.
    Uniform,
    /// pbrt-v3's density, sampled in constant time by alias tables
    /// ([`Alias2D`]) instead of by searching the CDFs: the pbrs extension
    /// `"string sampling" "alias"`. Other directions for the same sample
    /// values, so other noise; the same expected image.
    Alias,
}

#[derive(Clone, Debug)]
pub struct InfiniteLight {
    pub n_samples: u32,
    /// The scene's bounding radius (0 until [`LightModel::preprocess`]).
    pub scene_radius: f32,
    pub map: Arc<EnvMap>,
}

impl InfiniteLight {
    /// `sample_li` at `r` from the map's sample (`EnvMap::sample`, which
    /// does not depend on `r`, drawn beforehand).
    #[inline]
    pub fn sample_li_from(
        &self,
        r: &SurfacePoint,
        drawn: Option<EnvSample>,
    ) -> Option<LightSample> {
        let (wi, li, pdf) = drawn?;
        // Anything in the way occludes an infinitely distant light.
        let shadow = spawn_ray(r.p, r.p_error, r.n, wi);
        Some(LightSample {
            li,
            wi,
            pdf,
            shadow,
        })
    }

    /// pbrt-v3's `CreateInfiniteLight`, with `ctm` as light-to-world.
    pub fn new(p: &ParamValues, ctm: DMat4, report: &mut dyn Report) -> InfiniteLight {
        let l = p.spectrum("L") * p.spectrum("scale");
        let n = p.int_opt("samples").unwrap_or(p.int("nsamples"));
        let sampling = match p.string("sampling") {
            "map" => EnvSampling::Map,
            "uniform" => EnvSampling::Uniform,
            "alias" => EnvSampling::Alias,
            other => {
                report.warn(
                    Some("sampling"),
                    format!("unknown infinite light sampling \"{other}\" (pbrs has \"map\", \"alias\" and \"uniform\"): \"map\" is used"),
                    "unknown sampling",
                );
                EnvSampling::Map
            }
        };
        let image = p.image("mapname");
        InfiniteLight {
            n_samples: n.clamp(1, MAX_SAMPLES) as u32,
            scene_radius: 0.0,
            map: Arc::new(EnvMap::new(image.as_deref(), l, ctm, sampling)),
        }
    }
}

impl LightModel for InfiniteLight {
    #[inline]
    fn is_delta(&self) -> bool {
        false
    }

    fn is_infinite(&self) -> bool {
        true
    }

    fn at_infinity(&self) -> bool {
        true
    }

    fn n_samples(&self) -> u32 {
        self.n_samples.max(1)
    }

    fn n_samples_mut(&mut self) -> Option<&mut u32> {
        Some(&mut self.n_samples)
    }

    fn power(&self) -> Vec3 {
        self.map.power_radiance() * PI * self.scene_radius * self.scene_radius
    }

    #[inline]
    fn le(&self, d: Vec3) -> Vec3 {
        self.map.le(d)
    }

    #[inline]
    fn sample_li(&self, r: &SurfacePoint, u: Vec2, _geom: &Aggregate) -> Option<LightSample> {
        self.sample_li_from(r, self.map.sample(u))
    }

    #[inline]
    fn pdf_li(&self, _r: &SurfacePoint, wi: Vec3, _geom: &Aggregate) -> f32 {
        self.map.pdf(wi)
    }

    #[inline]
    fn pdf_li_ray(&self, _r: &SurfacePoint, ray: &Ray, _geom: &Aggregate) -> f32 {
        self.map.pdf(ray.d)
    }

    /// pbrt-v3's: the map's density of the direction the ray comes from,
    /// uniform on the disk of the scene's bounding sphere.
    fn pdf_le(&self, d: Vec3, _n: Vec3) -> (f32, f32) {
        let r = self.scene_radius;
        (1.0 / (std::f32::consts::PI * r * r), self.map.pdf(-d))
    }

    /// pbrt-v3's: a direction as `sample_li` samples it (`u1`), the ray
    /// coming from it through a point uniform on the disk of the scene's
    /// bounding sphere facing it (`u2`).
    fn sample_le(&self, u1: Vec2, u2: Vec2, geom: &Aggregate) -> Option<EmittedRay> {
        let (wi, le, pdf_dir) = self.map.sample(u1)?;
        let (ray, pdf_pos) = disk_ray(geom, self.scene_radius, wi, u2)?;
        (pdf_dir > 0.0).then_some(EmittedRay {
            le,
            ray,
            n: ray.d,
            pdf_pos,
            pdf_dir,
        })
    }

    fn preprocess(&mut self, geom: &Aggregate) {
        self.scene_radius = geom.bounds.bounding_sphere().1;
    }
}

/// One level of the MIP map: RGB texels, row-major, row 0 at t = 0.
#[derive(Clone, Debug)]
pub(super) struct Level {
    w: usize,
    h: usize,
    texels: Vec<Vec3>,
}

impl Level {
    /// pbrt-v3's `Texel` with repeat wrapping.
    #[inline]
    fn texel(&self, s: i64, t: i64) -> Vec3 {
        let s = s.rem_euclid(self.w as i64) as usize;
        let t = t.rem_euclid(self.h as i64) as usize;
        self.texels[t * self.w + s]
    }

    /// The four texels around `st` (indices at rows t0, t0 + 1 and
    /// columns s0, s0 + 1, in that order: (t0, s0), (t0 + 1, s0),
    /// (t0, s0 + 1), (t0 + 1, s0 + 1)) and the offsets (ds, dt) from the
    /// first.
    #[inline(always)]
    fn corners(&self, st: Vec2) -> ([usize; 4], f32, f32) {
        let s = st.x * self.w as f32 - 0.5;
        let t = st.y * self.h as f32 - 0.5;
        let (s0, t0) = (s.floor(), t.floor());
        // The texels' columns and rows with the wrap applied (divisions
        // only where a neighbour wraps).
        let (sa, sb) = wrap_pair(s0 as i64, self.w);
        let (ra, rb) = wrap_pair(t0 as i64, self.h);
        let (ra, rb) = (ra * self.w, rb * self.w);
        ([ra + sa, rb + sa, ra + sb, rb + sb], s - s0, t - t0)
    }

    /// `luminance(bilerp((u + ½)/n, vp)) · scale` for `u` in `0..n`
    /// (`out.len()` = n): a row of the sampling distribution, eight entries
    /// at a time in AVX2 lanes (the row's texel rows and offset found once,
    /// each lane `bilerp`'s operations in its order, so the values are its
    /// bit for bit) where the build has AVX2, the others by `bilerp`.
    pub(super) fn luminance_row(&self, vp: f32, scale: f32, out: &mut [f32]) {
        let t = vp * self.h as f32 - 0.5;
        let t0 = t.floor();
        let (ra, rb) = wrap_pair(t0 as i64, self.h);
        let rows = (ra * self.w, rb * self.w);
        let dt = t - t0;
        let n = out.len() as f32;
        let entry = |u: usize| luminance(self.bilerp(Vec2::new((u as f32 + 0.5) / n, vp))) * scale;
        super::infinite_lanes::luminance_row(&self.texels, self.w, rows, dt, scale, out, entry);
    }

    /// Asks for the cache lines `bilerp(st)` reads (a hint).
    #[inline]
    pub(super) fn prefetch(&self, st: Vec2) {
        let tx = self.texels.as_ptr();
        for i in self.corners(st).0 {
            crate::accel::prefetch(tx.wrapping_add(i));
        }
    }

    /// The texel rows `t0 ..= t1` and columns `s0 ..= s1` (before
    /// wrapping) that `bilerp` reads at points in row `v` of `nv` and
    /// columns `lo ..= hi` of `nu` of a grid over the map.
    #[inline]
    fn span(&self, v: usize, nv: usize, lo: usize, hi: usize, nu: usize) -> [i64; 4] {
        let (w, h) = (self.w as f32, self.h as f32);
        // The first texel at the span's start, the second at its (open) end.
        let at = |i: usize, n: usize, m: f32| (i as f32 / n as f32) * m - 0.5;
        [
            at(v, nv, h).floor() as i64,
            at(v + 1, nv, h).ceil() as i64,
            at(lo, nu, w).floor() as i64,
            at(hi + 1, nu, w).ceil() as i64,
        ]
    }

    /// Asks for the texels `bilerp` reads at points in row `v` of `nv`
    /// and columns `lo ..= hi` of `nu` of a grid over the map (a hint):
    /// for a sample of the map's distribution, once its row and the range
    /// its column is in are known. Spans wider than a few cache lines are
    /// left to the lookup.
    #[inline]
    pub(super) fn prefetch_bins(&self, v: usize, nv: usize, lo: usize, hi: usize, nu: usize) {
        let [t0, t1, s0, s1] = self.span(v, nv, lo, hi, nu);
        if t1 - t0 > 2 || s1 - s0 > 15 {
            return;
        }
        let tx = self.texels.as_ptr();
        for t in t0..=t1 {
            let row = t.rem_euclid(self.h as i64) as usize * self.w;
            // Every fifth texel (a cache line holds 5.3) and the last.
            let mut s = s0;
            while s <= s1 + 4 {
                let col = s.min(s1).rem_euclid(self.w as i64) as usize;
                crate::accel::prefetch(tx.wrapping_add(row + col));
                s += 5;
            }
        }
    }

    /// pbrt-v3's `triangle`: bilinear between the four nearest texel centres.
    #[inline]
    fn bilerp(&self, st: Vec2) -> Vec3 {
        let ([a, b, c, d], ds, dt) = self.corners(st);
        let tx = &self.texels;
        (1.0 - ds) * (1.0 - dt) * tx[a]
            + (1.0 - ds) * dt * tx[b]
            + ds * (1.0 - dt) * tx[c]
            + ds * dt * tx[d]
    }
}

/// `i` and `i + 1` wrapped into `0..n` (as [`Level::texel`] wraps them).
#[inline(always)]
fn wrap_pair(i: i64, n: usize) -> (usize, usize) {
    if i >= 0 && i < n as i64 - 1 {
        (i as usize, i as usize + 1)
    } else {
        (
            i.rem_euclid(n as i64) as usize,
            i.wrapping_add(1).rem_euclid(n as i64) as usize,
        )
    }
}

/// The environment map of an infinite light: its MIP levels, sampling
/// distribution and transform.
#[derive(Debug)]
pub struct EnvMap {
    pub(super) levels: Vec<Level>,
    pub(super) distribution: Distribution2D,
    /// The alias tables of `distribution` (`sampling "alias"` only).
    alias: Option<Box<Alias2D>>,
    /// The radiance of a one-texel map (no map, or a 1 × 1 image): then
    /// every lookup is this value and the sampling distribution uniform in
    /// (φ, θ), so lookups and sampling skip the map's arithmetic.
    pub(super) constant: Option<Vec3>,
    pub(super) sampling: EnvSampling,
    light_to_world: Mat3,
    world_to_light: Mat3,
}

/// pbrt-v3's windowed sinc (`Lanczos` with τ = 2).
fn lanczos(x: f32) -> f32 {
    let tau = 2.0;
    let x = x.abs();
    if x < 1e-5 {
        return 1.0;
    }
    if x > 1.0 {
        return 0.0;
    }
    let x = x * PI;
    ((x * tau).sin() / (x * tau)) * (x.sin() / x)
}

/// The four source texels and their weights for each of `new` texels when
/// stretching `old` texels (pbrt-v3's `resampleWeights`).
fn resample_weights(old: usize, new: usize) -> Vec<(i64, [f32; 4])> {
    (0..new)
        .map(|i| {
            let center = (i as f32 + 0.5) * old as f32 / new as f32;
            let first = ((center - 2.0) + 0.5).floor();
            let mut w: [f32; 4] =
                std::array::from_fn(|j| lanczos((first + j as f32 + 0.5 - center) / 2.0));
            let inv = 1.0 / (w[0] + w[1] + w[2] + w[3]);
            for v in &mut w {
                *v *= inv;
            }
            (first as i64, w)
        })
        .collect()
}

/// `img` (w × h) resampled to the next powers of two as pbrt-v3's MIPMap
/// does: along s, then along t, then clamped to be non-negative.
fn resample_pow2(img: &[Vec3], w: usize, h: usize) -> (Vec<Vec3>, usize, usize) {
    let (nw, nh) = (w.next_power_of_two(), h.next_power_of_two());
    let sw = resample_weights(w, nw);
    let mut zoomed = vec![Vec3::ZERO; nw * h];
    zoomed.par_chunks_mut(nw).enumerate().for_each(|(t, row)| {
        for (s, out) in row.iter_mut().enumerate() {
            let (first, wt) = sw[s];
            let mut v = Vec3::ZERO;
            for (j, &wj) in wt.iter().enumerate() {
                let os = (first + j as i64).rem_euclid(w as i64) as usize;
                v += wj * img[t * w + os];
            }
            *out = v;
        }
    });
    let tw = resample_weights(h, nh);
    let mut out = vec![Vec3::ZERO; nw * nh];
    for (t, &(first, wt)) in tw.iter().enumerate() {
        for s in 0..nw {
            let mut v = Vec3::ZERO;
            for (j, &wj) in wt.iter().enumerate() {
                let ot = (first + j as i64).rem_euclid(h as i64) as usize;
                v += wj * zoomed[ot * nw + s];
            }
            out[t * nw + s] = v.max(Vec3::ZERO);
        }
    }
    (out, nw, nh)
}

/// A sample of an environment map: the world direction towards the light,
/// its radiance and its solid-angle density.
pub type EnvSample = (Vec3, Vec3, f32);

impl EnvMap {
    /// The map `image` (raw values) times `l`, or `l` alone; `light_to_world`
    /// orients it.
    pub fn new(
        image: Option<&RgbImage>,
        l: Vec3,
        light_to_world: DMat4,
        sampling: EnvSampling,
    ) -> EnvMap {
        let (texels, w, h) = match image {
            Some(img) => (
                img.pixels().iter().map(|&p| p * l).collect::<Vec<Vec3>>(),
                img.width() as usize,
                img.height() as usize,
            ),
            None => (vec![l], 1, 1),
        };
        let (texels, w, h) = if w.is_power_of_two() && h.is_power_of_two() {
            (texels, w, h)
        } else {
            resample_pow2(&texels, w, h)
        };
        let n_levels = 1 + w.max(h).ilog2() as usize;
        let mut levels = vec![Level { w, h, texels }];
        for _ in 1..n_levels {
            let prev = levels.last().unwrap();
            let (lw, lh) = ((prev.w / 2).max(1), (prev.h / 2).max(1));
            let mut texels = Vec::with_capacity(lw * lh);
            for t in 0..lh as i64 {
                for s in 0..lw as i64 {
                    texels.push(
                        0.25 * (prev.texel(2 * s, 2 * t)
                            + prev.texel(2 * s + 1, 2 * t)
                            + prev.texel(2 * s, 2 * t + 1)
                            + prev.texel(2 * s + 1, 2 * t + 1)),
                    );
                }
            }
            levels.push(Level {
                w: lw,
                h: lh,
                texels,
            });
        }
        let lin = glam::DMat3::from_mat4(light_to_world);
        let inv = if lin.determinant() != 0.0 {
            lin.inverse()
        } else {
            glam::DMat3::IDENTITY
        };
        // (Only with light to sample: a dark one keeps the map's handling.)
        let constant =
            Some(levels[0].texels[0]).filter(|&l| w == 1 && h == 1 && luminance(l) > 0.0);
        let mut map = EnvMap {
            levels,
            distribution: Distribution2D::new(&[1.0], 1, 1),
            alias: None,
            constant,
            sampling,
            light_to_world: lin.as_mat3(),
            world_to_light: inv.as_mat3(),
        };
        if sampling != EnvSampling::Uniform {
            let (dw, dh) = (2 * w, 2 * h);
            let level = map.filter_level(0.5 / dw.min(dh) as f32);
            map.distribution = Distribution2D::from_rows(dw, dh, |v, row| {
                let vp = (v as f32 + 0.5) / dh as f32;
                let sin_theta = (PI * (v as f32 + 0.5) / dh as f32).sin();
                if level < 0.0 {
                    // (`lookup_level`'s finest-level case, row by row.)
                    map.levels[0].luminance_row(vp, sin_theta, row);
                    return;
                }
                for (u, out) in row.iter_mut().enumerate() {
                    let up = (u as f32 + 0.5) / dw as f32;
                    *out = luminance(map.lookup_level(Vec2::new(up, vp), level)) * sin_theta;
                }
            });
            if sampling == EnvSampling::Alias {
                map.alias = Some(Box::new(Alias2D::new(&map.distribution)));
            }
        }
        map
    }

    /// pbrt-v3's `MIPMap::Lookup(st, width)`: trilinear between the levels
    /// around the filter width's level.
    fn lookup(&self, st: Vec2, width: f32) -> Vec3 {
        self.lookup_level(st, self.filter_level(width))
    }

    /// The (fractional) MIP level of a filter width, as `lookup` finds it.
    fn filter_level(&self, width: f32) -> f32 {
        (self.levels.len() - 1) as f32 + width.max(1e-8).log2()
    }

    /// `lookup` at the level `filter_level` gives.
    #[inline]
    fn lookup_level(&self, st: Vec2, level: f32) -> Vec3 {
        let n = self.levels.len();
        if level < 0.0 {
            self.levels[0].bilerp(st)
        } else if level >= (n - 1) as f32 {
            self.levels[n - 1].texel(0, 0)
        } else {
            let i = level.floor() as usize;
            let d = level - i as f32;
            (1.0 - d) * self.levels[i].bilerp(st) + d * self.levels[i + 1].bilerp(st)
        }
    }

    /// Light-space direction to map coordinates.
    #[inline]
    fn st(w: Vec3) -> Vec2 {
        let theta = w.z.clamp(-1.0, 1.0).acos();
        let mut phi = w.y.atan2(w.x);
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        Vec2::new(phi * (0.5 / PI), theta * (1.0 / PI))
    }

    /// Radiance arriving along a ray with direction `d` that leaves the
    /// scene (pbrt-v3's `Le`).
    #[inline]
    pub fn le(&self, d: Vec3) -> Vec3 {
        if let Some(l) = self.constant {
            return l;
        }
        let w = (self.world_to_light * d).normalize();
        self.levels[0].bilerp(Self::st(w))
    }

    /// Asks for the cache lines that `le(d)` and `pdf(d)` read (a hint):
    /// for a ray that has left the scene, whose radiance and density are
    /// wanted later.
    #[inline]
    pub fn prefetch(&self, d: Vec3) {
        if self.constant.is_some() {
            return;
        }
        let w = (self.world_to_light * d).normalize();
        let st = Self::st(w);
        self.levels[0].prefetch(st);
        if self.sampling != EnvSampling::Uniform {
            self.distribution.prefetch_pdf(st);
        }
    }

    /// A direction towards the light, its radiance and solid-angle density.
    #[inline]
    pub fn sample(&self, u: Vec2) -> Option<EnvSample> {
        if self.sampling == EnvSampling::Uniform {
            let wi = uniform_sample_sphere(u);
            return Some((wi, self.le(wi), uniform_sphere_pdf()));
        }
        let (uv, map_pdf) = self.sample_map_with(u, true);
        self.sample_direction(uv, map_pdf)
    }

    /// `sample`'s point in the map and its density there, asking for the
    /// CDF entries and the texels around the point while the search runs
    /// if `hints` (not when a batch has asked for them).
    #[inline]
    pub(super) fn sample_map_with(&self, u: Vec2, hints: bool) -> (Vec2, f32) {
        match (self.constant, &self.alias) {
            (Some(_), _) => (u, 1.0),
            (None, Some(alias)) => alias.sample_continuous(u),
            (None, None) if hints => self
                .distribution
                .sample_continuous_with(u, |v, lo, hi| self.prefetch_texels(v, lo, hi)),
            (None, None) => self.distribution.sample_continuous_unhinted(u),
        }
    }

    /// Asks for the texels that `sample_direction` reads at a point of the
    /// distribution's row `v` in its bins `lo - 1 ..= hi` (a hint).
    #[inline]
    pub(super) fn prefetch_texels(&self, v: usize, lo: usize, hi: usize) {
        let (nu, nv) = self.distribution.size();
        self.levels[0].prefetch_bins(v, nv, lo.saturating_sub(1), hi, nu);
    }

    /// `sample`'s direction, radiance and density from its point in the map.
    #[inline]
    pub(super) fn sample_direction(&self, uv: Vec2, map_pdf: f32) -> Option<EnvSample> {
        if map_pdf == 0.0 {
            return None;
        }
        let (theta, phi) = (uv.y * PI, uv.x * 2.0 * PI);
        let (sin_theta, cos_theta) = theta.sin_cos();
        let (sin_phi, cos_phi) = phi.sin_cos();
        let w = Vec3::new(sin_theta * cos_phi, sin_theta * sin_phi, cos_theta);
        let wi = (self.light_to_world * w).normalize();
        if sin_theta == 0.0 || !wi.is_finite() {
            return None;
        }
        let pdf = map_pdf / (2.0 * PI * PI * sin_theta);
        let li = match self.constant {
            Some(l) => l,
            None => self.levels[0].bilerp(uv),
        };
        Some((wi, li, pdf))
    }

    /// Solid-angle density of `sample` choosing world direction `wi`.
    #[inline]
    pub fn pdf(&self, wi: Vec3) -> f32 {
        if self.sampling == EnvSampling::Uniform {
            return uniform_sphere_pdf();
        }
        let w = (self.world_to_light * wi).normalize();
        if self.constant.is_some() {
            // Uniform in (φ, θ): sin θ from the direction alone.
            let z = w.z.clamp(-1.0, 1.0);
            let sin_theta = (1.0 - z * z).max(0.0).sqrt();
            if sin_theta == 0.0 {
                return 0.0;
            }
            return 1.0 / (2.0 * PI * PI * sin_theta);
        }
        let st = Self::st(w);
        let sin_theta = (st.y * PI).sin();
        if sin_theta == 0.0 {
            return 0.0;
        }
        self.distribution.pdf(st) / (2.0 * PI * PI * sin_theta)
    }

    /// Width and height of the map's finest level (a power of two each).
    pub fn size(&self) -> (usize, usize) {
        (self.levels[0].w, self.levels[0].h)
    }

    /// Radiance for pbrt-v3's `Power` (times π r² there): the map filtered
    /// to one level above its coarsest.
    pub fn power_radiance(&self) -> Vec3 {
        self.lookup(Vec2::splat(0.5), 0.5)
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::scene::SampleDepth;

    fn image(w: u32, h: u32, f: impl Fn(u32, u32) -> Vec3) -> RgbImage {
        let px = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| f(x, y))
            .collect();
        RgbImage::new(w, h, px, SampleDepth::F32).unwrap()
    }

    /// A lopsided map: a bright spot, a dark band and a smooth gradient.
    pub(in crate::lights) fn lumpy(w: u32, h: u32) -> RgbImage {
        image(w, h, |x, y| {
            let base = 0.2 + (x as f32 / w as f32) + 0.5 * (y as f32 / h as f32);
            let spot = if x == w / 3 && y == h / 4 { 200.0 } else { 0.0 };
            let band = if y == h / 2 { 0.0 } else { 1.0 };
            Vec3::new(base + spot, 0.5 * base, 2.0 * base) * band
        })
    }

    pub(in crate::lights) fn rotated() -> DMat4 {
        DMat4::from_rotation_x(-std::f64::consts::FRAC_PI_2) * DMat4::from_rotation_z(0.3)
    }

    /// The environment map's bilinear lookup (columns and rows wrapped
    /// only where a neighbour leaves the map) gives the values of pbrt-v3's,
    /// every texel through `Texel`, bit for bit: odd and one-texel sizes,
    /// inside, across the seams and far outside.
    /// A row of the sampling distribution made by `luminance_row` (eight
    /// entries at a time in lanes where the build has AVX2) is
    /// `luminance(bilerp(st)) · scale` entry by entry, bit for bit: maps
    /// one or two texels wide, rows shorter than a vector, columns that
    /// wrap at both edges, texels of every magnitude.
    #[test]
    fn luminance_rows_are_the_entries_one_by_one() {
        let mut rng = crate::sampling::Pcg32::with_sequence(9);
        for (w, h) in [
            (37usize, 16usize),
            (1, 5),
            (2, 3),
            (6, 1),
            (64, 32),
            (300, 2),
        ] {
            let texels: Vec<Vec3> = (0..w * h)
                .map(|i| {
                    let m = [1.0, 1e-30, 3e4][i % 3];
                    Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32()) * m
                })
                .collect();
            let level = Level { w, h, texels };
            for n in [2 * w, w, 7, 8, 9, 100, 4 * w + 3] {
                for _ in 0..20 {
                    let vp = rng.uniform_f32();
                    let scale = rng.uniform_f32() * 2.0;
                    let mut row = vec![0.0f32; n];
                    level.luminance_row(vp, scale, &mut row);
                    for (u, &v) in row.iter().enumerate() {
                        let st = Vec2::new((u as f32 + 0.5) / n as f32, vp);
                        let plain = luminance(level.bilerp(st)) * scale;
                        assert_eq!(v.to_bits(), plain.to_bits(), "{w}x{h} n {n} u {u} vp {vp}");
                    }
                }
            }
        }
    }

    #[test]
    fn bilerp_equals_the_plain_lookup() {
        let mut rng = crate::sampling::Pcg32::with_sequence(5);
        for (w, h) in [(37usize, 16usize), (1, 5), (6, 1), (1, 1), (64, 32)] {
            let texels: Vec<Vec3> = (0..w * h)
                .map(|_| Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32()))
                .collect();
            let level = Level { w, h, texels };
            for k in 0..6000 {
                let spread = [1.0, 1.1, 9.0][k % 3];
                let st = Vec2::new(rng.uniform_f32(), rng.uniform_f32()) * spread
                    - Vec2::splat(0.5 * (spread - 1.0));
                let s = st.x * w as f32 - 0.5;
                let t = st.y * h as f32 - 0.5;
                let (s0, t0) = (s.floor(), t.floor());
                let (ds, dt) = (s - s0, t - t0);
                let (s0, t0) = (s0 as i64, t0 as i64);
                let plain = (1.0 - ds) * (1.0 - dt) * level.texel(s0, t0)
                    + (1.0 - ds) * dt * level.texel(s0, t0 + 1)
                    + ds * (1.0 - dt) * level.texel(s0 + 1, t0)
                    + ds * dt * level.texel(s0 + 1, t0 + 1);
                let fast = level.bilerp(st);
                assert_eq!(
                    fast.to_array().map(f32::to_bits),
                    plain.to_array().map(f32::to_bits),
                    "{w}x{h} st {st}"
                );
            }
        }
    }

    /// The texels a sample's hint asks for (`Level::span` of its row and
    /// the bins its search bisects) are those `bilerp` reads at the point
    /// it samples: else the hint would miss and the lookup wait.
    #[test]
    fn texel_hints_cover_the_sampled_point() {
        let img = lumpy(64, 32);
        let map = EnvMap::new(Some(&img), Vec3::ONE, rotated(), EnvSampling::Map);
        let (nu, nv) = map.distribution.size();
        let level = &map.levels[0];
        let mut rng = crate::sampling::Pcg32::with_sequence(3);
        for _ in 0..20000 {
            let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
            let mut span = None;
            let (uv, pdf) = map.distribution.sample_continuous_with(u, |v, lo, hi| {
                span = Some(level.span(v, nv, lo.saturating_sub(1), hi, nu));
            });
            if pdf == 0.0 {
                continue;
            }
            let [t0, t1, s0, s1] = span.unwrap();
            let s = uv.x * level.w as f32 - 0.5;
            let t = uv.y * level.h as f32 - 0.5;
            let (sf, tf) = (s.floor() as i64, t.floor() as i64);
            assert!(
                t0 <= tf && tf < t1,
                "rows {t0}..={t1}, read {tf} and {}",
                tf + 1
            );
            assert!(
                s0 <= sf && sf < s1,
                "columns {s0}..={s1}, read {sf} and {}",
                sf + 1
            );
            assert!(t1 - t0 <= 2, "a sample's rows span {t0}..={t1}");
        }
    }

    /// A one-texel map takes the constant shortcuts; the same map without
    /// them takes the general path (bilinear lookups, the search of its 2 × 2
    /// distribution, θ from acos): both give the same radiance, directions
    /// and densities up to rounding.
    #[test]
    fn constant_map_matches_the_general_path() {
        let l = Vec3::new(0.3, 0.5, 0.9);
        let one = EnvMap::new(None, l, rotated(), EnvSampling::Map);
        let mut general = EnvMap::new(
            Some(&image(1, 1, |_, _| l)),
            Vec3::ONE,
            rotated(),
            EnvSampling::Map,
        );
        assert!(one.constant.is_some() && general.constant.is_some());
        general.constant = None;
        let close = |a: f32, b: f32| (a - b).abs() <= 1e-4 * a.abs().max(b.abs()).max(1e-3);
        let mut rng = crate::sampling::Pcg32::with_sequence(11);
        for _ in 0..10_000 {
            let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
            let (a, b) = (one.sample(u), general.sample(u));
            let (Some((wa, la, pa)), Some((wb, lb, pb))) = (a, b) else {
                assert_eq!(a.is_some(), b.is_some(), "u = {u}");
                continue;
            };
            assert!((wa - wb).length() < 1e-4, "u = {u}: {wa} against {wb}");
            assert!(close(pa, pb), "u = {u}: pdf {pa} against {pb}");
            assert!((la - lb).abs().max_element() < 1e-5 && (la - l).abs().max_element() < 1e-6);
            let d = Vec3::new(
                rng.uniform_f32() - 0.5,
                rng.uniform_f32() - 0.5,
                rng.uniform_f32() - 0.5,
            );
            if d.length() > 1e-3 {
                let d = d.normalize();
                assert!(
                    close(one.pdf(d), general.pdf(d)),
                    "{d}: {} against {}",
                    one.pdf(d),
                    general.pdf(d)
                );
                assert!((one.le(d) - general.le(d)).abs().max_element() < 1e-5);
            }
        }
    }

    /// Chi-square test of `sample` (directions) against `pdf` (solid angle),
    /// on cells in (φ, θ) aligned with the distribution's bins, where
    /// pdf · sin θ is constant: the expected counts come from a midpoint rule
    /// inside each cell (exact there), rather than the general harness's
    /// adaptive quadrature, which the bins' edges would make very slow.
    #[test]
    fn sample_li_matches_pdf_li_chi_square() {
        use crate::sampling::chi2::chi2_survival;
        use std::f64::consts::PI as PI64;
        for (w, h, sampling) in [
            (16, 8, EnvSampling::Map),
            (12, 5, EnvSampling::Map),
            (16, 8, EnvSampling::Alias),
            (12, 5, EnvSampling::Alias),
        ] {
            let map = EnvMap::new(Some(&lumpy(w, h)), Vec3::ONE, rotated(), sampling);
            // Both maps give a 32 × 16 distribution (12 × 5 is resampled to 16 × 8).
            let (np, nt) = (32usize, 16usize);
            let to_light = |d: Vec3| (map.world_to_light * d).normalize();
            let n = 1_000_000;
            let mut observed = vec![0.0f64; np * nt];
            let mut rng = crate::sampling::Pcg32::with_sequence(5);
            for _ in 0..n {
                let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
                let Some((wi, _, pdf)) = map.sample(u) else {
                    continue;
                };
                assert!(pdf > 0.0 && (wi.length() - 1.0).abs() < 1e-4);
                let st = EnvMap::st(to_light(wi));
                let ip = ((st.x * np as f32) as usize).min(np - 1);
                let it = ((st.y * nt as f32) as usize).min(nt - 1);
                observed[it * np + ip] += 1.0;
            }
            let mut expected = vec![0.0f64; np * nt];
            let k = 4;
            for it in 0..nt {
                for ip in 0..np {
                    let mut sum = 0.0;
                    for a in 0..k {
                        for b in 0..k {
                            let t = (it as f64 + (a as f64 + 0.5) / k as f64) / nt as f64 * PI64;
                            let p =
                                (ip as f64 + (b as f64 + 0.5) / k as f64) / np as f64 * 2.0 * PI64;
                            let dl = Vec3::new(
                                (t.sin() * p.cos()) as f32,
                                (t.sin() * p.sin()) as f32,
                                t.cos() as f32,
                            );
                            let dw = (map.light_to_world * dl).normalize();
                            sum += map.pdf(dw) as f64 * t.sin();
                        }
                    }
                    let cell = (PI64 / nt as f64) * (2.0 * PI64 / np as f64);
                    expected[it * np + ip] = sum / (k * k) as f64 * cell * n as f64;
                }
            }
            let total: f64 = expected.iter().sum::<f64>() / n as f64;
            assert!((total - 1.0).abs() < 1e-3, "pdf integrates to {total}");
            // Pool cells expecting fewer than 5 samples.
            let (mut stat, mut dof, mut pool_o, mut pool_e) = (0.0, 0usize, 0.0, 0.0);
            for (o, e) in observed.iter().zip(&expected) {
                if *e < 5.0 {
                    pool_o += o;
                    pool_e += e;
                } else {
                    stat += (o - e) * (o - e) / e;
                    dof += 1;
                }
            }
            if pool_e > 0.0 {
                stat += (pool_o - pool_e) * (pool_o - pool_e) / pool_e.max(1e-9);
                dof += 1;
            }
            let p_value = chi2_survival(stat, (dof - 1) as f64);
            println!("{w}x{h}: chi2 {stat:.1}, dof {}, p {p_value:.3}", dof - 1);
            assert!(
                p_value > 0.005,
                "{w}x{h}: chi2 {stat}, dof {dof}, p {p_value}"
            );
        }
    }

    /// ∫ pdf dω = 1, integrated finely on the map's own (s, t) grid (where the
    /// density is constant per bin apart from 1/sin θ, which dω cancels).
    #[test]
    fn pdf_integrates_to_one_and_matches_samples() {
        let map = EnvMap::new(
            Some(&lumpy(8, 4)),
            Vec3::ONE,
            DMat4::IDENTITY,
            EnvSampling::Map,
        );
        let (nu, nv) = (16 * 8, 8 * 8);
        let mut sum = 0.0f64;
        for v in 0..nv {
            for u in 0..nu {
                let (s, t) = ((u as f64 + 0.5) / nu as f64, (v as f64 + 0.5) / nv as f64);
                let (theta, phi) = (t * std::f64::consts::PI, s * 2.0 * std::f64::consts::PI);
                let w = Vec3::new(
                    (theta.sin() * phi.cos()) as f32,
                    (theta.sin() * phi.sin()) as f32,
                    theta.cos() as f32,
                );
                let dw = theta.sin()
                    * (std::f64::consts::PI / nv as f64)
                    * (2.0 * std::f64::consts::PI / nu as f64);
                sum += map.pdf(w) as f64 * dw;
            }
        }
        assert!((sum - 1.0).abs() < 2e-3, "∫pdf = {sum}");
        // Every sample's density is the one pdf_li reports for its direction.
        let mut rng = crate::sampling::Pcg32::with_sequence(2);
        for _ in 0..10_000 {
            let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
            if let Some((wi, li, pdf)) = map.sample(u) {
                let p = map.pdf(wi);
                assert!((p - pdf).abs() <= 2e-3 * pdf, "{p} vs {pdf}");
                assert!((li - map.le(wi)).abs().max_element() <= 1e-3 * li.max_element().max(1.0));
            }
        }
    }

    #[test]
    fn one_pixel_map_is_the_constant_light() {
        let l = Vec3::new(0.3, 0.5, 0.7);
        let one = EnvMap::new(
            Some(&image(1, 1, |_, _| Vec3::new(1.0, 2.0, 0.5))),
            l,
            rotated(),
            EnvSampling::Map,
        );
        let none = EnvMap::new(
            None,
            l * Vec3::new(1.0, 2.0, 0.5),
            rotated(),
            EnvSampling::Map,
        );
        let mut rng = crate::sampling::Pcg32::with_sequence(9);
        for _ in 0..1000 {
            let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
            let a = one.sample(u).unwrap();
            let b = none.sample(u).unwrap();
            assert_eq!(a.0, b.0);
            assert_eq!(a.2, b.2);
            assert!((a.1 - Vec3::new(0.3, 1.0, 0.35)).abs().max_element() < 1e-6);
            assert!((one.le(a.0) - b.1).abs().max_element() < 1e-6);
        }
        assert!(
            (one.power_radiance() - none.power_radiance())
                .abs()
                .max_element()
                < 1e-6
        );
        assert!(
            (one.power_radiance() - Vec3::new(0.3, 1.0, 0.35))
                .abs()
                .max_element()
                < 1e-6
        );
    }

    /// Orientation: the file's top row is light-space +z; s = φ/2π from +x.
    #[test]
    fn lat_long_orientation() {
        // 4 × 2: top row red, bottom row blue; columns add green by φ.
        let img = image(4, 2, |x, y| {
            Vec3::new(
                if y == 0 { 1.0 } else { 0.0 },
                x as f32,
                if y == 1 { 1.0 } else { 0.0 },
            )
        });
        let map = EnvMap::new(Some(&img), Vec3::ONE, DMat4::IDENTITY, EnvSampling::Map);
        // θ = π/4 is the top row's centre (t = 0.25): red only.
        let a = std::f32::consts::FRAC_1_SQRT_2;
        let up = map.le(Vec3::new(a, 0.0, a));
        assert!(up.x > 0.999 && up.z < 1e-3, "{up}");
        let down = map.le(Vec3::new(a, 0.0, -a));
        assert!(down.z > 0.999 && down.x < 1e-3, "{down}");
        // At the pole itself pbrt-v3's repeat wrap blends in the other pole's row.
        let pole = map.le(Vec3::Z);
        assert!(
            (pole.x - 0.5).abs() < 1e-3 && (pole.z - 0.5).abs() < 1e-3,
            "{pole}"
        );
        // On the horizon at φ = 3π/4 + ε (s = 0.375 + ε: texel 1's centre at 0.375).
        let w = Vec3::new((0.75 * PI).cos(), (0.75 * PI).sin(), 0.0);
        assert!((map.le(w).y - 1.0).abs() < 1e-4, "{}", map.le(w));
        // The light's transform turns +z to world +y (Rotate -90 about x).
        let m = EnvMap::new(
            Some(&img),
            Vec3::ONE,
            DMat4::from_rotation_x(-std::f64::consts::FRAC_PI_2),
            EnvSampling::Map,
        );
        assert!(
            m.le(Vec3::new(a, a, 0.0)).x > 0.999,
            "{}",
            m.le(Vec3::new(a, a, 0.0))
        );
    }

    /// Non-power-of-two maps are resampled as pbrt-v3 does: a constant stays
    /// constant, the levels average the map, and the resampled level keeps
    /// the mean of a smooth map.
    #[test]
    fn resampling_and_levels() {
        let c = EnvMap::new(
            Some(&image(6, 3, |_, _| Vec3::splat(2.0))),
            Vec3::ONE,
            DMat4::IDENTITY,
            EnvSampling::Map,
        );
        assert_eq!((c.levels[0].w, c.levels[0].h), (8, 4));
        assert_eq!(c.levels.len(), 4);
        for lvl in &c.levels {
            for t in &lvl.texels {
                assert!((*t - Vec3::splat(2.0)).abs().max_element() < 1e-5, "{t}");
            }
        }
        let g = lumpy(16, 8);
        let m = EnvMap::new(Some(&g), Vec3::ONE, DMat4::IDENTITY, EnvSampling::Map);
        let mean: Vec3 = g.pixels().iter().sum::<Vec3>() / g.pixels().len() as f32;
        let top = m.levels.last().unwrap().texels[0];
        assert!(
            (top - mean).abs().max_element() < 1e-3 * mean.max_element(),
            "{top} vs {mean}"
        );
        // Power: the 2 × 1 level above the top, sampled at its centre = the mean.
        assert!((m.power_radiance() - mean).abs().max_element() < 1e-3 * mean.max_element());
        let w = lanczos(0.5);
        assert!((w - (PI).sin() / PI * (0.5 * PI).sin() / (0.5 * PI)).abs() < 1e-6);
    }

    #[test]
    fn uniform_sampling_option() {
        let map = EnvMap::new(
            Some(&lumpy(8, 4)),
            Vec3::ONE,
            rotated(),
            EnvSampling::Uniform,
        );
        let (wi, li, pdf) = map.sample(Vec2::new(0.3, 0.6)).unwrap();
        assert_eq!(pdf, 1.0 / (4.0 * PI));
        assert_eq!(map.pdf(wi), pdf);
        assert_eq!(li, map.le(wi));
    }
}
