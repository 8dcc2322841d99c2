//! `ptex` textures: the reader against the Ptex library (texels of every
//! face and B-spline lookups as pbrt-v3 makes them, printed by
//! `tests/inputs/ptex/gen.cpp` into `lookups.txt` from the files it wrote),
//! pbrs's render of `scenes/textures-ptex` against pbrt-v3's, and malformed
//! files: a located warning naming the file and a black texture (an error
//! under `--strict`), never a panic or an unbounded allocation.

mod common;
mod tex_common;

use common::*;
use pbrs::textures::ptex_file::{FaceDataRef, PtexFile, Res};
use pbrs::textures::ptex_filter::BicubicFilter;
use std::path::PathBuf;
use tex_common::{warnings, MemFiles};

const STEM: &str = "textures-ptex";
const SCENE: &str = "scenes/textures-ptex/textures-ptex.pbrt";

fn inputs() -> PathBuf {
    repo().join("tests/inputs/ptex")
}

fn open(name: &str) -> PtexFile {
    let bytes = std::fs::read(inputs().join(name)).expect("test file");
    PtexFile::parse(&bytes).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The lines of `lookups.txt` of one kind: file name and numbers.
fn expected(kind: &str) -> Vec<(String, Vec<f64>)> {
    let text = std::fs::read_to_string(inputs().join("lookups.txt")).expect("lookups.txt");
    text.lines()
        .filter_map(|l| {
            let mut w = l.split_whitespace();
            (w.next()? == kind).then(|| {
                let file = w.next().unwrap().to_string();
                (file, w.map(|x| x.parse().expect("number")).collect())
            })
        })
        .collect()
}

#[test]
fn texels_equal_the_ptex_library_s() {
    let lines = expected("pixel");
    assert!(lines.len() >= 30);
    for (name, v) in &lines {
        let f = open(name);
        let (face, x, y) = (v[0] as i32, v[1] as i32, v[2] as i32);
        let info = f.faces[face as usize];
        let px: Vec<f32> = match f.data(face, info.res).expect("face data") {
            FaceDataRef::Constant(p) => p.to_vec(),
            FaceDataRef::Packed(r, t) => {
                let i = ((y * r.u() + x) as usize) * f.nchannels;
                t[i..i + f.nchannels].to_vec()
            }
        };
        let one = 1.0 / f.data_type.one();
        for (c, &e) in v[3..].iter().enumerate() {
            let got = (px[c] * one) as f64;
            assert!(
                (got - e).abs() <= 1e-7 * e.abs().max(1.0),
                "{name} face {face} texel ({x}, {y}) channel {c}: {got} vs {e}"
            );
        }
    }
}

#[test]
fn bspline_lookups_equal_the_ptex_library_s() {
    let lines = expected("eval");
    assert!(lines.len() > 500);
    let filter = BicubicFilter::new(0.0);
    let mut worst = 0.0f64;
    for (name, v) in &lines {
        let f = open(name);
        let r = filter.eval(
            &f,
            v[0] as i32,
            v[1] as f32,
            v[2] as f32,
            v[3] as f32,
            v[4] as f32,
            v[5] as f32,
            v[6] as f32,
        );
        for (c, &e) in v[7..].iter().enumerate() {
            let err = (r[c] as f64 - e).abs() / e.abs().max(1.0);
            worst = worst.max(err);
            assert!(
                err <= 2e-6,
                "{name} lookup {:?}: channel {c} is {} where the Ptex library gives {e}",
                &v[..7],
                r[c]
            );
        }
    }
    eprintln!(
        "{} lookups, largest relative difference {worst:.2e}",
        lines.len()
    );
}

#[test]
fn the_file_s_structure_is_read() {
    let f = open("rgb8.ptx");
    assert_eq!((f.nchannels, f.faces.len(), f.triangles), (3, 4, false));
    assert_eq!(f.faces[2].res, Res::new(8, 8));
    assert!(f.faces[3].is_constant());
    assert_eq!(f.faces[0].adjface(1), 1);
    assert_eq!(f.faces[0].adjedge(1), 3);
    let g = open("gray16f.ptx");
    assert_eq!((g.nchannels, g.data_type.one()), (1, 1.0));
    let e = open("ell8.ptx");
    assert_eq!(
        (e.u_border, e.v_border),
        (
            pbrs::textures::ptex_file::BorderMode::Black,
            pbrs::textures::ptex_file::BorderMode::Periodic
        )
    );
}

#[test]
fn render_matches_pbrt() {
    let d = load(SCENE);
    let (w, h) = (d.film.xresolution, d.film.yresolution);
    assert_eq!((w, h), (96, 64));
    let (img, stats) = render_seeded_wh(d, w, h, 64, 0);
    assert_eq!(stats.dropped_samples(), 0);
    assert_matches(STEM, &img, &reference(STEM), Bounds::against_pbrt(STEM));
}

/// A scene with a `ptex` texture of the file `bytes` on a quad.
fn scene_with(bytes: Option<Vec<u8>>) -> (String, MemFiles) {
    let mut files = MemFiles::default();
    if let Some(b) = bytes {
        files.0.insert(tex_common::dir().join("t.ptx"), b);
    }
    let text = "WorldBegin\nTexture \"t\" \"spectrum\" \"ptex\" \"string filename\" \"t.ptx\"\nMaterial \"matte\" \"texture Kd\" \"t\"\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 1 1 0 0 1 0] \"integer indices\" [0 1 2 0 2 3] \"integer faceIndices\" [0 1]\nWorldEnd\n".to_string();
    (text, files)
}

/// What loading a scene with that file says; panics if it fails to load.
fn warning_for(bytes: Option<Vec<u8>>) -> String {
    let (text, files) = scene_with(bytes);
    let s = tex_common::load(&text, &files);
    warnings(&s)
}

fn valid() -> Vec<u8> {
    std::fs::read(inputs().join("rgb8.ptx")).unwrap()
}

#[test]
fn malformed_files_warn_naming_the_file() {
    let cases: Vec<(&str, Option<Vec<u8>>, &str)> = vec![
        ("missing", None, "no such file"),
        ("empty", Some(vec![]), "not a Ptex file"),
        (
            "bad magic",
            Some({
                let mut b = valid();
                b[0] = b'X';
                b
            }),
            "no \"Ptex\" magic",
        ),
        ("truncated", Some(valid()[..200].to_vec()), ""),
        (
            "huge face count",
            Some({
                let mut b = valid();
                b[24..28].copy_from_slice(&u32::MAX.to_le_bytes());
                b
            }),
            "face info",
        ),
        (
            "huge level count",
            Some({
                let mut b = valid();
                b[22..24].copy_from_slice(&u16::MAX.to_le_bytes());
                b
            }),
            "resolution levels",
        ),
        (
            "huge channel count",
            Some({
                let mut b = valid();
                b[20..22].copy_from_slice(&u16::MAX.to_le_bytes());
                b
            }),
            "channels",
        ),
        (
            "huge level data",
            Some({
                let mut b = valid();
                b[48..56].copy_from_slice(&u64::MAX.to_le_bytes());
                b
            }),
            "out of range",
        ),
        (
            "huge header size",
            Some({
                let mut b = valid();
                b[28..32].copy_from_slice(&u32::MAX.to_le_bytes());
                b
            }),
            "ends early",
        ),
        (
            "version",
            Some({
                let mut b = valid();
                b[4] = 7;
                b
            }),
            "version",
        ),
    ];
    for (what, bytes, says) in cases {
        let w = warning_for(bytes);
        assert!(
            w.contains("cannot read Ptex file \"/mem/t.ptx\"")
                && w.contains(says)
                && w.contains("a constant 0 (black) texture is used instead")
                && w.contains("t.pbrt:2:"),
            "{what}: {w}"
        );
    }
    // pbrt-v3 takes only 1- and 3-channel files.
    let mut two = valid();
    two[20] = 2;
    let f = PtexFile::parse(&two);
    assert!(f.is_err(), "a 2-channel reading of a 3-channel file's data");
    // --strict: the warning is an error.
    let (text, files) = scene_with(Some(valid()[..100].to_vec()));
    let loaded = tex_common::try_load(&text, &files).expect("loads");
    assert!(pbrs::loader::strictly(vec![loaded]).is_err());
    let (text, files) = scene_with(Some(valid()));
    let loaded = tex_common::try_load(&text, &files).expect("loads");
    assert!(warnings(&loaded).is_empty(), "{}", warnings(&loaded));
    assert!(pbrs::loader::strictly(vec![loaded]).is_ok());
}

/// Every truncation and many corruptions of each test file: an error or
/// a file whose lookups stay finite, never a panic.
#[test]
fn corrupt_files_never_panic() {
    let filter = BicubicFilter::new(0.0);
    let mut rng = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        rng
    };
    for name in ["rgb8.ptx", "gray16f.ptx", "rgb32f.ptx", "ell8.ptx"] {
        let good = std::fs::read(inputs().join(name)).unwrap();
        let mut variants: Vec<Vec<u8>> = (0..good.len())
            .step_by(7)
            .map(|n| good[..n].to_vec())
            .collect();
        for _ in 0..400 {
            let mut b = good.clone();
            for _ in 0..1 + next() % 4 {
                let i = (next() as usize) % b.len();
                b[i] = next() as u8;
            }
            variants.push(b);
        }
        for b in variants {
            let Ok(f) = PtexFile::parse(&b) else { continue };
            for face in -1..f.faces.len() as i32 + 1 {
                for (u, v, d) in [
                    (0.5, 0.5, 0.0),
                    (0.01, 0.99, 0.3),
                    (1.5, -0.2, 0.01),
                    (0.9, 0.1, 4.0),
                ] {
                    let r = filter.eval(&f, face, u, v, d, 0.0, 0.0, d);
                    assert!(r.iter().all(|x| !x.is_nan() || f.data_type.one() == 1.0));
                }
            }
        }
    }
}
