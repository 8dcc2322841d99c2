//! Render-core properties: scale invariance of robust ray origins, images
//! independent of the thread count, and the output file contract.

mod common;
use common::*;
use pbrs::loader::load_scene_str;
use pbrs::render::film::compare::relative_mse;
use std::process::Command;

/// The Cornell box with geometry and camera scaled by `s` (radiance is
/// scale-invariant, so the image must not change).
fn scaled_cornell(s: f64) -> pbrs::scene::SceneDescription {
    let text = std::fs::read_to_string(repo().join("scenes/cornell-path.pbrt")).unwrap();
    let look = "LookAt 0 1 6.8  0 1 0  0 1 0";
    assert!(text.contains(look));
    let text = text
        .replace(
            look,
            &format!("LookAt 0 {} {}  0 {} 0  0 1 0", s, 6.8 * s, s),
        )
        .replace("WorldBegin", &format!("WorldBegin\nScale {s} {s} {s}"));
    // A virtual file beside the real one, so Includes resolve.
    match load_scene_str(&text, &repo().join("scenes/cornell-path-scaled.pbrt")) {
        Ok(l) => l.scene,
        Err(f) => panic!("{:?}", f.errors),
    }
}

#[test]
fn scaled_cornell_box_renders_the_same_image() {
    let (base, _) = render_at(scaled_cornell(1.0), 64, 16, None);
    for s in [1e-4, 1e5] {
        let (img, stats) = render_at(scaled_cornell(s), 64, 16, None);
        assert_eq!(stats.dropped_samples(), 0);
        let e = relative_mse(&img, &base);
        eprintln!("scale {s:e}: relative MSE against the unscaled box {e:.2e}");
        assert!(
            e < 1e-4,
            "scale {s}: relative MSE {e} against the unscaled render"
        );
    }
}

fn pbrs() -> Command {
    Command::new(env!("CARGO_BIN_EXE_pbrs"))
}

#[test]
fn thread_count_does_not_change_the_file() {
    let dir = output_dir("threads");
    let mut files = Vec::new();
    for threads in [1, 2, 3] {
        let out = dir.join(format!("t{threads}.exr"));
        let _ = std::fs::remove_file(&out);
        // The Bitterli box uses a triangle filter of radius 1: tiles overlap.
        let st = pbrs()
            .args([
                "scenes/cornell-box.pbrt",
                "--spp",
                "4",
                "--cropwindow",
                "0.3",
                "0.6",
                "0.25",
                "0.55",
                "--quiet",
                "--threads",
            ])
            .arg(threads.to_string())
            .arg("--outfile")
            .arg(&out)
            .current_dir(repo())
            .status()
            .unwrap();
        assert!(st.success());
        files.push(std::fs::read(&out).unwrap());
    }
    assert!(files[0].len() > 1000);
    assert_eq!(files[0], files[1], "1 and 2 threads differ");
    assert_eq!(files[0], files[2], "1 and 3 threads differ");
}

#[test]
fn bad_output_extension_fails_before_rendering_and_writes_nothing() {
    let dir = output_dir("badext");
    let out = dir.join("image.jpg");
    let _ = std::fs::remove_file(&out);
    let o = pbrs()
        .args([
            "scenes/cornell-box.pbrt",
            "--spp",
            "1",
            "--quiet",
            "--outfile",
        ])
        .arg(&out)
        .current_dir(repo())
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(!out.exists());
    assert!(String::from_utf8_lossy(&o.stderr).contains("image.jpg"));
}

#[test]
fn invalid_overrides_are_errors() {
    // Usage errors (exit 2), found before rendering. `--threads 0` is not
    // one: pbrt-v3's `--nthreads 0` means one thread per core; a reversed
    // crop window is ordered, as pbrt-v3 does (tests/cli.rs covers both).
    for args in [
        &["--spp", "0"][..],
        &["--cropwindow", "0.5", "0.5", "0", "1"],
        &["--threads", "-1"],
    ] {
        let o = pbrs()
            .arg("scenes/cornell-box.pbrt")
            .args(args)
            .arg("--quiet")
            .current_dir(repo())
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "{args:?}");
    }
}

#[test]
fn renders_png_pfm_and_exr() {
    let dir = output_dir("formats");
    for ext in ["png", "pfm", "exr"] {
        let out = dir.join(format!("img.{ext}"));
        let _ = std::fs::remove_file(&out);
        let st = pbrs()
            .args([
                "scenes/cornell-path.pbrt",
                "--spp",
                "1",
                "--cropwindow",
                "0.4",
                "0.5",
                "0.4",
                "0.5",
                "--quiet",
                "--outfile",
            ])
            .arg(&out)
            .current_dir(repo())
            .status()
            .unwrap();
        assert!(st.success());
        let img = pbrs::render::film::io::read_image(&out).unwrap();
        assert_eq!((img.width, img.height), (51, 51), "{ext}");
    }
}

#[test]
fn a_film_too_large_for_memory_is_an_error_not_an_abort() {
    let out = output_dir("huge").join("huge.exr");
    let o = pbrs()
        .args(["tests/inputs/huge-film.pbrt", "--quiet", "--outfile"])
        .arg(&out)
        .current_dir(repo())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("the film needs"), "{err}");
    assert!(!out.exists());
}
