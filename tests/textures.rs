//! Every texture class of `textures::TEXTURES`, loaded through the
//! real loader and evaluated at chosen points against pbrt-v3's formulas
//! evaluated independently in f64 (`tex_common`). `every_class_has_a_case`
//! fails when a class of the table has no case here. Also: the mappings,
//! and bad input (located warnings or errors, never a panic).

mod tex_common;

use glam::{DMat4, Vec2, Vec3};
use pbrs::scene::{FloatTex, SpectrumTex, Tex};
use pbrs::textures::{Class, Mapping2D, TEXTURES};
use std::f64::consts::PI;
use tex_common::*;

/// One case per texture class: what it checks is in each function.
fn cases() -> Vec<(&'static str, fn())> {
    vec![
        ("constant", case_constant),
        ("scale", case_scale),
        ("mix", case_mix),
        ("bilerp", case_bilerp),
        ("imagemap", case_imagemap),
        ("uv", case_uv),
        ("checkerboard", case_checkerboard),
        ("dots", case_dots),
        ("fbm", case_fbm),
        ("wrinkled", case_wrinkled),
        ("marble", case_marble),
        ("windy", case_windy),
        ("ptex", case_ptex),
    ]
}

#[test]
fn every_class_has_a_case() {
    let cases = cases();
    for class in TEXTURES {
        let Some((_, case)) = cases.iter().find(|(n, _)| *n == class.name) else {
            panic!("texture class \"{}\" has no test case", class.name);
        };
        case();
    }
    assert_eq!(
        cases.len(),
        TEXTURES.len(),
        "a case for a class not in the table"
    );
}

/// Points spread over a few cells (uv) and space (p), with and without
/// differentials.
fn uv_points() -> Vec<At> {
    let mut out = Vec::new();
    for (i, (u, v)) in [
        (0.1, 0.2),
        (0.73, 0.41),
        (1.37, -0.62),
        (-2.05, 3.9),
        (0.5, 0.5),
        (4.49, 0.02),
    ]
    .into_iter()
    .enumerate()
    {
        let at = At::uv(u, v);
        out.push(at);
        out.push(at.duv(0.01 * (i + 1) as f32, 0.002, -0.003, 0.02 * i as f32));
    }
    out
}

fn p_points() -> Vec<At> {
    let mut out = Vec::new();
    for (i, p) in [
        [0.3, 1.7, -2.2],
        [12.1, 0.05, 3.3],
        [-4.4, -7.25, 0.6],
        [0.5, 0.5, 0.5],
        [101.3, -55.5, 7.77],
    ]
    .into_iter()
    .enumerate()
    {
        let at = At::p(p[0], p[1], p[2]);
        out.push(at);
        let s = 0.02 * (i + 1) as f32;
        out.push(at.dp(Vec3::new(s, 0.0, 0.3 * s), Vec3::new(0.0, 2.0 * s, 0.0)));
        // A footprint so large that no octave survives.
        out.push(at.dp(Vec3::new(3.0, 0.0, 0.0), Vec3::ZERO));
    }
    out
}

fn eval_f(t: &FloatTex, at: &At) -> f64 {
    t.eval(&at.sc()) as f64
}

fn eval_s(t: &SpectrumTex, at: &At) -> Vec3 {
    t.eval(&at.sc())
}

fn fract(x: f64) -> f64 {
    x - x.floor()
}

// ---------------------------------------------------------------- cases

fn case_constant() {
    let f = float_tex("Texture \"t\" \"float\" \"constant\" \"float value\" 2.5");
    assert_eq!(f.as_constant(), Some(2.5));
    let s = spectrum_tex("Texture \"t\" \"color\" \"constant\" \"rgb value\" [0.1 0.2 0.3]");
    assert_eq!(s.as_constant(), Some(Vec3::new(0.1, 0.2, 0.3)));
    let d = spectrum_tex("Texture \"t\" \"color\" \"constant\"");
    assert_eq!(
        d.as_constant(),
        Some(Vec3::ONE),
        "pbrt-v3's default value 1"
    );
}

fn case_scale() {
    // Constants fold to a constant.
    let c = float_tex("Texture \"t\" \"float\" \"scale\" \"float tex1\" 3 \"float tex2\" 0.25");
    assert_eq!(c.as_constant(), Some(0.75));
    let decl = "Texture \"ch\" \"color\" \"checkerboard\" \"string aamode\" \"none\" \"rgb tex1\" [1 2 3] \"rgb tex2\" [4 5 6]\nTexture \"t\" \"color\" \"scale\" \"texture tex1\" \"ch\" \"rgb tex2\" [0.5 2 1]";
    let t = spectrum_tex(decl);
    assert!(t.as_constant().is_none());
    for at in uv_points() {
        let (u, v) = (at.geom.uv.x as f64, at.geom.uv.y as f64);
        let even = (u.floor() + v.floor()).rem_euclid(2.0) == 0.0;
        let ch = if even {
            [1.0, 2.0, 3.0]
        } else {
            [4.0, 5.0, 6.0]
        };
        assert_close3(
            eval_s(&t, &at),
            [ch[0] * 0.5, ch[1] * 2.0, ch[2]],
            1e-6,
            "scale",
        );
    }
    // A spectrum scale reads its factors as spectra: pbrt-v3 ignores a
    // "float tex2" (and says so).
    let (t, w) = spectrum_tex_with(
        "Texture \"t\" \"color\" \"scale\" \"rgb tex1\" [2 2 2] \"float tex2\" 5",
        &MemFiles::default(),
    );
    assert_eq!(t.as_constant(), Some(Vec3::splat(2.0)));
    assert!(w.contains("\"float tex2\" not used"), "{w}");
}

fn case_mix() {
    let decl = "Texture \"a\" \"float\" \"bilerp\" \"float v00\" 0 \"float v10\" 1 \"float v01\" 0 \"float v11\" 1\nTexture \"ch\" \"float\" \"checkerboard\" \"string aamode\" \"none\"\nTexture \"t\" \"float\" \"mix\" \"texture tex1\" \"ch\" \"float tex2\" 3 \"texture amount\" \"a\"";
    let t = float_tex(decl);
    for at in uv_points() {
        let (u, v) = (at.geom.uv.x as f64, at.geom.uv.y as f64);
        let ch = if (u.floor() + v.floor()).rem_euclid(2.0) == 0.0 {
            1.0
        } else {
            0.0
        };
        let amount = u; // the bilerp ramp
        assert_close(
            eval_f(&t, &at),
            (1.0 - amount) * ch + amount * 3.0,
            1e-5,
            "mix",
        );
    }
    let c = spectrum_tex("Texture \"t\" \"color\" \"mix\" \"float amount\" 0.25");
    assert_eq!(
        c.as_constant(),
        Some(Vec3::splat(0.25)),
        "defaults 0 and 1 at amount 0.25, folded"
    );
}

fn case_bilerp() {
    let t = spectrum_tex("Texture \"t\" \"color\" \"bilerp\" \"rgb v00\" [1 0 0] \"rgb v01\" [0 1 0] \"rgb v10\" [0 0 1] \"rgb v11\" [1 1 1] \"float uscale\" 2 \"float vdelta\" 0.5");
    for at in uv_points() {
        let (s, tt) = (2.0 * at.geom.uv.x as f64, at.geom.uv.y as f64 + 0.5);
        let w = [
            (1.0 - s) * (1.0 - tt),
            (1.0 - s) * tt,
            s * (1.0 - tt),
            s * tt,
        ];
        let v = [
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 1.0, 1.0],
        ];
        let e = [0, 1, 2].map(|c| (0..4).map(|k| w[k] * v[k][c]).sum::<f64>());
        assert_close3(eval_s(&t, &at), e, 1e-5, "bilerp");
    }
    let f = float_tex("Texture \"t\" \"float\" \"bilerp\"");
    // pbrt-v3's defaults: 0, 1, 0, 1 (the value is t).
    assert_close(eval_f(&f, &At::uv(0.3, 0.8)), 0.8, 1e-6, "bilerp defaults");
}

const PNG_PIXELS: [[u8; 3]; 8] = [
    [10, 20, 30],
    [40, 50, 60],
    [70, 80, 90],
    [100, 110, 120],
    [130, 140, 150],
    [160, 170, 180],
    [190, 200, 210],
    [220, 230, 240],
];

fn image_files() -> MemFiles {
    let mut f = MemFiles::default();
    f.0.insert(dir().join("img.png"), png(4, 2, &PNG_PIXELS));
    let hdr: Vec<[f32; 3]> = (0..6)
        .map(|i| [i as f32 * 1.5, 10.0 - i as f32, 0.25 * i as f32])
        .collect();
    f.0.insert(dir().join("img.pfm"), pfm(3, 2, &hdr));
    f
}

/// The MIP map of an image texture handle.
fn mip_of<T>(t: &Tex<T>) -> *const () {
    match t {
        Tex::Texture(t) => match &t.class {
            Class::ImageMap(m) => std::sync::Arc::as_ptr(&m.mip) as *const (),
            _ => panic!("not an image texture"),
        },
        Tex::Constant(_) => panic!("a constant"),
    }
}

fn case_imagemap() {
    let files = image_files();
    // At texel centres without differentials every lookup is the texel:
    // sRGB-decoded (the default for .png), t = 0 at the image's bottom row.
    for filter in ["", "\"bool trilinear\" \"true\""] {
        let (t, w) = spectrum_tex_with(
            &format!(
                "Texture \"t\" \"color\" \"imagemap\" \"string filename\" \"img.png\" {filter}"
            ),
            &files,
        );
        assert!(w.is_empty(), "{w}");
        for ti in 0..2 {
            for si in 0..4 {
                let at = At::uv((si as f32 + 0.5) / 4.0, (ti as f32 + 0.5) / 2.0);
                let px = PNG_PIXELS[(1 - ti) * 4 + si];
                let e = px.map(|c| srgb_decode(c as f64 / 255.0));
                assert_close3(eval_s(&t, &at), e, 1e-5, "imagemap texel");
            }
        }
    }
    // Float: the luminance of the raw texels, then decoded; scale after.
    let (f, _) = float_tex_with(
        "Texture \"t\" \"float\" \"imagemap\" \"string filename\" \"img.png\" \"float scale\" 2",
        &files,
    );
    let px = PNG_PIXELS[4 + 2];
    let lum = luminance(px.map(|c| c as f64 / 255.0));
    assert_close(
        eval_f(&f, &At::uv(2.5 / 4.0, 0.25)),
        2.0 * srgb_decode(lum),
        1e-5,
        "float imagemap",
    );
    // gamma false: raw values.
    let (g, _) = spectrum_tex_with(
        "Texture \"t\" \"color\" \"imagemap\" \"string filename\" \"img.png\" \"bool gamma\" \"false\"",
        &files,
    );
    let px = PNG_PIXELS[1];
    assert_close3(
        eval_s(&g, &At::uv(1.5 / 4.0, 0.75)),
        px.map(|c| c as f64 / 255.0),
        1e-6,
        "gamma false",
    );
    // Wrap modes one texel left of the image (texel -1 of the bottom row).
    let left = At::uv(-0.5 / 4.0, 0.25);
    for (wrap, expect) in [
        ("repeat", Some(PNG_PIXELS[7])),
        ("clamp", Some(PNG_PIXELS[4])),
        ("black", None),
    ] {
        let (t, _) = spectrum_tex_with(
            &format!("Texture \"t\" \"color\" \"imagemap\" \"string filename\" \"img.png\" \"string wrap\" \"{wrap}\""),
            &files,
        );
        let e = match expect {
            Some(px) => px.map(|c| srgb_decode(c as f64 / 255.0)),
            None => [0.0; 3],
        };
        assert_close3(eval_s(&t, &left), e, 1e-5, wrap);
    }
    // A float image (PFM: linear, no decoding) of a size that is not a
    // power of two: resampled to 4×2, so the values are those of the
    // resampled image, still positive and of the same mean within the
    // Lanczos overshoot.
    let (h, w) = spectrum_tex_with(
        "Texture \"t\" \"color\" \"imagemap\" \"string filename\" \"img.pfm\"",
        &files,
    );
    assert!(w.is_empty(), "{w}");
    let v = eval_s(&h, &At::uv(0.5, 0.5));
    assert!(v.min_element() >= 0.0 && v.x > 1.0, "{v}");
    // One MIP map for textures with the same file and settings, another
    // for other settings.
    let s = load(
        "WorldBegin\nTexture \"a\" \"color\" \"imagemap\" \"string filename\" \"img.png\"\nTexture \"b\" \"color\" \"imagemap\" \"string filename\" \"img.png\"\nTexture \"c\" \"color\" \"imagemap\" \"string filename\" \"img.png\" \"float scale\" 2\nMaterial \"matte\" \"texture Kd\" \"a\"\nShape \"sphere\"\nMaterial \"matte\" \"texture Kd\" \"b\"\nShape \"sphere\"\nMaterial \"matte\" \"texture Kd\" \"c\"\nShape \"sphere\"\nWorldEnd",
        &files,
    );
    let kd = |i: usize| s.scene.materials[i].params.spectrum_tex("Kd").unwrap();
    assert_eq!(mip_of(&kd(0)), mip_of(&kd(1)), "same file and settings");
    assert_ne!(mip_of(&kd(0)), mip_of(&kd(2)), "another scale");
}

fn case_uv() {
    let t = spectrum_tex("Texture \"t\" \"color\" \"uv\" \"float uscale\" 2 \"float vscale\" 3 \"float udelta\" 0.1 \"float vdelta\" -0.2");
    for at in uv_points() {
        let (u, v) = (at.geom.uv.x as f64, at.geom.uv.y as f64);
        assert_close3(
            eval_s(&t, &at),
            [fract(2.0 * u + 0.1), fract(3.0 * v - 0.2), 0.0],
            1e-5,
            "uv",
        );
    }
    let (_, w) = float_tex_with(
        "Texture \"t\" \"float\" \"uv\"\nTexture \"t\" \"float\" \"constant\"",
        &MemFiles::default(),
    );
    assert!(
        w.contains("pbrt-v3 has no float texture of class \"uv\""),
        "{w}"
    );
}

/// The box-filtered checkerboard by brute force: the mean of tex2's
/// indicator over [s ± ds] × [t ± dt], on a fine grid.
fn box_filtered_odd(s: f64, t: f64, ds: f64, dt: f64) -> f64 {
    let n = 800;
    let mut odd = 0usize;
    for i in 0..n {
        for j in 0..n {
            let x = s - ds + 2.0 * ds * (i as f64 + 0.5) / n as f64;
            let y = t - dt + 2.0 * dt * (j as f64 + 0.5) / n as f64;
            odd += usize::from((x.floor() + y.floor()).rem_euclid(2.0) == 1.0);
        }
    }
    odd as f64 / (n * n) as f64
}

fn case_checkerboard() {
    // Point sampled.
    let none = float_tex("Texture \"t\" \"float\" \"checkerboard\" \"string aamode\" \"none\" \"float tex1\" 2 \"float tex2\" -1");
    for at in uv_points() {
        let (u, v) = (at.geom.uv.x as f64, at.geom.uv.y as f64);
        let e = if (u.floor() + v.floor()).rem_euclid(2.0) == 0.0 {
            2.0
        } else {
            -1.0
        };
        assert_eq!(eval_f(&none, &at), e, "{at:?}");
    }
    // Closed form against brute-force box filtering, for footprints that
    // straddle check edges.
    let cf = float_tex("Texture \"t\" \"float\" \"checkerboard\"");
    for (u, v, ds, dt) in [
        (0.95, 0.5, 0.2, 0.1),
        (1.1, 2.93, 0.35, 0.3),
        (-0.02, -0.97, 0.5, 0.08),
        (3.5, 3.5, 0.7, 0.9),
    ] {
        let at = At::uv(u, v).duv(ds, 0.0, 0.0, dt);
        let odd = box_filtered_odd(u as f64, v as f64, ds as f64, dt as f64);
        // tex1 = 1 on even checks, tex2 = 0 on odd ones.
        assert_close(
            eval_f(&cf, &at),
            1.0 - odd,
            3e-3,
            "closed-form checkerboard",
        );
    }
    // Footprints wider than a check: pbrt-v3 returns the average.
    let wide = At::uv(0.3, 0.3).duv(1.5, 0.0, 0.0, 0.2);
    assert_eq!(eval_f(&cf, &wide), 0.5);
    // 3D: cubes of the statement's transform applied to the point (pbrt-v3
    // applies the CTM itself, see mapping.rs).
    let c3 = spectrum_tex("Scale 0.5 0.5 0.5\nTexture \"t\" \"color\" \"checkerboard\" \"integer dimension\" 3 \"rgb tex1\" [1 0 0] \"rgb tex2\" [0 1 0]");
    for at in p_points() {
        let p = v3(at.hit.point.p).map(|c| (0.5 * c).floor());
        let even = (p[0] + p[1] + p[2]).rem_euclid(2.0) == 0.0;
        let e = if even {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 1.0, 0.0]
        };
        assert_close3(eval_s(&c3, &at), e, 0.0, "3D checkerboard");
    }
}

/// pbrt-v3's dot test in f64.
fn in_dot(s: f64, t: f64) -> bool {
    let (sc, tc) = ((s + 0.5).floor(), (t + 0.5).floor());
    if noise(sc + 0.5, tc + 0.5, 0.5) > 0.0 {
        let r = 0.35;
        let shift = 0.5 - r;
        let cs = sc + shift * noise(sc + 1.5, tc + 2.8, 0.5);
        let ct = tc + shift * noise(sc + 4.5, tc + 9.8, 0.5);
        return (s - cs).powi(2) + (t - ct).powi(2) < r * r;
    }
    false
}

fn case_dots() {
    let t = float_tex("Texture \"t\" \"float\" \"dots\" \"float inside\" 7 \"float outside\" 3 \"float uscale\" 1.5");
    let (mut dots, mut rest) = (0, 0);
    for i in 0..60 {
        for j in 0..60 {
            let (u, v) = (i as f64 * 0.113 - 2.0, j as f64 * 0.097 - 1.0);
            // Stay clear of the dots' edges, where f32 and f64 may differ.
            let d = in_dot(1.5 * u, v);
            let at = At::uv(u as f32, v as f32);
            let got = eval_f(&t, &at);
            // pbrt-v3 shows "outside" in the dots (its constructor's
            // arguments are swapped).
            let e = if d { 3.0 } else { 7.0 };
            if got != e {
                let near_edge = (-4..=4).any(|k| {
                    let eps = k as f64 * 2e-6;
                    in_dot(1.5 * u + eps, v + eps) != d
                });
                assert!(near_edge, "dots at ({u}, {v}): {got} vs {e}");
            }
            if d {
                dots += 1;
            } else {
                rest += 1;
            }
        }
    }
    assert!(dots > 200 && rest > 200, "{dots} in dots, {rest} outside");
}

fn case_fbm() {
    let t =
        float_tex("Texture \"t\" \"float\" \"fbm\" \"integer octaves\" 6 \"float roughness\" 0.6");
    for at in p_points() {
        let e = fbm(
            v3(at.hit.point.p),
            v3(at.geom.dpdx),
            v3(at.geom.dpdy),
            0.6,
            6,
        );
        assert_close(eval_f(&t, &at), e, 2e-4, &format!("fbm at {at:?}"));
    }
    // The statement's transform scales the point (CTM applied, as pbrt-v3).
    let s = spectrum_tex("Scale 2 2 2\nTexture \"t\" \"color\" \"fbm\"");
    let at = At::p(0.3, 1.7, -2.2);
    let e = fbm(v3(2.0 * at.hit.point.p), [0.0; 3], [0.0; 3], 0.5, 8);
    assert_close3(eval_s(&s, &at), [e; 3], 2e-4, "spectrum fbm");
}

fn case_wrinkled() {
    let t = float_tex(
        "Texture \"t\" \"float\" \"wrinkled\" \"integer octaves\" 5 \"float roughness\" 0.4",
    );
    for at in p_points() {
        let e = turbulence(
            v3(at.hit.point.p),
            v3(at.geom.dpdx),
            v3(at.geom.dpdy),
            0.4,
            5,
        );
        assert_close(eval_f(&t, &at), e, 2e-4, &format!("wrinkled at {at:?}"));
    }
}

fn case_windy() {
    let t = float_tex("Texture \"t\" \"float\" \"windy\"");
    for at in p_points() {
        let (p, dx, dy) = (v3(at.hit.point.p), v3(at.geom.dpdx), v3(at.geom.dpdy));
        let s = |v: [f64; 3]| v.map(|c| 0.1 * c);
        let e = fbm(s(p), s(dx), s(dy), 0.5, 3).abs() * fbm(p, dx, dy, 0.5, 6);
        assert_close(eval_f(&t, &at), e, 2e-4, &format!("windy at {at:?}"));
    }
}

/// pbrt-v3's marble colour spline in f64 (only its first two segments are
/// reachable: the segment index is min(1, ⌊6t⌋)).
fn marble_spline(t: f64) -> [f64; 3] {
    const C: [[f64; 3]; 9] = [
        [0.58, 0.58, 0.6],
        [0.58, 0.58, 0.6],
        [0.58, 0.58, 0.6],
        [0.5, 0.5, 0.5],
        [0.6, 0.59, 0.58],
        [0.58, 0.58, 0.6],
        [0.58, 0.58, 0.6],
        [0.2, 0.2, 0.33],
        [0.58, 0.58, 0.6],
    ];
    let first = ((t * 6.0).floor() as usize).min(1);
    let x = t * 6.0 - first as f64;
    // Bernstein form of the cubic Bézier.
    let b = [
        (1.0 - x).powi(3),
        3.0 * x * (1.0 - x).powi(2),
        3.0 * x * x * (1.0 - x),
        x.powi(3),
    ];
    [0, 1, 2].map(|c| 1.5 * (0..4).map(|k| b[k] * C[first + k][c]).sum::<f64>())
}

fn case_marble() {
    let t = spectrum_tex("Texture \"t\" \"color\" \"marble\" \"float scale\" 2.5 \"float variation\" 0.7 \"integer octaves\" 4 \"float roughness\" 0.45");
    for at in p_points() {
        let p = v3(at.hit.point.p).map(|c| 2.5 * c);
        let dx = v3(at.geom.dpdx).map(|c| 2.5 * c);
        let dy = v3(at.geom.dpdy).map(|c| 2.5 * c);
        let m = p[1] + 0.7 * fbm(p, dx, dy, 0.45, 4);
        let e = marble_spline(0.5 + 0.5 * m.sin());
        // The spline amplifies errors (its parameter reaches 5): a little
        // more room than the noise textures.
        assert_close3(eval_s(&t, &at), e, 2e-3, &format!("marble at {at:?}"));
    }
    let (_, w) = float_tex_with(
        "Texture \"t\" \"float\" \"marble\"\nTexture \"t\" \"float\" \"constant\"",
        &MemFiles::default(),
    );
    assert!(w.contains("no float texture of class \"marble\""), "{w}");
}

fn case_ptex() {
    let (t, w) = spectrum_tex_with(
        "Texture \"t\" \"color\" \"ptex\" \"string filename\" \"face.ptx\"",
        &MemFiles::default(),
    );
    // pbrt-v3: an unreadable Ptex file gives a texture of 0 (`T{}`).
    assert_eq!(t.as_constant(), Some(Vec3::ZERO));
    assert!(
        w.contains("cannot read Ptex file \"/mem/face.ptx\"")
            && w.contains("a constant 0 (black) texture is used instead"),
        "{w}"
    );
}

// ---------------------------------------------------------------- mappings

#[test]
fn spherical_mapping_uses_the_inverse_texture_transform() {
    let decl = "Translate 1 2 3\nTexture \"t\" \"color\" \"uv\" \"string mapping\" \"spherical\"";
    let t = spectrum_tex(decl);
    for p in [
        [1.5, 2.2, 3.9],
        [0.1, 2.0, 2.5],
        [1.0, 1.0, 3.0],
        [3.0, 5.0, -1.0],
    ] {
        let at = At::p(p[0], p[1], p[2]);
        let d = [p[0] as f64 - 1.0, p[1] as f64 - 2.0, p[2] as f64 - 3.0];
        let r = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        let theta = (d[2] / r).acos();
        let phi = d[1].atan2(d[0]).rem_euclid(2.0 * PI);
        let e = [fract(theta / PI), fract(phi / (2.0 * PI))];
        let v = eval_s(&t, &at);
        assert_close(v.x as f64, e[0], 1e-5, "spherical s");
        assert_close(v.y as f64, e[1], 1e-5, "spherical t");
    }
}

#[test]
fn cylindrical_and_planar_mappings() {
    let cyl = spectrum_tex(
        "Rotate 90 1 0 0\nTexture \"t\" \"color\" \"uv\" \"string mapping\" \"cylindrical\"",
    );
    // Rotate 90 about x maps texture (x, y, z) to world (x, -z, y); its
    // inverse maps world (x, y, z) to texture (x, z, -y).
    for p in [[0.5, 0.2, 0.7], [-1.0, 0.4, 0.1], [0.3, -0.9, -0.6]] {
        let q = [p[0] as f64, p[2] as f64, -p[1] as f64];
        let r = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
        let e = [fract((PI + q[1].atan2(q[0])) / (2.0 * PI)), fract(q[2] / r)];
        let v = eval_s(&cyl, &At::p(p[0], p[1], p[2]));
        assert_close(v.x as f64, e[0], 1e-5, "cylindrical s");
        assert_close(v.y as f64, e[1], 1e-5, "cylindrical t");
    }
    // Planar: world p (pbrt-v3 ignores the transform here).
    let pl = spectrum_tex("Translate 5 5 5\nTexture \"t\" \"color\" \"uv\" \"string mapping\" \"planar\" \"vector v1\" [0.5 0 0.5] \"vector v2\" [0 -1 0] \"float udelta\" 0.25 \"float vdelta\" 3");
    for p in [[0.2, -0.3, 0.4], [1.7, 0.1, -2.2]] {
        let e = [
            fract(0.25 + 0.5 * p[0] as f64 + 0.5 * p[2] as f64),
            fract(3.0 - p[1] as f64),
        ];
        let v = eval_s(&pl, &At::p(p[0], p[1], p[2]));
        assert_close(v.x as f64, e[0], 1e-5, "planar s");
        assert_close(v.y as f64, e[1], 1e-5, "planar t");
    }
}

#[test]
fn mapping_differentials() {
    let at = At::new(Vec3::new(0.3, 0.4, 0.5), Vec2::new(0.2, 0.7))
        .duv(0.01, 0.02, -0.03, 0.04)
        .dp(Vec3::new(0.01, 0.0, -0.02), Vec3::new(0.0, 0.015, 0.005));
    let uv = Mapping2D::Uv {
        su: 2.0,
        sv: -3.0,
        du: 0.5,
        dv: 0.25,
    };
    let (st, dx, dy) = uv.map(&at.sc());
    assert!((st - Vec2::new(0.9, -1.85)).length() < 1e-6);
    assert!((dx - Vec2::new(0.02, -0.06)).length() < 1e-7);
    assert!((dy - Vec2::new(-0.06, -0.12)).length() < 1e-7);
    let planar = Mapping2D::Planar {
        vs: Vec3::new(1.0, 2.0, 0.0),
        vt: Vec3::new(0.0, 0.0, 1.0),
        ds: 0.0,
        dt: 0.0,
    };
    let (_, dx, dy) = planar.map(&at.sc());
    assert!((dx - Vec2::new(0.01, -0.02)).length() < 1e-7);
    assert!((dy - Vec2::new(0.03, 0.005)).length() < 1e-7);
    // Spherical: pbrt-v3's forward difference with step 0.1 (f64 here).
    let sph = Mapping2D::spherical(DMat4::IDENTITY);
    let (st, dx, _) = sph.map(&at.sc());
    let f = |p: [f64; 3]| {
        let r = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        [
            (p[2] / r).acos() / PI,
            p[1].atan2(p[0]).rem_euclid(2.0 * PI) / (2.0 * PI),
        ]
    };
    let p = v3(at.hit.point.p);
    let q = [p[0] + 0.1 * 0.01, p[1], p[2] - 0.1 * 0.02];
    let (a, b) = (f(p), f(q));
    assert_close(st.x as f64, a[0], 1e-6, "spherical st");
    assert_close(dx.x as f64, (b[0] - a[0]) / 0.1, 1e-3, "spherical ds/dx");
    assert_close(dx.y as f64, (b[1] - a[1]) / 0.1, 1e-3, "spherical dt/dx");
}

// ---------------------------------------------------------------- bad input

#[test]
fn bad_texture_input_warns_with_locations() {
    let f = image_files();
    let s = load(
        "WorldBegin\nTexture \"a\" \"float\" \"checkerbord\"\nTexture \"b\" \"float\" \"checkerboard\" \"integer dimension\" 4\nTexture \"c\" \"color\" \"checkerboard\" \"string aamode\" \"closedfrom\"\nTexture \"d\" \"color\" \"imagemap\" \"string filename\" \"img.png\" \"string wrap\" \"mirror\" \"string filter\" \"bilinear\"\nTexture \"e\" \"color\" \"uv\" \"string mapping\" \"spherica\"\nTexture \"g\" \"colour\" \"constant\"\nMaterial \"matte\" \"texture Kd\" \"b\" \"texture sigma\" \"c\"\nShape \"sphere\"\nWorldEnd",
        &f,
    );
    let w = warnings(&s);
    for expect in [
        "t.pbrt:2:21: unknown texture class \"checkerbord\" (did you mean \"checkerboard\"?)",
        "t.pbrt:3:21: texture \"b\": 4 dimensional checkerboard texture not supported",
        "\"aamode\" is \"closedfrom\", which pbrt-v3 does not know (did you mean \"closedform\"?): \"closedform\" is used",
        "\"wrap\" is \"mirror\", which pbrt-v3 does not know",
        "\"filter\" is a pbrt-v4 parameter",
        "2D texture mapping \"spherica\" unknown (did you mean \"spherical\"?)",
        "texture type \"colour\" is neither",
        "unknown spectrum texture \"b\" for \"Kd\"",
        "unknown float texture \"c\" for \"sigma\" (\"c\" is a spectrum texture)",
    ] {
        assert!(w.contains(expect), "missing \"{expect}\" in:\n{w}");
    }
    // An image that cannot be read, missing or corrupt: a warning naming the
    // file and the substitute, pbrt-v3's constant grey (an error with
    // --strict).
    let mut bad = MemFiles::default();
    bad.0.insert(
        dir().join("bad.png"),
        b"\x89PNG\r\n\x1a\nnot really".to_vec(),
    );
    for file in ["nothere.png", "bad.png"] {
        let s = load(
            &format!("WorldBegin\nTexture \"t\" \"color\" \"imagemap\" \"string filename\" \"{file}\"\nWorldEnd"),
            &bad,
        );
        let w = warnings(&s);
        assert!(
            w.contains(file) && w.contains("a constant grey texture (0.5) is used instead"),
            "{w}"
        );
        assert!(pbrs::loader::strictly(vec![s]).is_err());
    }
}

/// Every class, both types, with every parameter given a value of every
/// type, odd numbers included: loading must not panic, and what loads must
/// evaluate to finite or at least non-panicking values.
#[test]
fn garbage_parameters_never_panic() {
    let files = image_files();
    let values = [
        "\"float {}\" -1e30",
        "\"float {}\" 0",
        "\"integer {}\" -2147483648",
        "\"integer {}\" 1000000",
        "\"string {}\" \"\"",
        "\"string {}\" \"img.png\"",
        "\"bool {}\" \"true\"",
        "\"rgb {}\" [-1 1e38 0]",
        "\"texture {}\" \"nope\"",
        "\"vector {}\" [0 0 0]",
        "\"float {}\" [1 2 3]",
    ];
    for class in TEXTURES {
        for ty in ["float", "color"] {
            for v in values {
                let mut params = String::new();
                for p in class.params {
                    params += &v.replace("{}", p.name);
                    params.push(' ');
                }
                for m in ["mapping", "uscale", "v1", "udelta"] {
                    params += &v.replace("{}", m);
                    params.push(' ');
                }
                let text = format!(
                    "WorldBegin\nTexture \"t\" \"{ty}\" \"{}\" {params}\nMaterial \"matte\" \"texture Kd\" \"t\" \"texture sigma\" \"t\"\nShape \"sphere\"\nWorldEnd",
                    class.name
                );
                if let Ok(s) = try_load(&text, &files) {
                    let m = &s.scene.materials[0].params;
                    for at in uv_points().into_iter().chain(p_points()) {
                        let _ = m.spectrum_tex("Kd").unwrap().eval(&at.sc());
                        let _ = m.float_tex("sigma").unwrap().eval(&at.sc());
                    }
                }
            }
        }
    }
}

#[test]
fn reference_documents_every_texture_class() {
    let reference = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("grammar/REFERENCE.md"),
    )
    .unwrap();
    let start = reference.find("## Textures").expect("a Textures section");
    let section = &reference[start..];
    let section = &section[..section[3..].find("\n## ").map_or(section.len(), |e| e + 3)];
    for class in TEXTURES {
        assert!(
            section.contains(&format!("`{}`", class.name)),
            "REFERENCE.md's Textures section lacks `{}`",
            class.name
        );
        for p in class.params {
            assert!(
                section.contains(&format!("`{}`", p.name)),
                "REFERENCE.md lacks `{}` of `{}`",
                p.name,
                class.name
            );
        }
    }
}
