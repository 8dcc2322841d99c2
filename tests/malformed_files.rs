//! The side-file corpus (`tests/malformed/files/`, written by its
//! `make.py`) and the numeric extremes and command lines of bad input: each
//! case is run through the real binary, in a fresh working directory, with
//! `ulimit -v` 8 GiB, and must
//! - exit with the stated status (1 for an error; 0 for pbrt-v3's
//!   render-on cases, which are then run again with `--strict` and must
//!   exit 1),
//! - never panic or die of a signal,
//! - name the file it is about (and, for scene text, FILE:LINE:),
//! - leave no image after a failure and no stray file anywhere,
//! - stay within [`MAX_SECONDS`] and [`MAX_PEAK_BYTES`] of resident memory.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Wall time a case may take (generous for loaded CI machines).
const MAX_SECONDS: f64 = 60.0;
/// Peak resident memory a case may reach.
const MAX_PEAK_BYTES: u64 = 2 << 30;

fn corpus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/malformed/files")
}

/// A scene around one line of options (line 5) and one of world
/// statements (line 8), with a point light; 4×4 pixels, 1 spp.
fn scene(options: &str, world: &str) -> String {
    format!(
        "LookAt 0 0 -5  0 0 0  0 1 0\nCamera \"perspective\"\nFilm \"image\" \"integer xresolution\" 4 \"integer yresolution\" 4\nSampler \"random\" \"integer pixelsamples\" 1\n{options}\nWorldBegin\nLightSource \"point\" \"point from\" [0 0 -5]\n{world}\nWorldEnd\n"
    )
}

/// A closed room of perfect mirrors around the camera, with a small light.
const MIRROR_ROOM: &str = "Material \"mirror\" Shape \"sphere\" \"float radius\" 10 AttributeBegin AreaLightSource \"diffuse\" Shape \"sphere\" \"float radius\" 0.5 AttributeEnd";

struct Case {
    name: String,
    /// The scene text (written to `case.pbrt`), if the case has one.
    scene: Option<String>,
    /// Arguments; `SCENE` is replaced by the scene's path, `CORPUS/` by the corpus directory.
    args: Vec<String>,
    status: i32,
    /// Texts stderr must hold (a file name, a location, a word of the message).
    texts: Vec<String>,
}

fn case(name: &str, scene: Option<String>, args: &[&str], status: i32, texts: &[&str]) -> Case {
    Case {
        name: name.into(),
        scene,
        args: args.iter().map(|s| s.to_string()).collect(),
        status,
        texts: texts.iter().map(|s| s.to_string()).collect(),
    }
}

fn render(name: &str, scene_text: String, status: i32, texts: &[&str]) -> Case {
    case(
        name,
        Some(scene_text),
        &["SCENE", "--outfile", "out/img.png"],
        status,
        texts,
    )
}

/// Side files a world statement names: each renders on with a located
/// warning naming the file (pbrt-v3 reports and renders on).
fn side_file_cases() -> Vec<Case> {
    let mut out = Vec::new();
    let images = [
        "bad-crc.png",
        "bomb.png",
        "huge.png",
        "truncated.png",
        "overrun.tga",
        "truncated-rle.tga",
        "huge.tga",
        "huge.pfm",
        "truncated.pfm",
        "nan.pfm",
        "bad-header.hdr",
        "zero-size.png",
        "huge.hdr",
        "not-an-image.exr",
    ];
    for f in images {
        let world = format!("Texture \"t\" \"spectrum\" \"imagemap\" \"string filename\" \"CORPUS/{f}\" Material \"matte\" \"texture Kd\" \"t\" Shape \"sphere\"");
        out.push(render(
            &format!("texture {f}"),
            scene("", &world),
            0,
            &[f, "case.pbrt:8:"],
        ));
    }
    for f in ["nan.pfm", "bomb.png", "overrun.tga"] {
        let world =
            format!("LightSource \"infinite\" \"string mapname\" \"CORPUS/{f}\" Shape \"sphere\"");
        out.push(render(
            &format!("envmap {f}"),
            scene("", &world),
            0,
            &[f, "case.pbrt:8:"],
        ));
    }
    let spds = [
        "odd-count.spd",
        "words.spd",
        "nonfinite.spd",
        "decreasing.spd",
        "empty.spd",
        "negative-wavelength.spd",
        "nan.spd",
        "not-utf8.spd",
    ];
    for f in spds {
        let world = format!("Material \"metal\" \"spectrum eta\" \"CORPUS/{f}\" Shape \"sphere\"");
        out.push(render(
            &format!("spd {f}"),
            scene("", &world),
            0,
            &[f, "case.pbrt:8:"],
        ));
    }
    let bsdfs = [
        "bad-magic.bsdf",
        "truncated.bsdf",
        "huge-counts.bsdf",
        "nan-coefficient.bsdf",
        "offset-out-of-range.bsdf",
        "decreasing-nodes.bsdf",
        "bad-flags.bsdf",
        "zero-size.bsdf",
    ];
    for f in bsdfs {
        let world =
            format!("Material \"fourier\" \"string bsdffile\" \"CORPUS/{f}\" Shape \"sphere\"");
        out.push(render(
            &format!("bsdf {f}"),
            scene("", &world),
            0,
            &[f, "case.pbrt:8:"],
        ));
    }
    let meshes = [
        ("plymesh", "huge-count.ply"),
        ("plymesh", "inconsistent.ply"),
        ("plymesh", "huge-faces.ply"),
        ("plymesh", "huge-list.ply"),
        ("objmesh", "bad-index.obj"),
        ("gltfmesh", "float-indices.gltf"),
        ("gltfmesh", "huge-count.gltf"),
        ("gltfmesh", "index-out-of-range.gltf"),
        ("gltfmesh", "huge-positions.gltf"),
    ];
    for (kind, f) in meshes {
        let world = format!("Shape \"{kind}\" \"string filename\" \"CORPUS/{f}\"");
        out.push(render(
            &format!("{kind} {f}"),
            scene("", &world),
            0,
            &[f, "case.pbrt:8:"],
        ));
    }
    out
}

/// Numeric extremes in the scene text: clamped with a located warning
/// (exit 0), or refused with a located error (exit 1).
fn extreme_cases() -> Vec<Case> {
    let mut out = Vec::new();
    for integrator in ["directlighting", "whitted", "path", "volpath", "sppm"] {
        let opts = format!("Integrator \"{integrator}\" \"integer maxdepth\" 1000000000");
        out.push(render(
            &format!("maxdepth {integrator}"),
            scene(&opts, MIRROR_ROOM),
            0,
            &["case.pbrt:5:", "maxdepth", "100000"],
        ));
    }
    // bdpt and mlt have no Russian roulette and connect every pair of
    // subpath lengths: their depth is clamped lower, in a closed room too.
    const MATTE_ROOM: &str =
        "Material \"matte\" \"rgb Kd\" [0.9 0.9 0.9] Shape \"sphere\" \"float radius\" 10";
    for (name, opts, world) in [
        ("bdpt mirrors", "Integrator \"bdpt\" \"integer maxdepth\" 1000000000", MIRROR_ROOM),
        ("bdpt matte", "Integrator \"bdpt\" \"integer maxdepth\" 1000000000", MATTE_ROOM),
        ("mlt matte", "Integrator \"mlt\" \"integer maxdepth\" 1000000000 \"integer bootstrapsamples\" 100 \"integer chains\" 4 \"integer mutationsperpixel\" 1", MATTE_ROOM),
    ] {
        out.push(render(
            &format!("maxdepth {name}"),
            scene(opts, world),
            0,
            &["case.pbrt:5:", "maxdepth", "at most 128 deep"],
        ));
    }
    for class in ["wrinkled", "fbm"] {
        let world = format!("Texture \"n\" \"float\" \"{class}\" \"integer octaves\" 2000000000 Material \"matte\" \"texture sigma\" \"n\" Shape \"sphere\"");
        out.push(render(
            &format!("octaves {class}"),
            scene("", &world),
            0,
            &["case.pbrt:8:", "octaves"],
        ));
    }
    out.push(render(
        "photonsperiteration",
        scene("Integrator \"sppm\" \"integer photonsperiteration\" 2000000000 \"integer iterations\" 1", "Shape \"sphere\""),
        0,
        &["case.pbrt:5:", "photonsperiteration"],
    ));
    out.push(render(
        "pixelsamples",
        scene(
            "Sampler \"halton\" \"integer pixelsamples\" 2000000000",
            "Shape \"sphere\"",
        ),
        1,
        &["case.pbrt:5:", "pixelsamples"],
    ));
    out.push(render(
        "resolution",
        scene(
            "Film \"image\" \"integer xresolution\" 1000000 \"integer yresolution\" 1000000",
            "Shape \"sphere\"",
        ),
        1,
        &["case.pbrt:5:", "xresolution"],
    ));
    out.push(render(
        "density spike",
        scene(
            "Integrator \"volpath\"",
            "MakeNamedMedium \"m\" \"string type\" \"heterogeneous\" \"integer nx\" 8 \"integer ny\" 1 \"integer nz\" 1 \"float density\" [1e9 0 0 0 0 0 0 0] \"rgb sigma_a\" [1 1 1] \"rgb sigma_s\" [1 1 1] \"point p0\" [-3 -3 -3] \"point p1\" [3 3 3] AttributeBegin MediumInterface \"m\" \"\" Material \"none\" Shape \"sphere\" \"float radius\" 3 AttributeEnd",
        ),
        0,
        &["tracking steps"],
    ));
    out.push(render(
        "transform overflow",
        scene("", "Transform [1e300 0 0 0 0 1e300 0 0 0 0 1e300 0 0 0 0 1] ConcatTransform [1e300 0 0 0 0 1e300 0 0 0 0 1e300 0 0 0 0 1] Shape \"sphere\""),
        1,
        &["case.pbrt:8:", "not finite"],
    ));
    out.push(render(
        "scale overflow",
        scene(
            "",
            "Scale 1e300 1e300 1e300 Scale 1e300 1 1 Shape \"sphere\"",
        ),
        1,
        &["case.pbrt:8:", "not finite"],
    ));
    out.push(render(
        "f32 overflow",
        scene("", "Scale 1e30 1e30 1e30 Scale 1e30 1 1 Shape \"sphere\""),
        1,
        &["case.pbrt:8:", "not finite"],
    ));
    out.push(render(
        "lookat overflow",
        scene(
            "",
            "Scale 1e30 1e30 1e30 LookAt 1e300 0 0  0 0 0  0 1 0 Shape \"sphere\"",
        ),
        0,
        &["case.pbrt:8:", "degenerate LookAt"],
    ));
    out.push(render(
        "grid voxels huge",
        scene("Integrator \"volpath\"", "MakeNamedMedium \"m\" \"string type\" \"heterogeneous\" \"integer nx\" 100000 \"integer ny\" 100000 \"integer nz\" 100000 \"float density\" [1]"),
        1,
        &["case.pbrt:8:"],
    ));
    for f in ["words.dat", "odd-count.dat", "nonfinite.dat"] {
        let text = scene("", "Shape \"sphere\"").replace(
            "Camera \"perspective\"",
            &format!("Camera \"realistic\" \"string lensfile\" \"CORPUS/{f}\""),
        );
        out.push(render(&format!("lens {f}"), text, 1, &[f, "case.pbrt:2:"]));
    }
    out
}

/// Command lines: flags out of range, files that are not scene text.
fn command_line_cases() -> Vec<Case> {
    let simple = scene("", "Shape \"sphere\"");
    vec![
        case(
            "nthreads huge",
            Some(simple),
            &[
                "SCENE",
                "--nthreads",
                "1000000000",
                "--outfile",
                "out/img.png",
            ],
            0,
            &["--nthreads 1000000000"],
        ),
        case(
            "scene /dev/zero",
            None,
            &["/dev/zero", "--outfile", "out/img.png"],
            1,
            &["/dev/zero"],
        ),
        case(
            "scene with NUL bytes",
            None,
            &["CORPUS/nul.pbrt", "--outfile", "out/img.png"],
            1,
            &["nul.pbrt", "NUL"],
        ),
    ]
}

struct Run {
    status: Option<i32>,
    stderr: String,
    seconds: f64,
    peak_bytes: u64,
}

/// Runs pbrs with `args` in `dir` under `ulimit -v` 8 GiB, polling its
/// peak resident memory (`VmHWM`) until it exits.
fn run_bounded(dir: &Path, args: &[String]) -> Run {
    let mut cmd = Command::new("sh");
    cmd.arg("-c")
        .arg("ulimit -v 8388608; exec \"$0\" \"$@\"")
        .arg(env!("CARGO_BIN_EXE_pbrs"))
        .args(args)
        .current_dir(dir)
        .env("NO_COLOR", "1")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    let start = Instant::now();
    let mut child = cmd.spawn().unwrap();
    let mut stderr_pipe = child.stderr.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = stderr_pipe.read_to_string(&mut s);
        s
    });
    let status_path = format!("/proc/{}/status", child.id());
    let mut peak_kib = 0u64;
    let status = loop {
        if let Ok(s) = std::fs::read_to_string(&status_path) {
            if let Some(v) = s
                .lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1))
                .and_then(|v| v.parse::<u64>().ok())
            {
                peak_kib = peak_kib.max(v);
            }
        }
        if let Some(st) = child.try_wait().unwrap() {
            break st;
        }
        if start.elapsed().as_secs_f64() > MAX_SECONDS * 2.0 {
            let _ = child.kill();
            break child.wait().unwrap();
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    Run {
        status: status.code(),
        stderr: reader.join().unwrap(),
        seconds: start.elapsed().as_secs_f64(),
        peak_bytes: peak_kib * 1024,
    }
}

/// Every file under `dir`, relative to it.
fn files_under(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            out.extend(
                files_under(&p)
                    .into_iter()
                    .map(|f| Path::new(p.file_name().unwrap()).join(f)),
            );
        } else {
            out.push(PathBuf::from(p.file_name().unwrap()));
        }
    }
    out
}

/// Runs one case (with `strict` adding `--strict`); the problems found.
fn check(c: &Case, strict: bool) -> Vec<String> {
    static NEXT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let n = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("pbrs-malformed-{}-{n}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("out")).unwrap();
    let corpus = corpus();
    let fix = |s: &str| s.replace("CORPUS/", &format!("{}/", corpus.display()));
    if let Some(text) = &c.scene {
        std::fs::write(dir.join("case.pbrt"), fix(text)).unwrap();
    }
    let mut args: Vec<String> = c
        .args
        .iter()
        .map(|a| {
            if a == "SCENE" {
                "case.pbrt".to_string()
            } else {
                fix(a)
            }
        })
        .collect();
    if strict {
        args.push("--strict".into());
    }
    let expected = if strict { 1 } else { c.status };
    let r = run_bounded(&dir, &args);
    let mut problems = Vec::new();
    if r.status != Some(expected) {
        problems.push(format!("exit status {:?}, expected {expected}", r.status));
    }
    if r.stderr.contains("panicked") {
        problems.push("panicked".into());
    }
    for t in &c.texts {
        if !r.stderr.contains(t.as_str()) {
            problems.push(format!("stderr lacks {t:?}"));
        }
    }
    if r.seconds > MAX_SECONDS {
        problems.push(format!("took {:.1} s", r.seconds));
    }
    if r.peak_bytes > MAX_PEAK_BYTES {
        problems.push(format!("peak memory {} MiB", r.peak_bytes >> 20));
    }
    let mut left = files_under(&dir);
    left.retain(|f| f != Path::new("case.pbrt"));
    let allowed: Vec<PathBuf> = if r.status == Some(0) {
        vec![PathBuf::from("out/img.png")]
    } else {
        vec![]
    };
    if left != allowed {
        problems.push(format!("files left: {left:?}"));
    }
    let _ = std::fs::remove_dir_all(&dir);
    problems
        .into_iter()
        .map(|p| {
            format!(
                "{}{}: {p}\n{}",
                c.name,
                if strict { " --strict" } else { "" },
                r.stderr
            )
        })
        .collect()
}

fn run_all(cases: Vec<Case>) {
    let mut failures = Vec::new();
    for c in &cases {
        failures.extend(check(c, false));
        if c.status == 0 && c.scene.is_some() && !c.name.starts_with("nthreads") {
            failures.extend(check(c, true));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

#[test]
fn side_files_are_reported_with_their_names() {
    run_all(side_file_cases());
}

#[test]
fn numeric_extremes_are_bounded() {
    run_all(extreme_cases());
}

#[test]
fn command_lines_are_bounded() {
    run_all(command_line_cases());
}

/// A farm part whose EXR data window claims a huge size is refused by
/// `pbrs merge` before its pixels are allocated.
#[test]
fn merge_refuses_a_huge_part() {
    let dir = std::env::temp_dir().join(format!("pbrs-malformed-merge-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("s.pbrt"), scene("", "Shape \"sphere\"")).unwrap();
    let r = run_bounded(
        &dir,
        &[
            "s.pbrt",
            "--tile",
            "0",
            "--tiles",
            "1",
            "--outfile",
            "part.exr",
            "--quiet",
        ]
        .map(String::from),
    );
    assert_eq!(r.status, Some(0), "{}", r.stderr);
    let mut exr = std::fs::read(dir.join("part.exr")).unwrap();
    let key = b"dataWindow\0box2i\0";
    let at = exr.windows(key.len()).position(|w| w == key).unwrap() + key.len() + 4;
    exr[at + 8..at + 12].copy_from_slice(&(1i32 << 30).to_le_bytes());
    exr[at + 12..at + 16].copy_from_slice(&(1i32 << 30).to_le_bytes());
    std::fs::write(dir.join("huge-part.exr"), &exr).unwrap();
    let r = run_bounded(
        &dir,
        &["merge", "out.exr", "huge-part.exr"].map(String::from),
    );
    assert_eq!(r.status, Some(1), "{}", r.stderr);
    assert!(r.stderr.contains("huge-part.exr"), "{}", r.stderr);
    assert!(!r.stderr.contains("panicked"), "{}", r.stderr);
    assert!(r.peak_bytes < MAX_PEAK_BYTES && r.seconds < MAX_SECONDS);
    assert!(!dir.join("out.exr").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn corpus_covers_every_class() {
    let n = side_file_cases().len() + extreme_cases().len() + command_line_cases().len();
    assert!(n >= 60, "only {n} cases");
}
