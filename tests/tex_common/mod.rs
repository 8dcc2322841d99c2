//! Helpers for the texture tests: textures loaded through the real loader
//! (files from memory), hits to evaluate them at, and independent `f64`
//! implementations of pbrt-v3's formulas to compare with.
#![allow(dead_code)]

use glam::{Vec2, Vec3};
use pbrs::accel::SurfaceHit;
use pbrs::lang::parser::FileLoader;
use pbrs::loader::{load_scene_with, LoadFailure, LoadedScene};
use pbrs::materials::ShadingContext;
use pbrs::scene::{FloatTex, SpectrumTex};
use pbrs::shapes::{DiffGeom, SurfacePoint};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Files served from memory by name (relative to the scene's directory).
#[derive(Clone, Default)]
pub struct MemFiles(pub HashMap<PathBuf, Vec<u8>>);

impl FileLoader for MemFiles {
    fn load(&self, path: &Path) -> Result<Vec<u8>, String> {
        self.0
            .get(path)
            .cloned()
            .ok_or_else(|| format!("no such file (test loader): {}", path.display()))
    }
}

/// The scene directory the tests pretend to be in.
pub fn dir() -> PathBuf {
    PathBuf::from("/mem")
}

pub fn try_load(text: &str, files: &MemFiles) -> Result<LoadedScene, LoadFailure> {
    load_scene_with(text, &dir().join("t.pbrt"), Box::new(files.clone()))
}

pub fn load(text: &str, files: &MemFiles) -> LoadedScene {
    try_load(text, files).unwrap_or_else(|f| {
        panic!(
            "{text}\n{}",
            f.errors
                .iter()
                .map(|e| e.to_string())
                .collect::<Vec<_>>()
                .join("\n")
        )
    })
}

pub fn warnings(s: &LoadedScene) -> String {
    s.warnings
        .iter()
        .map(|w| w.to_string())
        .collect::<Vec<_>>()
        .join("\n")
}

/// The spectrum texture "t" defined by `decls` (statements before
/// `WorldEnd`), as a matte's Kd, and the scene's warnings.
pub fn spectrum_tex_with(decls: &str, files: &MemFiles) -> (SpectrumTex, String) {
    let s = load(
        &format!("WorldBegin\n{decls}\nMaterial \"matte\" \"texture Kd\" \"t\"\nShape \"sphere\"\nWorldEnd\n"),
        files,
    );
    let w = warnings(&s);
    (
        s.scene.materials[0].params.spectrum_tex("Kd").expect("Kd"),
        w,
    )
}

/// The float texture "t" defined by `decls`, as a matte's sigma.
pub fn float_tex_with(decls: &str, files: &MemFiles) -> (FloatTex, String) {
    let s = load(
        &format!("WorldBegin\n{decls}\nMaterial \"matte\" \"texture sigma\" \"t\"\nShape \"sphere\"\nWorldEnd\n"),
        files,
    );
    let w = warnings(&s);
    (
        s.scene.materials[0]
            .params
            .float_tex("sigma")
            .expect("sigma"),
        w,
    )
}

pub fn spectrum_tex(decls: &str) -> SpectrumTex {
    let (t, w) = spectrum_tex_with(decls, &MemFiles::default());
    assert!(w.is_empty(), "unexpected warnings for {decls}:\n{w}");
    t
}

pub fn float_tex(decls: &str) -> FloatTex {
    let (t, w) = float_tex_with(decls, &MemFiles::default());
    assert!(w.is_empty(), "unexpected warnings for {decls}:\n{w}");
    t
}

/// A hit to evaluate textures at: world point, uv, and screen-space
/// differentials (dp/dx, dp/dy, and du/dx, dv/dx, du/dy, dv/dy).
#[derive(Clone, Copy, Debug)]
pub struct At {
    pub hit: SurfaceHit,
    pub geom: DiffGeom,
}

impl At {
    pub fn new(p: Vec3, uv: Vec2) -> At {
        At {
            hit: SurfaceHit {
                point: SurfacePoint {
                    p,
                    p_error: Vec3::ZERO,
                    n: Vec3::Z,
                    ns: Vec3::Z,
                },
                material: 0,
                light: None,
                time: 0.0,
            },
            geom: DiffGeom {
                uv,
                dpdu: Vec3::X,
                dpdv: Vec3::Y,
                shading_dpdu: Vec3::X,
                shading_dpdv: Vec3::Y,
                ..DiffGeom::ZERO
            },
        }
    }
    pub fn uv(u: f32, v: f32) -> At {
        At::new(Vec3::ZERO, Vec2::new(u, v))
    }
    pub fn p(x: f32, y: f32, z: f32) -> At {
        At::new(Vec3::new(x, y, z), Vec2::ZERO)
    }
    /// With uv differentials.
    pub fn duv(mut self, dudx: f32, dvdx: f32, dudy: f32, dvdy: f32) -> At {
        self.geom.dudx = dudx;
        self.geom.dvdx = dvdx;
        self.geom.dudy = dudy;
        self.geom.dvdy = dvdy;
        self
    }
    /// With position differentials.
    pub fn dp(mut self, dpdx: Vec3, dpdy: Vec3) -> At {
        self.geom.dpdx = dpdx;
        self.geom.dpdy = dpdy;
        self
    }
    pub fn sc(&self) -> ShadingContext<'_> {
        ShadingContext {
            hit: &self.hit,
            geom: &self.geom,
        }
    }
}

pub fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + b.abs())
}

#[track_caller]
pub fn assert_close(a: f64, b: f64, tol: f64, what: &str) {
    assert!(close(a, b, tol), "{what}: {a} vs expected {b}");
}

#[track_caller]
pub fn assert_close3(a: Vec3, b: [f64; 3], tol: f64, what: &str) {
    for (i, (x, y)) in a.to_array().iter().zip(b).enumerate() {
        assert!(
            close(*x as f64, y, tol),
            "{what}[{i}]: {a} vs expected {b:?}"
        );
    }
}

// ------------------------------------------------------------ reference

/// Ken Perlin's permutation (as in pbrt-v3's src/core/texture.cpp).
#[rustfmt::skip]
const PERM: [u8; 256] = [
    151, 160, 137, 91, 90, 15, 131, 13, 201, 95, 96, 53, 194, 233, 7, 225,
    140, 36, 103, 30, 69, 142, 8, 99, 37, 240, 21, 10, 23, 190, 6, 148,
    247, 120, 234, 75, 0, 26, 197, 62, 94, 252, 219, 203, 117, 35, 11, 32,
    57, 177, 33, 88, 237, 149, 56, 87, 174, 20, 125, 136, 171, 168, 68, 175,
    74, 165, 71, 134, 139, 48, 27, 166, 77, 146, 158, 231, 83, 111, 229, 122,
    60, 211, 133, 230, 220, 105, 92, 41, 55, 46, 245, 40, 244, 102, 143, 54,
    65, 25, 63, 161, 1, 216, 80, 73, 209, 76, 132, 187, 208, 89, 18, 169,
    200, 196, 135, 130, 116, 188, 159, 86, 164, 100, 109, 198, 173, 186, 3, 64,
    52, 217, 226, 250, 124, 123, 5, 202, 38, 147, 118, 126, 255, 82, 85, 212,
    207, 206, 59, 227, 47, 16, 58, 17, 182, 189, 28, 42, 223, 183, 170, 213,
    119, 248, 152, 2, 44, 154, 163, 70, 221, 153, 101, 155, 167, 43, 172, 9,
    129, 22, 39, 253, 19, 98, 108, 110, 79, 113, 224, 232, 178, 185, 112, 104,
    218, 246, 97, 228, 251, 34, 242, 193, 238, 210, 144, 12, 191, 179, 162, 241,
    81, 51, 145, 235, 249, 14, 239, 107, 49, 192, 214, 31, 181, 199, 106, 157,
    184, 84, 204, 176, 115, 121, 50, 45, 127, 4, 150, 254, 138, 236, 205, 93,
    222, 114, 67, 29, 24, 72, 243, 141, 128, 195, 78, 66, 215, 61, 156, 180,
];

fn p8(i: i64) -> i64 {
    PERM[i.rem_euclid(256) as usize] as i64
}

/// Perlin's improved-noise gradient: one of twelve edge directions (and
/// four repeats) chosen by the hashed lattice point.
fn gradient(ix: i64, iy: i64, iz: i64, d: [f64; 3]) -> f64 {
    let h = p8(p8(p8(ix) + iy) + iz) & 15;
    let (x, y, z) = (d[0], d[1], d[2]);
    let u = match h {
        0..=7 | 12 | 13 => x,
        _ => y,
    };
    let v = match h {
        0..=3 | 12 | 13 => y,
        _ => z,
    };
    let su = if h & 1 == 1 { -u } else { u };
    let sv = if h & 2 == 2 { -v } else { v };
    su + sv
}

/// Gradient noise in f64: the quintic-weighted trilinear blend of the
/// corner gradients' dot products (pbrt-v3's `Noise`).
pub fn noise(x: f64, y: f64, z: f64) -> f64 {
    let c = [x.floor(), y.floor(), z.floor()];
    let f = [x - c[0], y - c[1], z - c[2]];
    let fade = |t: f64| t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
    let mut sum = 0.0;
    for corner in 0..8 {
        let o = [corner & 1, (corner >> 1) & 1, (corner >> 2) & 1];
        let g = gradient(
            c[0] as i64 + o[0] as i64,
            c[1] as i64 + o[1] as i64,
            c[2] as i64 + o[2] as i64,
            [f[0] - o[0] as f64, f[1] - o[1] as f64, f[2] - o[2] as f64],
        );
        let mut w = 1.0;
        for a in 0..3 {
            let t = fade(f[a]);
            w *= if o[a] == 1 { t } else { 1.0 - t };
        }
        sum += w * g;
    }
    sum
}

fn smoothstep(lo: f64, hi: f64, v: f64) -> f64 {
    let t = ((v - lo) / (hi - lo)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

fn octave_count(dpdx: [f64; 3], dpdy: [f64; 3], max: i32) -> f64 {
    let l2 = |v: [f64; 3]| v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    let len2 = l2(dpdx).max(l2(dpdy));
    (-1.0 - 0.5 * len2.log2()).clamp(0.0, max as f64)
}

fn scaled(p: [f64; 3], s: f64) -> [f64; 3] {
    [p[0] * s, p[1] * s, p[2] * s]
}

/// pbrt-v3's FBm in f64.
pub fn fbm(p: [f64; 3], dpdx: [f64; 3], dpdy: [f64; 3], omega: f64, max: i32) -> f64 {
    let n = octave_count(dpdx, dpdy, max);
    let whole = n.floor() as i32;
    let mut sum = 0.0;
    for i in 0..whole {
        let q = scaled(p, 1.99f64.powi(i));
        sum += omega.powi(i) * noise(q[0], q[1], q[2]);
    }
    let q = scaled(p, 1.99f64.powi(whole));
    sum + omega.powi(whole) * smoothstep(0.3, 0.7, n - whole as f64) * noise(q[0], q[1], q[2])
}

/// pbrt-v3's Turbulence in f64 (its clamped octaves count 0.2 each, the
/// partial octave and the first clamped one at the same amplitude).
pub fn turbulence(p: [f64; 3], dpdx: [f64; 3], dpdy: [f64; 3], omega: f64, max: i32) -> f64 {
    let n = octave_count(dpdx, dpdy, max);
    let whole = n.floor() as i32;
    let mut sum = 0.0;
    for i in 0..whole {
        let q = scaled(p, 1.99f64.powi(i));
        sum += omega.powi(i) * noise(q[0], q[1], q[2]).abs();
    }
    let q = scaled(p, 1.99f64.powi(whole));
    let s = smoothstep(0.3, 0.7, n - whole as f64);
    let last = noise(q[0], q[1], q[2]).abs();
    sum += omega.powi(whole) * ((1.0 - s) * 0.2 + s * last);
    for i in whole..max {
        sum += omega.powi(i) * 0.2;
    }
    sum
}

/// pbrt-v3's sRGB decoding in f64.
pub fn srgb_decode(v: f64) -> f64 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// pbrt-v3's luminance weights.
pub fn luminance(c: [f64; 3]) -> f64 {
    0.212671 * c[0] + 0.715160 * c[1] + 0.072169 * c[2]
}

pub fn v3(v: Vec3) -> [f64; 3] {
    [v.x as f64, v.y as f64, v.z as f64]
}

/// An 8-bit RGB PNG of `w`×`h` pixels (rows top to bottom).
pub fn png(w: u32, h: u32, rgb: &[[u8; 3]]) -> Vec<u8> {
    let mut img = image::RgbImage::new(w, h);
    for (i, p) in img.pixels_mut().enumerate() {
        *p = image::Rgb(rgb[i]);
    }
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

/// A little-endian RGB PFM of `w`×`h` pixels given top row first (the file
/// stores rows bottom to top).
pub fn pfm(w: usize, h: usize, rgb: &[[f32; 3]]) -> Vec<u8> {
    let mut out = format!("PF\n{w} {h}\n-1\n").into_bytes();
    for row in (0..h).rev() {
        for c in &rgb[row * w..(row + 1) * w] {
            for v in c {
                out.extend_from_slice(&v.to_le_bytes());
            }
        }
    }
    out
}
