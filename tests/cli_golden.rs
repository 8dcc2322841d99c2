//! `pbrs test` (golden-image regression for a folder of scenes) and `pbrs img
//! diff|convert|info`, through the binary: every exit status, on a Cornell
//! box at 32×32, 16 spp. A re-render that differs only by noise (another
//! seed, another thread count) passes; a 3% brighter light, a changed wall
//! colour, a missing texture (now grey) and a moved box each fail; bad input
//! exits 2 with the file named and nothing written.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pbrs-cli-golden-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A change to the Cornell box.
#[derive(Clone, Copy, Default)]
struct Change {
    light_scale: f64,
    red_wall: Option<[f64; 3]>,
    box_dx: f64,
    /// The short box's colour from the image texture `tex.pfm`.
    textured: bool,
}

/// The texture of a textured box: a constant green, far from the 0.5 grey
/// pbrs (like pbrt-v3) substitutes for a missing texture file.
fn write_texture(dir: &Path) {
    pfm(&dir.join("tex.pfm"), 2, 2, |_, _| [0.15, 0.6, 0.15]);
}

/// The Cornell box (`scenes/cornell-path.pbrt`'s geometry) at 32×32, 16 spp.
fn cornell(c: Change) -> String {
    let common = std::fs::read_to_string(repo().join("scenes/cornell-common.inc")).unwrap();
    let cube = std::fs::read_to_string(repo().join("scenes/unitcube.inc")).unwrap();
    let s = if c.light_scale == 0.0 {
        1.0
    } else {
        c.light_scale
    };
    let l = format!("[{} {} {}]", 17.0 * s, 12.0 * s, 4.0 * s);
    let mut common = common.replace("[17 12 4]", &l);
    if let Some(r) = c.red_wall {
        common = common.replace(
            "[0.63 0.065 0.05]",
            &format!("[{} {} {}]", r[0], r[1], r[2]),
        );
    }
    let material = if c.textured {
        "Texture \"tex\" \"spectrum\" \"imagemap\" \"string filename\" \"tex.pfm\"\n\
         Material \"matte\" \"texture Kd\" \"tex\""
    } else {
        "Material \"matte\" \"rgb Kd\" [0.725 0.71 0.68]"
    };
    format!(
        "Scale -1 1 1\nLookAt 0 1 6.8  0 1 0  0 1 0\nCamera \"perspective\" \"float fov\" [19.5]\n\
         Film \"image\" \"integer xresolution\" [32] \"integer yresolution\" [32] \"string filename\" \"out.exr\"\n\
         Sampler \"halton\" \"integer pixelsamples\" [16]\nIntegrator \"path\" \"integer maxdepth\" [8]\n\
         WorldBegin\n{common}\nAttributeBegin\n{material}\n\
         Translate {} 0.3 0.37\nRotate -17 0 1 0\nScale 0.6 0.6 0.6\n{cube}\nAttributeEnd\nWorldEnd\n",
        0.33 + c.box_dx
    )
}

fn pbrs(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pbrs"))
        .args(args)
        .current_dir(dir)
        .env("NO_COLOR", "1")
        .output()
        .unwrap()
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

fn expect(o: &Output, code: i32) -> String {
    let t = text(o);
    assert_eq!(o.status.code(), Some(code), "{t}");
    t
}

/// The Cornell box with its textured short box.
const TEXTURED: Change = Change {
    light_scale: 0.0,
    red_wall: None,
    box_dx: 0.0,
    textured: true,
};

/// A folder with the Cornell box (short box textured) and a second scene,
/// goldens written.
fn folder(name: &str) -> PathBuf {
    let d = tmp(name);
    std::fs::create_dir_all(d.join("s")).unwrap();
    std::fs::write(d.join("s/box.pbrt"), cornell(TEXTURED)).unwrap();
    write_texture(&d.join("s"));
    let moved = Change {
        box_dx: -0.05,
        ..Default::default()
    };
    std::fs::write(d.join("s/other.pbrt"), cornell(moved)).unwrap();
    let t = expect(&pbrs(&["test", "s", "--update"], &d), 0);
    assert!(t.contains("2 goldens written"), "{t}");
    assert!(d.join("s/golden/box.exr").exists() && d.join("s/golden/other.exr").exists());
    d
}

#[test]
fn noise_passes_and_real_changes_fail() {
    let d = folder("changes");
    let golden = std::fs::read(d.join("s/golden/box.exr")).unwrap();
    // The default seed, and a fresh seed: noise only.
    let t = expect(&pbrs(&["test", "s"], &d), 0);
    assert!(t.contains("2 passed, 0 failed"), "{t}");
    // By default the test render takes seed 2, independent of the golden's
    // seeds 0 and 1: the figures of --seed 2.
    let figures = |t: &str| {
        let l = t.lines().find(|l| l.starts_with("ok    box")).unwrap();
        l.split_once("): ").unwrap().1.to_string()
    };
    let t2 = expect(&pbrs(&["test", "s", "--seed", "2"], &d), 0);
    assert_eq!(figures(&t), figures(&t2));
    let t0 = expect(&pbrs(&["test", "s", "--seed", "0"], &d), 0);
    assert_ne!(figures(&t), figures(&t0));
    let t = expect(
        &pbrs(&["test", "s", "--seed", "7", "--junit", "j.xml"], &d),
        0,
    );
    assert!(t.contains("box") && t.contains("pass"), "{t}");
    let j = std::fs::read_to_string(d.join("j.xml")).unwrap();
    assert!(
        j.contains("tests=\"2\" failures=\"0\" errors=\"0\"")
            && j.contains("<testcase name=\"box\""),
        "{j}"
    );
    // One thread: the same pixels as all of them, so it passes; goldens
    // written with one thread equal those written with all.
    expect(
        &pbrs(&["test", "s", "--seed", "7", "--nthreads", "1"], &d),
        0,
    );
    std::fs::create_dir_all(d.join("t")).unwrap();
    std::fs::copy(d.join("s/box.pbrt"), d.join("t/box.pbrt")).unwrap();
    write_texture(&d.join("t"));
    expect(&pbrs(&["test", "t", "--update", "--nthreads", "1"], &d), 0);
    let t = expect(
        &pbrs(&["img", "diff", "t/golden/box.exr", "s/golden/box.exr"], &d),
        0,
    );
    assert!(t.contains("max |A−B|      0.000000e0"), "{t}");
    // Real changes, each caught.
    let changes = [
        (
            "light 3% brighter",
            Change {
                light_scale: 1.03,
                ..TEXTURED
            },
        ),
        (
            "red wall changed",
            Change {
                red_wall: Some([0.55, 0.065, 0.05]),
                ..TEXTURED
            },
        ),
        (
            "box moved",
            Change {
                box_dx: 0.1,
                ..TEXTURED
            },
        ),
        // The scene unchanged but its texture file gone: grey instead.
        ("texture missing", TEXTURED),
    ];
    for (what, c) in changes {
        std::fs::write(d.join("s/box.pbrt"), cornell(c)).unwrap();
        if what == "texture missing" {
            std::fs::remove_file(d.join("s/tex.pfm")).unwrap();
        }
        let o = pbrs(
            &[
                "test", "s", "--seed", "7", "--junit", "j.xml", "--report", "rep",
            ],
            &d,
        );
        let t = expect(&o, 1);
        assert!(
            t.contains("FAIL") && t.contains("1 passed, 1 failed"),
            "{what}: {t}"
        );
        if what == "texture missing" {
            // The loader's warning says why.
            assert!(t.contains("tex.pfm"), "{t}");
        }
        let j = std::fs::read_to_string(d.join("j.xml")).unwrap();
        assert!(
            j.contains("failures=\"1\"")
                && j.contains("<failure message=")
                && j.contains("× noise"),
            "{what}: {j}"
        );
        let html = std::fs::read_to_string(d.join("rep/index.html")).unwrap();
        assert!(
            html.contains("box: FAIL") && html.contains("box-difference.png"),
            "{what}"
        );
        for k in ["golden", "render", "difference"] {
            assert!(d.join(format!("rep/box-{k}.png")).exists(), "{what}: {k}");
        }
    }
    // Only --update writes goldens.
    assert_eq!(std::fs::read(d.join("s/golden/box.exr")).unwrap(), golden);
}

#[test]
fn golden_toml_selects_scenes_and_sets_spp_resolution_and_tolerances() {
    let d = folder("toml");
    let toml = "spp = 8\n[[scene]]\nfile = \"box.pbrt\"\nresolution = [24, 16]\ntolerance = 3\n";
    std::fs::write(d.join("s/golden.toml"), toml).unwrap();
    let t = expect(&pbrs(&["test", "s", "--update"], &d), 0);
    assert!(
        t.contains("1 goldens written") && !t.contains("other"),
        "{t}"
    );
    let t = expect(&pbrs(&["img", "info", "s/golden/box.exr"], &d), 0);
    assert!(
        t.contains("24×16") && t.contains("pbrsSpp: 8") && t.contains("pbrsGoldenNoise"),
        "{t}"
    );
    expect(&pbrs(&["test", "s", "--seed", "3"], &d), 0);
    // A golden of another size: bad input.
    std::fs::write(
        d.join("s/golden.toml"),
        toml.replace("[24, 16]", "[16, 16]"),
    )
    .unwrap();
    let t = expect(&pbrs(&["test", "s"], &d), 2);
    assert!(
        t.contains("box.exr: the golden is 24×16 but the render is 16×16"),
        "{t}"
    );
    // Malformed files: located, with the key.
    let bad = [
        (
            "spp = 8\n[[scene]]\nfile = \"box.pbrt\"\ntolerance = -1\n",
            "golden.toml:4:13: key `scene.tolerance`: expected a number > 0",
        ),
        ("sp = 8\n", "golden.toml:1:6: key `sp`: unknown key"),
        ("[[scene]]\nspp = 4\n", "key `scene.file`: missing"),
        ("spp = [8\n", "TOML parse error at line 1"),
    ];
    for (toml, msg) in bad {
        std::fs::write(d.join("s/golden.toml"), toml).unwrap();
        let t = expect(&pbrs(&["test", "s"], &d), 2);
        assert!(t.contains(msg), "{toml}: {t}");
    }
}

#[test]
fn bad_input_exits_2_and_the_other_scenes_still_run() {
    let d = folder("bad");
    // A scene that fails to load: its diagnostic, and the other scene runs.
    std::fs::write(
        d.join("s/broken.pbrt"),
        "WorldBegin\nShape \"sphere\" \"float radius\" [\nWorldEnd\n",
    )
    .unwrap();
    // --update: the other goldens are written, none for the broken scene,
    // and nothing else lands in golden/.
    let t = expect(&pbrs(&["test", "s", "--update"], &d), 2);
    assert!(t.contains("0 failed, 1 errors, 2 goldens written"), "{t}");
    let mut files: Vec<String> = std::fs::read_dir(d.join("s/golden"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    files.sort();
    assert_eq!(files, ["box.exr", "other.exr"]);
    let t = expect(&pbrs(&["test", "s", "--junit", "j.xml"], &d), 2);
    assert!(
        t.contains("broken.pbrt") && t.contains("the scene did not load"),
        "{t}"
    );
    assert!(t.contains("2 passed, 0 failed, 1 errors"), "{t}");
    let j = std::fs::read_to_string(d.join("j.xml")).unwrap();
    assert!(
        j.contains("errors=\"1\"") && j.contains("<error message="),
        "{j}"
    );
    std::fs::remove_file(d.join("s/broken.pbrt")).unwrap();
    // A missing golden, a truncated one, a file that is no golden.
    std::fs::remove_file(d.join("s/golden/other.exr")).unwrap();
    let t = expect(&pbrs(&["test", "s"], &d), 2);
    assert!(
        t.contains("other.exr: no golden (run pbrs test --update"),
        "{t}"
    );
    let g = std::fs::read(d.join("s/golden/box.exr")).unwrap();
    std::fs::write(d.join("s/golden/other.exr"), &g[..g.len() / 3]).unwrap();
    let t = expect(&pbrs(&["test", "s"], &d), 2);
    assert!(t.contains("other.exr: cannot read it as EXR"), "{t}");
    expect(
        &pbrs(
            &["s/box.pbrt", "--quiet", "--outfile", "s/golden/other.exr"],
            &d,
        ),
        0,
    );
    let t = expect(&pbrs(&["test", "s"], &d), 2);
    assert!(t.contains("other.exr: not a pbrs golden"), "{t}");
    // No scenes, no folder.
    std::fs::create_dir_all(d.join("empty")).unwrap();
    let t = expect(&pbrs(&["test", "empty"], &d), 2);
    assert!(t.contains("empty: no scenes"), "{t}");
    let t = expect(&pbrs(&["test", "nowhere"], &d), 2);
    assert!(t.contains("nowhere: not a directory"), "{t}");
}

#[test]
fn renders_carry_metadata_unless_reproducible() {
    let d = tmp("meta");
    std::fs::write(d.join("box.pbrt"), cornell(Change::default())).unwrap();
    for f in ["a.exr", "a.png"] {
        expect(
            &pbrs(
                &[
                    "box.pbrt",
                    "--quiet",
                    "--spp",
                    "4",
                    "--seed",
                    "5",
                    "--outfile",
                    f,
                ],
                &d,
            ),
            0,
        );
        let t = expect(&pbrs(&["img", "info", f], &d), 0);
        for want in [
            "pbrsScene: box.pbrt",
            "pbrsSpp: 4",
            "pbrsIntegrator: path",
            "pbrsSeed: 5",
            "pbrsRenderTime: ",
            "pbrsVersion: ",
        ] {
            assert!(t.contains(want), "{f}: {want}: {t}");
        }
    }
    expect(
        &pbrs(
            &[
                "box.pbrt",
                "--quiet",
                "--reproducible",
                "--outfile",
                "r.exr",
            ],
            &d,
        ),
        0,
    );
    let t = expect(&pbrs(&["img", "info", "r.exr"], &d), 0);
    assert!(!t.contains("pbrs"), "{t}");
}

/// Writes a PFM of `w`×`h` with values `f(x, y)`.
fn pfm(path: &Path, w: u32, h: u32, f: impl Fn(u32, u32) -> [f32; 3]) {
    let mut img = pbrs::image::Image::new(w, h);
    for y in 0..h {
        for x in 0..w {
            img.set_pixel(x, y, glam::Vec3::from_array(f(x, y)));
        }
    }
    pbrs::image::io::write_image(path, &img).unwrap();
}

#[test]
fn img_diff_exit_statuses_and_error_image() {
    let d = tmp("diff");
    pfm(&d.join("a.pfm"), 16, 8, |x, y| {
        [x as f32 / 16.0, y as f32 / 8.0, 0.5]
    });
    pfm(&d.join("b.pfm"), 16, 8, |x, y| {
        [x as f32 / 16.0 * 1.01, y as f32 / 8.0, 0.5]
    });
    pfm(&d.join("c.pfm"), 8, 8, |_, _| [1.0; 3]);
    let t = expect(&pbrs(&["img", "diff", "a.pfm", "a.pfm"], &d), 0);
    assert!(
        t.contains("relative MSE   0.000000e0") && t.contains("block error"),
        "{t}"
    );
    // Without tolerances any difference fails; --tol and --mean-tol decide.
    expect(&pbrs(&["img", "diff", "b.pfm", "a.pfm"], &d), 1);
    expect(
        &pbrs(
            &[
                "img",
                "diff",
                "b.pfm",
                "a.pfm",
                "--tol",
                "1e-3",
                "--error-image",
                "e.png",
            ],
            &d,
        ),
        0,
    );
    assert!(d.join("e.png").exists());
    expect(
        &pbrs(
            &[
                "img",
                "diff",
                "b.pfm",
                "a.pfm",
                "--tol",
                "1e-3",
                "--mean-tol",
                "1e-3",
            ],
            &d,
        ),
        1,
    );
    expect(
        &pbrs(&["img", "diff", "b.pfm", "a.pfm", "--tol", "1e-9"], &d),
        1,
    );
    // Bad input.
    let t = expect(
        &pbrs(
            &["img", "diff", "a.pfm", "c.pfm", "--error-image", "f.png"],
            &d,
        ),
        2,
    );
    assert!(t.contains("a.pfm is 16×8 but c.pfm is 8×8"), "{t}");
    assert!(!d.join("f.png").exists());
    // A grey PFM against a colour one: a clear error naming both.
    let mut grey = b"Pf\n16 8\n-1.0\n".to_vec();
    for _ in 0..16 * 8 {
        grey.extend_from_slice(&0.5f32.to_le_bytes());
    }
    std::fs::write(d.join("g.pfm"), grey).unwrap();
    let t = expect(&pbrs(&["img", "diff", "a.pfm", "g.pfm"], &d), 2);
    assert!(t.contains("a.pfm has channels RGB but g.pfm has Y"), "{t}");
    // Non-finite pixels are counted and fail whatever the tolerance.
    pfm(&d.join("n.pfm"), 16, 8, |x, y| {
        if (x, y) == (3, 2) {
            [f32::NAN, 0.0, 0.5]
        } else {
            [x as f32 / 16.0, y as f32 / 8.0, 0.5]
        }
    });
    let t = expect(
        &pbrs(&["img", "diff", "n.pfm", "a.pfm", "--tol", "1e9"], &d),
        1,
    );
    assert!(
        t.contains("non-finite     A 1, B 0") && t.contains("DIFFERENT"),
        "{t}"
    );
    std::fs::write(d.join("bad.exr"), b"not an exr").unwrap();
    let t = expect(&pbrs(&["img", "diff", "a.pfm", "bad.exr"], &d), 2);
    assert!(t.contains("bad.exr: cannot read it as EXR"), "{t}");
    let t = expect(&pbrs(&["img", "diff", "a.pfm", "missing.pfm"], &d), 2);
    assert!(t.contains("missing.pfm"), "{t}");
}

#[test]
fn img_convert_formats_exposure_crop_flip_and_non_finite() {
    let d = tmp("convert");
    pfm(&d.join("in.pfm"), 8, 4, |x, y| {
        [0.1 * x as f32, 0.2 * y as f32, 0.25]
    });
    for f in ["o.exr", "o.png", "o.tga", "o.hdr", "o.pfm"] {
        expect(&pbrs(&["img", "convert", "in.pfm", f], &d), 0);
        let t = expect(&pbrs(&["img", "info", f], &d), 0);
        assert!(t.contains("8×4"), "{f}: {t}");
    }
    // Exposure +1 doubles; the crop keeps x 2..6, y 1..3; the flip turns rows.
    expect(
        &pbrs(
            &[
                "img",
                "convert",
                "in.pfm",
                "x.pfm",
                "--exposure",
                "1",
                "--crop",
                "2",
                "6",
                "1",
                "3",
                "--flip",
            ],
            &d,
        ),
        0,
    );
    let x = pbrs::image::io::read_image(&d.join("x.pfm")).unwrap();
    assert_eq!((x.width, x.height), (4, 2));
    let p = x.pixel(0, 0);
    assert!(
        (p.x - 0.4).abs() < 1e-6 && (p.y - 0.8).abs() < 1e-6 && (p.z - 0.5).abs() < 1e-6,
        "{p}"
    );
    // --clamp: exposure +3 multiplies by 8, then values above 1 are 1.
    expect(
        &pbrs(
            &[
                "img",
                "convert",
                "in.pfm",
                "c.pfm",
                "--exposure",
                "3",
                "--clamp",
            ],
            &d,
        ),
        0,
    );
    let c = pbrs::image::io::read_image(&d.join("c.pfm")).unwrap();
    let (p1, p2) = (c.pixel(1, 0), c.pixel(2, 0));
    assert!(
        (p1.x - 0.8).abs() < 1e-6 && p2.x == 1.0 && p1.z == 1.0,
        "{p1} {p2}"
    );
    assert!(c.data.iter().all(|&v| (0.0..=1.0).contains(&v)));
    // 8-bit outputs are sRGB-encoded; --gamma G encodes v^(1/G) instead:
    // blue 0.25 is byte 137 in sRGB, 64 with gamma 1, 136 with gamma 2.2.
    for (args, want) in [
        (&[][..], 137u8),
        (&["--gamma", "1"][..], 64),
        (&["--gamma", "2.2", "--clamp"][..], 136),
    ] {
        let mut a = vec!["img", "convert", "in.pfm", "g.png"];
        a.extend_from_slice(args);
        expect(&pbrs(&a, &d), 0);
        let bytes = std::fs::read(d.join("g.png")).unwrap();
        let mut r = png::Decoder::new(std::io::Cursor::new(bytes))
            .read_info()
            .unwrap();
        let mut buf = vec![0; r.output_buffer_size().unwrap()];
        r.next_frame(&mut buf).unwrap();
        let blue = buf[2];
        assert!(blue.abs_diff(want) <= 1, "{args:?}: {blue} vs {want}");
    }
    // A NaN and an infinite pixel: reported, black in 8-bit files.
    pfm(&d.join("nan.pfm"), 2, 1, |x, _| {
        if x == 0 {
            [f32::NAN, 0.5, 0.5]
        } else {
            [f32::INFINITY, 1.0, 1.0]
        }
    });
    let t = expect(&pbrs(&["img", "convert", "nan.pfm", "nan.png"], &d), 0);
    assert!(
        t.contains("2 pixels with NaN or infinite values (written as black)"),
        "{t}"
    );
    let n = pbrs::image::io::read_image(&d.join("nan.png")).unwrap();
    assert!(n.data.iter().all(|&v| v == 0.0), "{:?}", n.data);
    let t = expect(&pbrs(&["img", "info", "nan.pfm"], &d), 0);
    assert!(t.contains("non-finite pixels 2"), "{t}");
    // Bad input: nothing written.
    let t = expect(
        &pbrs(
            &[
                "img", "convert", "in.pfm", "y.png", "--crop", "0", "9", "0", "1",
            ],
            &d,
        ),
        2,
    );
    assert!(
        t.contains("--crop 0 9 0 1 is not within in.pfm (8×4"),
        "{t}"
    );
    assert!(!d.join("y.png").exists());
    std::fs::write(d.join("t.pfm"), b"PF\n8 4\n-1.0\n\0\0").unwrap();
    let t = expect(&pbrs(&["img", "convert", "t.pfm", "y.png"], &d), 2);
    assert!(
        t.contains("t.pfm: cannot read it as PFM") && t.contains("truncated"),
        "{t}"
    );
    let t = expect(&pbrs(&["img", "convert", "in.pfm", "y.bmp"], &d), 2);
    assert!(t.contains("y.bmp: unsupported image format"), "{t}");
    assert!(!d.join("y.png").exists() && !d.join("y.bmp").exists());
    // info: every file is reported; a bad one makes the status 2.
    let t = expect(&pbrs(&["img", "info", "in.pfm", "t.pfm", "o.exr"], &d), 2);
    assert!(
        t.contains("in.pfm") && t.contains("o.exr") && t.contains("t.pfm: cannot read"),
        "{t}"
    );
    assert!(t.contains("R: min 0.000000 max 0.700000"), "{t}");
}
