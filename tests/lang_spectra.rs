//! Spectra to RGB as pbrt-v3's RGB build converts them: `spectrum` pairs,
//! spectrum files (`.spd`) and `blackbody`, against the CIE 1931 2° table.
//!
//! The expected RGB values were computed apart from pbrs, in f64 with numpy,
//! from colour-science 0.4.7's copy of the CIE 1931 2° 1 nm table, following
//! pbrt-v3's `RGBSpectrum::FromSampled` (linear interpolation at 360..=830 nm,
//! constant beyond the ends, scale 470 / (106.856895 · 471), pbrt-v3's XYZ→RGB
//! matrix). The same computation with pbrt-v3's own CIE table differs by at
//! most 4e-6, so the tolerance below also accepts pbrt-v3's numbers.

mod common;

use common::warning_text as warnings;
use glam::Vec3;
use pbrs::lang::FileLoader;
use pbrs::loader::{load_scene_str, load_scene_with, LoadedScene};
use std::cell::RefCell;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::rc::Rc;

const TOL: f32 = 1e-5;

fn inputs() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/inputs")
}

/// The matte Kd of a one-sphere scene with `kd` as its Kd parameter.
fn kd_of(s: &LoadedScene) -> Vec3 {
    let m = &s.scene.materials[0];
    assert_eq!(m.kind, "matte", "{m:?}");
    m.constant_spectrum("Kd").unwrap()
}

fn scene(kd: &str) -> String {
    format!("WorldBegin\nMaterial \"matte\" {kd}\nShape \"sphere\"\nWorldEnd\n")
}

/// Loads `text` as if it were `tests/inputs/spectra.pbrt` on disk.
fn load_in_inputs(text: &str) -> LoadedScene {
    load_scene_str(text, &inputs().join("spectra.pbrt")).unwrap_or_else(|f| panic!("{f:?}"))
}

/// Within [`TOL`] of an f64 reference value.
fn close(a: Vec3, b: [f64; 3]) -> bool {
    (0..3).all(|i| (a[i] as f64 - b[i]).abs() < TOL as f64)
}

/// Files in memory; every path asked for is recorded.
struct Memory {
    files: HashMap<PathBuf, Vec<u8>>,
    asked: Rc<RefCell<Vec<PathBuf>>>,
}

impl FileLoader for Memory {
    fn load(&self, path: &Path) -> Result<Vec<u8>, String> {
        self.asked.borrow_mut().push(path.to_path_buf());
        self.files
            .get(path)
            .cloned()
            .ok_or_else(|| "no such file".to_string())
    }
}

/// Loads `text` as `/scene/top.pbrt` with the in-memory `files` (paths
/// relative to `/scene`); returns the scene and the paths read.
fn load_in_memory(text: &str, files: &[(&str, &str)]) -> (LoadedScene, Vec<PathBuf>) {
    let asked = Rc::new(RefCell::new(Vec::new()));
    let loader = Memory {
        files: files
            .iter()
            .map(|(p, t)| (Path::new("/scene").join(p), t.as_bytes().to_vec()))
            .collect(),
        asked: asked.clone(),
    };
    let s = load_scene_with(text, Path::new("/scene/top.pbrt"), Box::new(loader))
        .unwrap_or_else(|f| panic!("{f:?}"));
    let asked = asked.borrow().clone();
    (s, asked)
}

#[test]
fn real_silver_and_copper_files() {
    let cases = [
        ("spds/Ag.eta.spd", [0.15493513, 0.11647543, 0.13808744]),
        ("spds/Ag.k.spd", [4.8180982, 3.1156151, 2.1424006]),
        // pbrt-v3's measured copper (metal.cpp): the metal material's defaults.
        ("spds/Cu.eta.spd", [0.19999061, 0.92208471, 1.0998764]),
        ("spds/Cu.k.spd", [3.9046405, 2.4476304, 2.1376514]),
    ];
    for (file, want) in cases {
        let s = load_in_inputs(&scene(&format!("\"spectrum Kd\" \"{file}\"")));
        assert!(s.warnings.is_empty(), "{file}: {}", warnings(&s));
        let got = kd_of(&s);
        assert!(close(got, want), "{file}: {got} vs {want:?}");
    }
}

#[test]
fn inline_pairs_flat_and_blackbody() {
    let kd = |p: &str| kd_of(&load_in_inputs(&scene(p)));
    // A flat spectrum of 1 (illuminant E) in sRGB; Y is 470/471 of 1.
    let flat = kd("\"spectrum Kd\" [300 1 900 1]");
    assert!(close(flat, [1.2023306, 0.94621414, 0.90733975]), "{flat}");
    // Pairs in any order are sorted (pbrt-v3), interpolated linearly.
    let want = [0.43126247, 0.61965408, 0.45809467];
    let a = kd("\"spectrum Kd\" [400 0.2 500 0.8 600 0.4 700 0.6]");
    let b = kd("\"spectrum Kd\" [600 0.4 400 0.2 700 0.6 500 0.8]");
    assert!(close(a, want), "{a}");
    assert_eq!(a, b);
    // pbrt-v3's normalised blackbody (peak 1) times the scale.
    let warm = kd("\"blackbody Kd\" [2700 1]");
    assert!(close(warm, [0.53349438, 0.22157057, 0.05290183]), "{warm}");
    let d65ish = kd("\"blackbody Kd\" [6500 2]");
    assert!(
        close(d65ish / 2.0, [0.92221984, 0.86949517, 0.91521722]),
        "{d65ish}"
    );
}

#[test]
fn cie_table_is_the_standard_observer() {
    use pbrs::loader::cie1931::{CIE_1931_2DEG, CIE_LAMBDA_MAX, CIE_LAMBDA_MIN};
    use pbrs::loader::color::cie_xyz;
    assert_eq!((CIE_LAMBDA_MIN, CIE_LAMBDA_MAX), (360, 830));
    assert_eq!(CIE_1931_2DEG.len(), 471);
    // Values of the CIE's table at a few wavelengths, and its ȳ peak.
    assert_eq!(cie_xyz(555)[1], 1.0);
    assert_eq!(cie_xyz(600), [1.0622, 0.631, 0.0008]);
    assert_eq!(cie_xyz(450), [0.3362, 0.038, 1.77211]);
    // pbrt-v3's table has 0.9874812 here, two digits swapped.
    assert_eq!(cie_xyz(547)[1], 0.9874182);
    assert_eq!(cie_xyz(359), [0.0; 3]);
    assert_eq!(cie_xyz(831), [0.0; 3]);
    // ∑ȳ over the table is pbrt-v3's CIE_Y_integral (106.856895) to 3e-7
    // relative; the x̄ and z̄ sums as computed from colour-science's table.
    let sum: [f64; 3] = CIE_1931_2DEG
        .iter()
        .fold([0.0; 3], |s, c| [s[0] + c[0], s[1] + c[1], s[2] + c[2]]);
    assert!((sum[1] - 106.856895).abs() < 3e-5, "{sum:?}");
    assert!((sum[0] - 106.865469).abs() < 1e-5, "{sum:?}");
    assert!((sum[2] - 106.892251).abs() < 1e-5, "{sum:?}");
}

#[test]
fn files_resolve_against_the_top_level_directory_and_are_read_once() {
    let spd = "400 0.25\n700 0.25\n";
    let text = "WorldBegin\nInclude \"sub/part.pbrt\"\nAttributeBegin\nMaterial \"matte\" \"spectrum Kd\" \"grey.spd\" \"float sigma\" 10\nShape \"sphere\"\nAttributeEnd\nAttributeBegin\nAreaLightSource \"diffuse\" \"spectrum L\" \"grey.spd\"\nShape \"sphere\"\nAttributeEnd\nWorldEnd\n";
    let part = "Material \"matte\" \"spectrum Kd\" \"grey.spd\"\nShape \"sphere\"\n";
    let (s, asked) = load_in_memory(
        text,
        &[
            ("sub/part.pbrt", part),
            ("grey.spd", spd),
            ("sub/grey.spd", "400 9 700 9"),
        ],
    );
    assert!(s.warnings.is_empty(), "{}", warnings(&s));
    let spd_reads: Vec<&PathBuf> = asked
        .iter()
        .filter(|p| p.extension().is_some_and(|e| e == "spd"))
        .collect();
    assert_eq!(spd_reads, [&PathBuf::from("/scene/grey.spd")], "{asked:?}");
    let flat = Vec3::new(1.2023306, 0.94621414, 0.90733975) * 0.25;
    assert_eq!(s.scene.materials.len(), 2);
    for m in &s.scene.materials {
        let kd = m.constant_spectrum("Kd").unwrap();
        assert!((kd - flat).abs().max_element() < TOL, "{kd}");
    }
    let l = s
        .scene
        .shapes
        .iter()
        .find_map(|sh| sh.area_light.as_ref())
        .expect("an area light");
    assert!((l.l - flat).abs().max_element() < TOL, "{:?}", l.l);
}

/// One scene per problem: the scene loads, the warning is located at the
/// parameter's value, and the colour is pbrt-v3's.
#[test]
fn bad_files_give_located_warnings() {
    // (label, file text, what the warnings say, Kd: None for the flat 1's)
    type Case<'a> = (&'a str, &'a str, &'a [&'a str], Option<[f64; 3]>);
    let cases: &[Case] = &[
        ("", "", &["holds no (wavelength, value) pair: black is used"], Some([0.0; 3])),
        ("", "# only a comment\n", &["holds no (wavelength, value) pair"], Some([0.0; 3])),
        ("", "500", &["the last one (500) has no pair", "holds no (wavelength, value) pair"], Some([0.0; 3])),
        ("odd", "300 1 900 1 950", &["5 values, an odd count: the last one (950) has no pair and is ignored (as pbrt-v3)"], None),
        ("text", "300 1\nabout 900 1", &["line 2: \"about\" is not a number: skipped (as pbrt-v3)"], None),
        ("repeated", "300 1 600 1 600 1 900 1", &["wavelength 600 nm is given twice"], None),
        ("decreasing", "900 1 300 1", &["wavelengths are not in increasing order (300 nm after 900 nm): the pairs are sorted (as pbrt-v3)"], None),
        ("binary", "\u{0}\u{1}\u{2}", &["is not a number", "holds no (wavelength, value) pair"], Some([0.0; 3])),
    ];
    let flat = [1.2023306, 0.94621414, 0.90733975];
    for (i, (label, text, want, colour)) in cases.iter().enumerate() {
        let (s, _) = load_in_memory(&scene("\"spectrum Kd\" \"f.spd\""), &[("f.spd", text)]);
        let w = warnings(&s);
        assert_eq!(s.warnings.len(), want.len(), "case {i} {label}: {w}");
        for (got, want) in s.warnings.iter().zip(want.iter()) {
            let got = got.to_string();
            assert!(
                got.starts_with("/scene/top.pbrt:2:32: spectrum file \"/scene/f.spd\"")
                    && got.contains(want),
                "case {i} {label}: {got:?} lacks {want:?}"
            );
        }
        let kd = kd_of(&s);
        let expect = colour.unwrap_or(flat);
        assert!(close(kd, expect), "case {i} {label}: {kd}");
    }
}

#[test]
fn missing_file_is_black_with_a_warning() {
    let (s, asked) = load_in_memory(&scene("\"spectrum Kd\" \"nope.spd\""), &[]);
    let w = warnings(&s);
    assert_eq!(asked, [PathBuf::from("/scene/nope.spd")]);
    assert_eq!(s.warnings.len(), 1, "{w}");
    assert!(
        w.starts_with("/scene/top.pbrt:2:32: cannot read spectrum file \"/scene/nope.spd\" for \"Kd\": no such file: black is used (as pbrt-v3)"),
        "{w}"
    );
    assert_eq!(kd_of(&s), Vec3::ZERO);
    // An absolute name is used as it is.
    let (_, asked) = load_in_memory(&scene("\"spectrum Kd\" \"/elsewhere/a.spd\""), &[]);
    assert_eq!(asked, [PathBuf::from("/elsewhere/a.spd")]);
}

#[test]
fn several_files_are_several_spectra() {
    // pbrt-v3 makes one spectrum per file name; a material reads one
    // spectrum only, so the parameter is left unused and Kd keeps 0.5.
    let (s, _) = load_in_memory(
        &scene("\"spectrum Kd\" [\"a.spd\" \"b.spd\"]"),
        &[("a.spd", "400 1 700 1"), ("b.spd", "400 1 700 1")],
    );
    let w = warnings(&s);
    assert!(
        w.contains("parameter \"spectrum Kd\" not used by Material \"matte\""),
        "{w}"
    );
    assert_eq!(kd_of(&s), Vec3::splat(0.5));
}
