//! The command line as pbrt users call it: pbrt-v3's and pbrt-v4's flags,
//! several scene files and standard input, `--cat`/`--toply` round trips,
//! the tev live view, partial images and exit codes. Every test runs the
//! built binary at a tiny resolution.

use pbrs::image::io::read_pfm;
use pbrs::image::Image;
use std::io::{Read, Write};
use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn pbrs() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_pbrs"));
    c.current_dir(repo()).env("NO_COLOR", "1");
    c
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pbrs-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn run(c: &mut Command) -> Output {
    c.output().unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn ok(o: &Output) {
    assert_eq!(o.status.code(), Some(0), "stderr: {}", stderr(o));
}

/// A small scene: `film` and `sampler` lines replace the defaults.
fn scene(film: &str, sampler: &str) -> String {
    format!(
        r#"LookAt 0 0 5  0 0 0  0 1 0
Camera "perspective" "float fov" [ 40 ]
{film}
{sampler}
WorldBegin
LightSource "point" "point from" [ 2 2 5 ] "rgb I" [ 30 30 30 ]
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [ 2 2 2 ] "integer nsamples" [ 4 ]
  Translate 0 3 0
  Shape "sphere" "float radius" [ 0.5 ]
AttributeEnd
Material "matte" "rgb Kd" [ 0.5 0.4 0.3 ]
Shape "sphere" "float radius" [ 1 ]
WorldEnd
"#
    )
}

fn small_scene() -> String {
    scene(
        r#"Film "image" "integer xresolution" [ 40 ] "integer yresolution" [ 30 ]"#,
        r#"Sampler "halton" "integer pixelsamples" [ 4 ]"#,
    )
}

/// The small scene with a sampler whose samples do not depend on the crop
/// (pbrt-v3's Halton and Sobol samplers index samples over the sample
/// bounds, so a crop changes them; the stratified sampler does not).
fn crop_invariant_scene() -> String {
    small_scene().replace(
        r#"Sampler "halton" "integer pixelsamples" [ 4 ]"#,
        r#"Sampler "stratified" "integer xsamples" [ 2 ] "integer ysamples" [ 2 ]"#,
    )
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn image(p: &Path) -> Image {
    read_pfm(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

fn bytes(p: &Path) -> Vec<u8> {
    std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

#[test]
fn pbrt_v3_spellings_are_accepted_and_honoured() {
    let d = tmp("v3");
    let s = write(&d, "s.pbrt", &small_scene());
    // pbrt-v3's forms: one dash, two dashes, --flag=value; the image does
    // not depend on the thread count.
    let a = d.join("a.pfm");
    let b = d.join("b.pfm");
    let c = d.join("c.pfm");
    ok(&run(pbrs()
        .args(["-nthreads", "1", "-quiet", "-outfile"])
        .arg(&a)
        .arg(&s)));
    ok(&run(pbrs()
        .arg("--nthreads=2")
        .arg(format!("--outfile={}", b.display()))
        .args(["--quiet"])
        .arg(&s)));
    ok(&run(pbrs()
        .args(["--threads", "2", "-q", "-o"])
        .arg(&c)
        .arg(&s)));
    // pbrt-v3: 0 threads is one per core.
    let z = d.join("z.pfm");
    ok(&run(pbrs()
        .args(["--nthreads", "0", "-q", "-o"])
        .arg(&z)
        .arg(&s)));
    assert_eq!(bytes(&a), bytes(&z));
    assert_eq!(bytes(&a), bytes(&b), "--nthreads 1 and 2 differ");
    assert_eq!(bytes(&a), bytes(&c));
    let img = image(&a);
    assert_eq!((img.width, img.height), (40, 30));
    assert!(img.data.iter().any(|&v| v > 0.0), "black image");

    // The logging flags are accepted.
    let l = d.join("l.pfm");
    ok(&run(pbrs()
        .args(["--v", "2", "-v", "1", "--v=3", "--logtostderr", "-logdir"])
        .arg(&d)
        .arg(format!("--logdir={}", d.display()))
        .args([
            "-minloglevel",
            "0",
            "--minloglevel=1",
            "--quiet",
            "--outfile",
        ])
        .arg(&l)
        .arg(&s)));
    assert_eq!(bytes(&a), bytes(&l));

    // --cropwindow: four values, one or two dashes, or pbrt-v4's comma form.
    let s = write(&d, "c.pbrt", &crop_invariant_scene());
    let full = d.join("full.pfm");
    ok(&run(pbrs().args(["-q", "--outfile"]).arg(&full).arg(&s)));
    let img = image(&full);
    for form in [
        vec!["-cropwindow", "0.25", "0.75", "0", "0.5"],
        vec!["--cropwindow", "0.75", "0.25", "0.5", "0"],
        vec!["--cropwindow", "0.25,0.75,0,0.5"],
        vec!["--cropwindow=0.25,0.75,0,0.5"],
    ] {
        let o = d.join("crop.pfm");
        ok(&run(pbrs()
            .args(&form)
            .args(["--quiet", "--outfile"])
            .arg(&o)
            .arg(&s)));
        let cimg = image(&o);
        assert_eq!((cimg.width, cimg.height), (20, 15), "{form:?}");
        // A crop renders the same pixels as the full image.
        for y in 0..15 {
            for x in 0..20 {
                assert_eq!(
                    cimg.pixel(x, y),
                    img.pixel(x + 10, y),
                    "{form:?} at {x},{y}"
                );
            }
        }
    }
}

#[test]
fn film_cropwindow_takes_precedence_as_in_pbrt_v3() {
    let d = tmp("cropprec");
    let text = scene(
        r#"Film "image" "integer xresolution" [ 40 ] "integer yresolution" [ 30 ] "float cropwindow" [ 0 0.5 0 1 ]"#,
        r#"Sampler "halton" "integer pixelsamples" [ 1 ]"#,
    );
    let s = write(&d, "s.pbrt", &text);
    let o = d.join("o.pfm");
    let out = run(pbrs()
        .args(["--cropwindow", "0", "1", "0", "0.5", "--outfile"])
        .arg(&o)
        .arg(&s));
    ok(&out);
    assert!(
        stderr(&out).contains("--cropwindow is ignored"),
        "{}",
        stderr(&out)
    );
    let img = image(&o);
    assert_eq!((img.width, img.height), (20, 30));
}

#[test]
fn quick_quarters_the_resolution_and_takes_one_sample() {
    let d = tmp("quick");
    for (sampler, spp) in [
        (r#"Sampler "halton" "integer pixelsamples" [ 16 ]"#, 1),
        (
            r#"Sampler "stratified" "integer xsamples" [ 3 ] "integer ysamples" [ 2 ]"#,
            1,
        ),
        (r#"Sampler "sobol" "integer pixelsamples" [ 8 ]"#, 1),
        // pbrt-v3's random sampler ignores --quick.
        (r#"Sampler "random" "integer pixelsamples" [ 4 ]"#, 4),
    ] {
        let text = scene(
            r#"Film "image" "integer xresolution" [ 130 ] "integer yresolution" [ 67 ]"#,
            sampler,
        );
        let s = write(&d, "s.pbrt", &text);
        let o = d.join("q.pfm");
        let out = run(pbrs().args(["-quick", "--outfile"]).arg(&o).arg(&s));
        ok(&out);
        let img = image(&o);
        // pbrt-v3 film.cpp: max(1, res / 4), integer division.
        assert_eq!((img.width, img.height), (32, 16), "{sampler}");
        assert!(
            stderr(&out).contains(&format!("32x16 px, {spp} spp")),
            "{sampler}: {}",
            stderr(&out)
        );
    }
    // At least one pixel.
    let s = write(
        &d,
        "t.pbrt",
        &scene(
            r#"Film "image" "integer xresolution" [ 3 ] "integer yresolution" [ 5 ]"#,
            "",
        ),
    );
    let o = d.join("t.pfm");
    ok(&run(pbrs()
        .args(["--quick", "-q", "--outfile"])
        .arg(&o)
        .arg(&s)));
    let img = image(&o);
    assert_eq!((img.width, img.height), (1, 1));
}

#[test]
fn pbrt_v4_flags() {
    let d = tmp("v4");
    let s = write(&d, "s.pbrt", &crop_invariant_scene());
    let full = d.join("full.pfm");
    let out = run(pbrs()
        .args(["--spp", "2", "--stats", "--outfile"])
        .arg(&full)
        .arg(&s));
    ok(&out);
    assert!(stderr(&out).contains("2 spp"), "{}", stderr(&out));
    assert!(stderr(&out).contains("statistics:"), "{}", stderr(&out));
    // 40 × 30 pixels at 2 spp.
    assert!(stderr(&out).contains("samples: 2400"), "{}", stderr(&out));
    // Load, build and render time, on the summary line and in the statistics.
    let times = |line: &str, prefix: &str| {
        line.split(prefix).nth(1).is_some_and(|rest| {
            ["load ", "build ", "render "]
                .iter()
                .all(|k| rest.contains(k))
        })
    };
    assert!(
        stderr(&out).lines().any(|l| times(l, "threads; "))
            && stderr(&out).lines().any(|l| times(l, "times: ")),
        "{}",
        stderr(&out)
    );
    let full_img = image(&full);

    // --pixelbounds x0 x1 y0 y1, in either form: exactly those pixels.
    for form in [
        vec!["--pixelbounds", "12", "20", "10", "14"],
        vec!["-pixelbounds=12,20,10,14"],
    ] {
        let o = d.join("pb.pfm");
        ok(&run(pbrs()
            .args(&form)
            .args(["--spp", "2", "-q", "--outfile"])
            .arg(&o)
            .arg(&s)));
        let img = image(&o);
        assert_eq!((img.width, img.height), (8, 4), "{form:?}");
        assert!(img.data.iter().any(|&v| v > 0.0), "black crop");
        for y in 0..4 {
            for x in 0..8 {
                assert_eq!(img.pixel(x, y), full_img.pixel(x + 12, y + 10));
            }
        }
    }

    // --seed changes the samples; the same seed gives the same bytes.
    let (s1, s1b, s2) = (d.join("s1.pfm"), d.join("s1b.pfm"), d.join("s2.pfm"));
    for (seed, o) in [("1", &s1), ("1", &s1b), ("2", &s2)] {
        ok(&run(pbrs()
            .args(["--seed", seed, "--spp", "2", "-q", "--outfile"])
            .arg(o)
            .arg(&s)));
    }
    assert_eq!(bytes(&s1), bytes(&s1b));
    assert_ne!(bytes(&s1), bytes(&s2), "--seed has no effect");
}

#[test]
fn exit_codes_and_quiet() {
    let d = tmp("exit");
    // A warning: an unused parameter.
    let text = small_scene().replace(
        r#"Shape "sphere" "float radius" [ 1 ]"#,
        r#"Shape "sphere" "float radius" [ 1 ] "float frobnicate" [ 1 ]"#,
    );
    let s = write(&d, "s.pbrt", &text);
    let o = d.join("o.pfm");
    let loud = run(pbrs().arg("--outfile").arg(&o).arg(&s));
    ok(&loud);
    assert!(stderr(&loud).contains("frobnicate"), "{}", stderr(&loud));
    for quiet in [vec!["--quiet"], vec!["-quiet"], vec!["-q"]] {
        let out = run(pbrs().args(&quiet).arg("--outfile").arg(&o).arg(&s));
        ok(&out);
        assert_eq!(stderr(&out), "", "{quiet:?} printed something");
        assert!(out.stdout.is_empty());
    }
    // glog's level 2 (errors) hides warnings but keeps the summary.
    let out = run(pbrs()
        .args(["--minloglevel", "2", "--outfile"])
        .arg(&o)
        .arg(&s));
    ok(&out);
    assert!(!stderr(&out).contains("frobnicate"), "{}", stderr(&out));
    assert!(stderr(&out).contains("40x30 px"));

    // Scene errors: 1, and the error is printed even with --quiet.
    let bad = write(
        &d,
        "bad.pbrt",
        "WorldBegin\nShape \"sphere\" \"float radius\" [ 1 \nWorldEnd\n",
    );
    let out = run(pbrs().args(["--quiet", "--outfile"]).arg(&o).arg(&bad));
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(stderr(&out).contains("never closed"), "{}", stderr(&out));
    let out = run(pbrs().arg(d.join("missing.pbrt")));
    assert_eq!(out.status.code(), Some(1));
    let out = run(pbrs().args(["--check"]).arg(&bad));
    assert_eq!(out.status.code(), Some(1));

    // Usage errors: 2.
    for args in [
        vec!["--frobnicate", "x.pbrt"],
        vec!["--nthreads"],
        vec!["--nthreads", "many", "x.pbrt"],
        vec!["--cropwindow", "0", "1"],
        vec!["--cat", "--toply", "x.pbrt"],
    ] {
        let out = run(pbrs().args(&args).stdin(Stdio::null()));
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
    }
    // A value a flag cannot take: 2, after the scene is read.
    for args in [
        vec!["--spp", "0"],
        vec!["--cropwindow", "0.5", "0.5", "0", "1"],
        vec!["--pixelbounds", "50", "60", "0", "10"],
        vec!["--partial-interval", "-1"],
    ] {
        let out = run(pbrs().args(&args).arg("--outfile").arg(&o).arg(&s));
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
    }
    // Empty input renders nothing (pbrt-v3 renders at WorldEnd).
    let empty = write(&d, "empty.pbrt", "# nothing\n");
    let out = run(pbrs().current_dir(&d).arg(&empty));
    ok(&out);
    assert!(
        stderr(&out).contains("nothing to render"),
        "{}",
        stderr(&out)
    );
    assert!(!d.join("pbrt.exr").exists());
    // Help in pbrt's spellings: 0, clap's generated text.
    for h in ["--help", "-help", "-h"] {
        let out = run(pbrs().arg(h));
        ok(&out);
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(
            text.contains("--nthreads") && text.contains("--display-server"),
            "{h}"
        );
    }
    // The subcommand keeps working.
    let out = run(pbrs().args(["converge", "--help"]));
    ok(&out);
    assert!(String::from_utf8_lossy(&out.stdout).contains("--spp-max"));
}

#[test]
fn several_files_render_as_one_scene_and_dash_reads_stdin() {
    let d = tmp("multi");
    let (da, db) = (d.join("a"), d.join("b"));
    std::fs::create_dir_all(&da).unwrap();
    std::fs::create_dir_all(&db).unwrap();
    // The world file names a texture relative to its own directory.
    std::fs::copy(
        repo().join("scenes/textures-env/pattern.png"),
        db.join("pattern.png"),
    )
    .unwrap();
    let whole = small_scene().replace(
        r#"Material "matte" "rgb Kd" [ 0.5 0.4 0.3 ]"#,
        "Texture \"p\" \"spectrum\" \"imagemap\" \"string filename\" \"pattern.png\"\nMaterial \"matte\" \"texture Kd\" \"p\"",
    );
    let (opts, world) = whole.split_at(whole.find("WorldBegin").unwrap());
    let one = write(&db, "whole.pbrt", &whole);
    let a = write(&da, "options.pbrt", opts);
    let b = write(&db, "world.pbrt", world);
    let (o1, o2, o3, o4) = (
        d.join("1.pfm"),
        d.join("2.pfm"),
        d.join("3.pfm"),
        d.join("4.pfm"),
    );
    ok(&run(pbrs().args(["-q", "--outfile"]).arg(&o1).arg(&one)));
    ok(&run(pbrs()
        .args(["-q", "--outfile"])
        .arg(&o2)
        .arg(&a)
        .arg(&b)));
    assert_eq!(bytes(&o1), bytes(&o2), "two files differ from one");

    // `-`: standard input, its file names relative to the current directory.
    let mut child = pbrs()
        .current_dir(&db)
        .args(["-q", "--outfile"])
        .arg(&o3)
        .arg("-")
        .stdin(Stdio::piped())
        .spawn()
        .unwrap();
    child
        .stdin
        .take()
        .unwrap()
        .write_all(whole.as_bytes())
        .unwrap();
    ok(&child.wait_with_output().unwrap());
    assert_eq!(bytes(&o1), bytes(&o3));
    // No file and standard input not a terminal: pbrt-v3 reads it.
    let mut child = pbrs()
        .current_dir(&db)
        .args(["-q", "--outfile"])
        .arg(&o4)
        .stdin(Stdio::piped())
        .spawn()
        .unwrap();
    child
        .stdin
        .take()
        .unwrap()
        .write_all(whole.as_bytes())
        .unwrap();
    ok(&child.wait_with_output().unwrap());
    assert_eq!(bytes(&o1), bytes(&o4));
}

#[test]
fn each_world_block_renders_in_turn_as_in_pbrt_v3() {
    let d = tmp("worlds");
    let film = |name: &str, w: u32| {
        format!(
            r#"Film "image" "integer xresolution" [ {w} ] "integer yresolution" [ 10 ] "string filename" [ "{name}" ]"#
        )
    };
    let a = write(
        &d,
        "a.pbrt",
        &scene(
            &film("a.pfm", 12),
            r#"Sampler "halton" "integer pixelsamples" [ 1 ]"#,
        ),
    );
    // The second scene's options must not leak from the first (pbrt-v3
    // starts afresh after WorldEnd): its default sampler has 16 spp.
    let b_text = scene(&film("b.pfm", 14), "").replace(
        r#"Material "matte" "rgb Kd" [ 0.5 0.4 0.3 ]"#,
        r#"Material "matte" "rgb Kd" [ 0.1 0.6 0.2 ]"#,
    );
    let b = write(&d, "b.pbrt", &b_text);
    let out = run(pbrs().current_dir(&d).arg(&a).arg(&b));
    ok(&out);
    let (ia, ib) = (image(&d.join("a.pfm")), image(&d.join("b.pfm")));
    assert_eq!((ia.width, ib.width), (12, 14));
    let both = [bytes(&d.join("a.pfm")), bytes(&d.join("b.pfm"))];
    // Each alone gives the same files.
    for (f, want) in [(&a, &both[0]), (&b, &both[1])] {
        std::fs::remove_file(d.join("a.pfm")).ok();
        std::fs::remove_file(d.join("b.pfm")).ok();
        ok(&run(pbrs().current_dir(&d).arg("-q").arg(f)));
        let name = if f == &a { "a.pfm" } else { "b.pfm" };
        assert_eq!(&bytes(&d.join(name)), want);
    }
    // Both world blocks in one file: the same two renders. Options after
    // the last WorldEnd render nothing, with a warning.
    let one = write(
        &d,
        "ab.pbrt",
        &format!(
            "{}{}Sampler \"halton\"\n",
            scene(
                &film("a.pfm", 12),
                r#"Sampler "halton" "integer pixelsamples" [ 1 ]"#
            ),
            b_text
        ),
    );
    std::fs::remove_file(d.join("a.pfm")).ok();
    std::fs::remove_file(d.join("b.pfm")).ok();
    let out = run(pbrs().current_dir(&d).arg(&one));
    ok(&out);
    assert!(
        stderr(&out).contains("after the last WorldEnd"),
        "{}",
        stderr(&out)
    );
    assert_eq!(bytes(&d.join("a.pfm")), both[0]);
    assert_eq!(bytes(&d.join("b.pfm")), both[1]);
}

/// Every scene file under `scenes/` (not the references).
fn all_scenes() -> Vec<PathBuf> {
    fn walk(d: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                if p.file_name().is_some_and(|n| n != "references") {
                    walk(&p, out);
                }
            } else if p.extension().is_some_and(|x| x == "pbrt") {
                out.push(p);
            }
        }
    }
    let mut v = Vec::new();
    walk(&repo().join("scenes"), &mut v);
    v.sort();
    assert!(v.len() > 20, "scenes/ not found");
    v
}

/// Small, fast renders: a quarter of the resolution, the centre, 1 spp.
const FAST: &[&str] = &[
    "--quick",
    "--spp",
    "1",
    "--cropwindow",
    "0.4",
    "0.6",
    "0.4",
    "0.6",
    "--quiet",
];

fn render_stdin(cwd: &Path, text: &[u8], out: &Path) -> Output {
    let mut child = pbrs()
        .current_dir(cwd)
        .args(FAST)
        .arg("--outfile")
        .arg(out)
        .arg("-")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    child.stdin.take().unwrap().write_all(text).unwrap();
    child.wait_with_output().unwrap()
}

#[test]
fn cat_and_toply_round_trip_on_every_scene() {
    let d = tmp("cat");
    for (i, s) in all_scenes().iter().enumerate() {
        let rel = s.strip_prefix(repo()).unwrap();
        let orig = d.join(format!("{i}-orig.pfm"));
        let out = run(pbrs().args(FAST).arg("--outfile").arg(&orig).arg(rel));
        ok(&out);
        // --cat with a relative path: names relative to the current directory.
        let cat = run(pbrs().arg("--cat").arg(rel));
        ok(&cat);
        let again = d.join(format!("{i}-cat.pfm"));
        ok(&render_stdin(&repo(), &cat.stdout, &again));
        assert_eq!(
            bytes(&orig),
            bytes(&again),
            "{}: --cat renders differently",
            rel.display()
        );
        // Printing the printed scene changes nothing.
        let mut child = pbrs()
            .args(["--cat", "-"])
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .unwrap();
        child.stdin.take().unwrap().write_all(&cat.stdout).unwrap();
        let twice = child.wait_with_output().unwrap();
        assert_eq!(
            String::from_utf8_lossy(&twice.stdout),
            String::from_utf8_lossy(&cat.stdout),
            "{}: --cat is not idempotent",
            rel.display()
        );
        // --toply from another directory, with an absolute scene path: PLY
        // files land there and the printed names stay valid from there.
        let work = d.join(format!("{i}-ply"));
        std::fs::create_dir_all(&work).unwrap();
        let ply = run(pbrs().current_dir(&work).arg("-toply").arg(s));
        ok(&ply);
        if ply.stdout != cat.stdout {
            let o = d.join(format!("{i}-ply.pfm"));
            ok(&render_stdin(&work, &ply.stdout, &o));
            assert_eq!(
                bytes(&orig),
                bytes(&o),
                "{}: --toply renders differently",
                rel.display()
            );
        }
    }
}

/// A grid of (n+1)² vertices with normals, uvs and face indices.
fn grid_mesh(n: usize, with_face_indices: bool) -> String {
    let (mut p, mut nn, mut uv, mut idx, mut fi) = (
        String::new(),
        String::new(),
        String::new(),
        String::new(),
        String::new(),
    );
    for j in 0..=n {
        for i in 0..=n {
            let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
            let (x, y) = (u * 2.0 - 1.0, v * 2.0 - 1.0);
            let z = 0.3 * (3.0 * x).sin() * (2.0 * y).cos();
            p += &format!("{x} {y} {z} ");
            let l = (1.0 + 0.2f64).sqrt();
            nn += &format!("{} {} {} ", 0.4 * x / l, 0.1 / l, 1.0 / l);
            uv += &format!("{u} {v} ");
        }
    }
    for j in 0..n {
        for i in 0..n {
            let a = j * (n + 1) + i;
            idx += &format!(
                "{} {} {} {} {} {} ",
                a,
                a + 1,
                a + n + 2,
                a,
                a + n + 2,
                a + n + 1
            );
            fi += &format!("{} {} ", j, j);
        }
    }
    let face = if with_face_indices {
        format!(" \"integer faceIndices\" [ {fi} ]")
    } else {
        String::new()
    };
    format!(
        "Shape \"trianglemesh\" \"point P\" [ {p} ] \"normal N\" [ {nn} ] \"float uv\" [ {uv} ] \"integer indices\" [ {idx} ]{face}\n"
    )
}

#[test]
fn toply_writes_big_meshes_to_ply_and_renders_the_same() {
    let d = tmp("toply");
    let text = format!(
        r#"LookAt 0 0 4  0 0 0  0 1 0
Camera "perspective" "float fov" [ 45 ]
Film "image" "integer xresolution" [ 48 ] "integer yresolution" [ 48 ]
Sampler "halton" "integer pixelsamples" [ 2 ]
WorldBegin
LightSource "point" "point from" [ 1 2 4 ] "rgb I" [ 20 20 20 ]
Texture "c" "spectrum" "checkerboard" "float uscale" [ 6 ] "float vscale" [ 6 ] "rgb tex1" [ 0.8 0.2 0.1 ] "rgb tex2" [ 0.1 0.3 0.8 ]
Material "plastic" "texture Kd" "c" "rgb Ks" [ 0.3 0.3 0.3 ]
AttributeBegin
  Translate -0.2 0 0
  {}AttributeEnd
Translate 0.2 0.1 -0.5
{}{}WorldEnd
"#,
        grid_mesh(20, true),
        grid_mesh(24, false),
        // A small mesh stays inline.
        "Shape \"trianglemesh\" \"point P\" [ -3 -3 -1 3 -3 -1 3 3 -1 ] \"integer indices\" [ 0 1 2 ]\n"
    );
    let s = write(&d, "grid.pbrt", &text);
    let work = d.join("work");
    std::fs::create_dir_all(&work).unwrap();
    let out = run(pbrs().current_dir(&work).arg("--toply").arg(&s));
    ok(&out);
    let printed = String::from_utf8(out.stdout).unwrap();
    assert_eq!(printed.matches("Shape \"plymesh\"").count(), 2, "{printed}");
    assert_eq!(printed.matches("Shape \"trianglemesh\"").count(), 1);
    assert!(printed.contains("\"mesh_00001.ply\"") && printed.contains("\"mesh_00002.ply\""));
    for f in ["mesh_00001.ply", "mesh_00002.ply"] {
        let b = bytes(&work.join(f));
        let head = String::from_utf8_lossy(&b[..400.min(b.len())]).into_owned();
        assert!(
            head.starts_with("ply\nformat binary_little_endian 1.0\n"),
            "{head}"
        );
        assert!(head.contains("property float nx") && head.contains("property float u"));
        // Our own reader takes it, with every vertex and triangle.
        let m = pbrs::loader::ply::read_ply(&b).unwrap_or_else(|e| panic!("{f}: {e}"));
        let n = if f.ends_with("1.ply") { 20 } else { 24 };
        assert_eq!(m.mesh.positions.len(), (n + 1) * (n + 1));
        assert_eq!(m.mesh.indices.len(), n * n * 6);
        assert!(m.mesh.normals.is_some() && m.mesh.uvs.is_some());
    }
    assert!(String::from_utf8_lossy(&bytes(&work.join("mesh_00001.ply"))).contains("face_indices"));
    // Byte-identical renders.
    let (a, b) = (d.join("a.pfm"), d.join("b.pfm"));
    ok(&run(pbrs().args(["-q", "--outfile"]).arg(&a).arg(&s)));
    let mut child = pbrs()
        .current_dir(&work)
        .args(["-q", "--outfile"])
        .arg(&b)
        .arg("-")
        .stdin(Stdio::piped())
        .spawn()
        .unwrap();
    child
        .stdin
        .take()
        .unwrap()
        .write_all(printed.as_bytes())
        .unwrap();
    ok(&child.wait_with_output().unwrap());
    assert_eq!(bytes(&a), bytes(&b), "--toply output renders differently");
    // $PLY_PREFIX names the files.
    let out = run(pbrs()
        .current_dir(&work)
        .env("PLY_PREFIX", "grid")
        .arg("--toply")
        .arg(&s));
    ok(&out);
    assert!(work.join("grid_00002.ply").is_file());
}

/// What a tiny tev server decoded: the image created and its channels.
#[derive(Default, Debug)]
struct TevState {
    name: String,
    width: i32,
    height: i32,
    channels: Vec<String>,
    values: Vec<Vec<f32>>,
    updates: usize,
    closed: bool,
}

fn cstr(b: &[u8], at: &mut usize) -> String {
    let end = b[*at..].iter().position(|&c| c == 0).expect("NUL") + *at;
    let s = String::from_utf8(b[*at..end].to_vec()).unwrap();
    *at = end + 1;
    s
}

fn i32_at(b: &[u8], at: &mut usize) -> i32 {
    let v = i32::from_le_bytes(b[*at..*at + 4].try_into().unwrap());
    *at += 4;
    v
}

/// Decodes tev IPC packets from `sock` until the peer closes.
fn tev_serve(mut sock: std::net::TcpStream) -> TevState {
    let mut st = TevState::default();
    loop {
        let mut len = [0u8; 4];
        if sock.read_exact(&mut len).is_err() {
            return st;
        }
        let n = u32::from_le_bytes(len) as usize;
        assert!(n >= 5, "packet length {n}");
        let mut b = vec![0u8; n - 4];
        sock.read_exact(&mut b).expect("truncated packet");
        let mut at = 1;
        match b[0] {
            4 => {
                at += 1; // grab focus
                st.name = cstr(&b, &mut at);
                st.width = i32_at(&b, &mut at);
                st.height = i32_at(&b, &mut at);
                let nc = i32_at(&b, &mut at);
                st.channels = (0..nc).map(|_| cstr(&b, &mut at)).collect();
                st.values = vec![vec![f32::NAN; (st.width * st.height) as usize]; nc as usize];
            }
            3 => {
                at += 1;
                assert_eq!(cstr(&b, &mut at), st.name);
                let ch = cstr(&b, &mut at);
                let c = st.channels.iter().position(|x| *x == ch).expect("channel");
                let (x, y, w, h) = (
                    i32_at(&b, &mut at),
                    i32_at(&b, &mut at),
                    i32_at(&b, &mut at),
                    i32_at(&b, &mut at),
                );
                assert!(x >= 0 && y >= 0 && x + w <= st.width && y + h <= st.height);
                assert_eq!(b.len() - at, (w * h * 4) as usize);
                for j in 0..h {
                    for i in 0..w {
                        let k = at + 4 * (j * w + i) as usize;
                        st.values[c][((y + j) * st.width + x + i) as usize] =
                            f32::from_le_bytes(b[k..k + 4].try_into().unwrap());
                    }
                }
                st.updates += 1;
            }
            2 => st.closed = true,
            t => panic!("unknown packet type {t}"),
        }
    }
}

#[test]
fn display_server_receives_the_final_image() {
    let d = tmp("tev");
    let s = write(&d, "s.pbrt", &small_scene());
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = listener.local_addr().unwrap();
    let server = std::thread::spawn(move || tev_serve(listener.accept().unwrap().0));
    let o = d.join("o.pfm");
    ok(&run(pbrs()
        .arg(format!("--display-server={addr}"))
        .args(["-q", "--outfile"])
        .arg(&o)
        .arg(&s)));
    let st = server.join().unwrap();
    let img = image(&o);
    assert_eq!((st.width, st.height), (40, 30));
    assert_eq!(st.channels, ["R", "G", "B"]);
    assert!(st.name.contains("o.pfm"), "{}", st.name);
    // Tiles while rendering, then the whole image.
    assert!(st.updates > 3, "{} updates", st.updates);
    for y in 0..30 {
        for x in 0..40 {
            let v = img.pixel(x, y);
            for c in 0..3 {
                let got = st.values[c][(y * 40 + x) as usize];
                assert_eq!(got.to_bits(), v[c].to_bits(), "pixel {x},{y} channel {c}");
            }
        }
    }
}

#[test]
fn a_lost_display_server_does_not_stop_the_render() {
    let d = tmp("tevlost");
    let s = write(
        &d,
        "s.pbrt",
        &scene(
            r#"Film "image" "integer xresolution" [ 160 ] "integer yresolution" [ 120 ]"#,
            r#"Sampler "halton" "integer pixelsamples" [ 4 ]"#,
        ),
    );
    let reference = d.join("ref.pfm");
    ok(&run(pbrs()
        .args(["-q", "--outfile"])
        .arg(&reference)
        .arg(&s)));
    // The server reads the create packet and a little more, then hangs up.
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = listener.local_addr().unwrap();
    let server = std::thread::spawn(move || {
        let (mut sock, _) = listener.accept().unwrap();
        let mut buf = [0u8; 600];
        let _ = sock.read_exact(&mut buf);
        drop(sock);
    });
    let o = d.join("o.pfm");
    let out = run(pbrs()
        .args(["--display-server", &addr.to_string(), "--outfile"])
        .arg(&o)
        .arg(&s));
    ok(&out);
    server.join().unwrap();
    assert_eq!(bytes(&reference), bytes(&o));
    // Nobody listening at all: a warning, and the image.
    let port = {
        let l = TcpListener::bind("127.0.0.1:0").unwrap();
        l.local_addr().unwrap().port()
    };
    let o2 = d.join("o2.pfm");
    let out = run(pbrs()
        .args([
            "--display-server",
            &format!("127.0.0.1:{port}"),
            "--outfile",
        ])
        .arg(&o2)
        .arg(&s));
    ok(&out);
    assert!(
        stderr(&out).contains("live view stopped"),
        "{}",
        stderr(&out)
    );
    assert_eq!(bytes(&reference), bytes(&o2));
}

#[test]
fn partial_images_are_written_whole_while_rendering() {
    let d = tmp("partial");
    let s = write(
        &d,
        "s.pbrt",
        &scene(
            r#"Film "image" "integer xresolution" [ 256 ] "integer yresolution" [ 192 ]"#,
            r#"Sampler "halton" "integer pixelsamples" [ 16 ]"#,
        ),
    );
    let o = d.join("o.pfm");
    let mut child = pbrs()
        .args([
            "--write-partial-images",
            "--partial-interval",
            "0",
            "--stats",
            "--nthreads",
            "2",
            "--outfile",
        ])
        .arg(&o)
        .arg(&s)
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Every time the file is there, it is a complete image.
    let mut seen = 0;
    let final_status = loop {
        if let Ok(b) = std::fs::read(&o) {
            let img = pbrs::image::io::parse_pfm(&b).expect("a half-written image");
            assert_eq!((img.width, img.height), (256, 192));
            seen += 1;
        }
        if let Some(st) = child.try_wait().unwrap() {
            break st;
        }
        std::thread::sleep(std::time::Duration::from_millis(2));
    };
    let mut err = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    assert!(final_status.success(), "{err}");
    let n: usize = err
        .split("partial images written: ")
        .nth(1)
        .and_then(|t| t.lines().next())
        .and_then(|t| t.trim().parse().ok())
        .unwrap_or_else(|| panic!("no partial count in {err}"));
    assert!(n >= 1, "{err}");
    eprintln!("{n} partial images written; the file was read whole {seen} times");
    // No temporary files are left behind, and the final image is the same
    // as without partial images.
    let left: Vec<_> = std::fs::read_dir(&d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n != "s.pbrt" && n != "o.pfm")
        .collect();
    assert!(left.is_empty(), "left behind: {left:?}");
    let plain = d.join("plain.pfm");
    ok(&run(pbrs().args(["-q", "--outfile"]).arg(&plain).arg(&s)));
    assert_eq!(bytes(&plain), bytes(&o));
}

/// `--spp` reaches the sampler as its kind takes it: `sobol`, `02sequence`
/// and `maxmindist` round up to a power of two with pbrt-v3's warning (the
/// summary's sample count shows what was taken); `halton` takes any count.
#[test]
fn spp_flag_is_rounded_as_the_sampler_rounds_it() {
    let d = tmp("spp-round");
    for (sampler, warning) in [
        ("sobol", "rounded up to 8 for SobolSampler"),
        ("02sequence", "rounded up to power of 2 (from 6 to 8)"),
        ("maxmindist", "rounded up to 8 for MaxMinDistSampler"),
        ("halton", ""),
    ] {
        let text = scene(
            "Film \"image\" \"integer xresolution\" 8 \"integer yresolution\" 8",
            &format!("Sampler \"{sampler}\" \"integer pixelsamples\" 4"),
        );
        let f = write(&d, &format!("{sampler}.pbrt"), &text);
        let out = d.join(format!("{sampler}.pfm"));
        let o = run(pbrs().arg(&f).args(["--spp", "6", "--outfile"]).arg(&out));
        ok(&o);
        let e = stderr(&o);
        if warning.is_empty() {
            assert!(!e.contains("--spp 6:"), "{sampler}: {e}");
        } else {
            assert!(
                e.contains("warning: --spp 6: ") && e.contains(warning),
                "{sampler}: {e}"
            );
        }
        let spp = if warning.is_empty() { 6 } else { 8 };
        assert!(
            e.contains(&format!("8x8 px, {spp} spp")),
            "{sampler}: {spp} spp not in {e}"
        );
    }
}
