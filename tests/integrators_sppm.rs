//! `sppm` (stochastic progressive photon mapping): its image does not
//! depend on the thread count, it converges to the path tracer's image on a
//! diffuse scene (where both are consistent), it finds the caustic of a
//! point light through glass that the path tracer renders black, it writes
//! intermediate images where `imagewritefrequency` asks, and its bad
//! parameters are located warnings. Its image against pbrt-v3's converged
//! sppm is a golden scene (`scenes/sppm/caustic.pbrt`, see
//! `scenes/references/golden.txt`).

mod common;

use common::{block_means, load, load_text, render_threads, repo, warning_text};
use pbrs::image::Image;
use pbrs::integrators::{PathSettings, SppmSettings};
use pbrs::scene::{IntegratorSettings, SceneDescription};

fn mean(img: &Image) -> f64 {
    img.data.iter().map(|&v| v as f64).sum::<f64>() / img.data.len() as f64
}

/// The caustic scene with fewer iterations (the golden test renders it
/// as written).
fn caustic(iterations: u32) -> SceneDescription {
    let mut d = load("scenes/sppm/caustic.pbrt");
    let IntegratorSettings::Sppm(s) = &mut d.integrator else {
        panic!("not sppm")
    };
    s.iterations = iterations;
    d
}

/// The Cornell box (`cornell-path`) at `w`×`h` pixels.
fn cornell(w: u32, h: u32) -> SceneDescription {
    let mut d = load("scenes/cornell-path.pbrt");
    d.film.xresolution = w;
    d.film.yresolution = h;
    d
}

/// `sppm` with these iterations, photons per iteration, maximum depth and
/// radius.
fn sppm(iterations: u32, photons: u32, max_depth: u32, radius: f32) -> IntegratorSettings {
    IntegratorSettings::Sppm(SppmSettings {
        iterations,
        photons_per_iteration: photons,
        max_depth,
        radius,
        write_frequency: 0,
    })
}

#[test]
fn the_image_does_not_depend_on_the_thread_count() {
    let mut d = caustic(6);
    // Not a multiple of the photon chunk: a short last chunk.
    if let IntegratorSettings::Sppm(s) = &mut d.integrator {
        s.photons_per_iteration = 20_000;
    }
    let a = render_threads(&d, 1);
    let b = render_threads(&d, 2);
    assert!(mean(&a) > 0.0);
    common::assert_bit_identical(&a, &b, "1 and 2 threads");
}

/// The same on the Cornell box, triangles only, where a row's camera paths
/// and a chunk's photons are traced sixteen side by side (a row of 20
/// pixels and chunks of 256 photons end with partly filled lanes).
#[test]
fn side_by_side_paths_do_not_depend_on_the_thread_count() {
    let mut d = cornell(20, 12);
    d.integrator = sppm(4, 3000, 5, 0.1);
    let a = render_threads(&d, 1);
    let b = render_threads(&d, 2);
    assert!(mean(&a) > 0.0);
    common::assert_bit_identical(&a, &b, "1 and 2 threads");
}

#[test]
fn the_caustic_path_cannot_find_is_there() {
    let d = caustic(16);
    let sppm = render_threads(&d, 2);
    let mut p = d.clone();
    p.integrator = IntegratorSettings::Path(PathSettings {
        max_depth: 8,
        ..PathSettings::default()
    });
    p.sampler.pixel_samples = 64;
    let path = render_threads(&p, 2);
    // The caustic is under the sphere, in its shadow: the brightest pixel
    // of sppm's image, (nearly) black in the path tracer's.
    let lum = |img: &Image, i: usize| img.data[3 * i..3 * i + 3].iter().sum::<f32>();
    let n = (sppm.width * sppm.height) as usize;
    let brightest = (0..n)
        .max_by(|&a, &b| lum(&sppm, a).total_cmp(&lum(&sppm, b)))
        .unwrap();
    assert!(lum(&sppm, brightest) > 1.0, "{}", lum(&sppm, brightest));
    assert!(
        lum(&path, brightest) < 0.05 * lum(&sppm, brightest),
        "path {} sppm {}",
        lum(&path, brightest),
        lum(&sppm, brightest)
    );
}

/// A diffuse scene (the Cornell box: matte surfaces and an area light),
/// where both are consistent: sppm's image converges to the path tracer's,
/// by the image mean and 4×4 block means.
#[test]
fn on_a_diffuse_scene_sppm_converges_to_path() {
    let mut d = cornell(16, 16);
    let mut p = d.clone();
    p.sampler.pixel_samples = 4096;
    d.integrator = sppm(256, 16384, 8, 0.04);
    let sppm = render_threads(&d, 2);
    let path = render_threads(&p, 2);
    let (ms, mp) = (mean(&sppm), mean(&path));
    assert!((ms - mp).abs() < 0.02 * mp, "means: sppm {ms}, path {mp}");
    let (bs, bp) = (block_means(&sppm, 4), block_means(&path, 4));
    for (i, (s, p)) in bs.iter().zip(&bp).enumerate() {
        assert!(
            (s - p).abs() < 0.06 * p.max(0.05),
            "block {i}: sppm {s}, path {p}"
        );
    }
}

#[test]
fn intermediate_images_are_written() {
    let mut d = caustic(4);
    if let IntegratorSettings::Sppm(s) = &mut d.integrator {
        s.write_frequency = 2;
    }
    let dir = repo().join("target/test-output/sppm-writes");
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("caustic.pfm");
    let _ = std::fs::remove_file(&out);
    d.film.filename = out.clone();
    let img = render_threads(&d, 2);
    // Written after iteration 2 (the end's image is the caller's to write).
    let written = pbrs::image::io::read_image(&out).expect("an intermediate image");
    assert_eq!((written.width, written.height), (img.width, img.height));
    assert!(mean(&written) > 0.0);
    assert_ne!(written.data, img.data);
}

#[test]
fn bad_parameters_are_located_warnings() {
    let scene = |params: &str| {
        format!("Integrator \"sppm\" {params}\nWorldBegin\nLightSource \"point\"\nWorldEnd\n")
    };
    for (params, want) in [
        (
            "\"integer iterations\" 0",
            "\"iterations\" is 0: it must be ≥ 1; 64 is used",
        ),
        (
            "\"integer numiterations\" -3",
            "\"numiterations\" is -3: it must be ≥ 1; 64 is used",
        ),
        (
            "\"integer photonsperiteration\" 0",
            "\"photonsperiteration\" is 0: it must be ≥ 1 (or -1, one per pixel)",
        ),
        (
            "\"float radius\" -1",
            "\"radius\" is -1: it must be a positive number; 1 is used",
        ),
        (
            "\"integer imagewritefrequency\" 0",
            "\"imagewritefrequency\" is 0: it must be ≥ 1",
        ),
    ] {
        let loaded = load_text(&scene(params));
        let w = warning_text(&loaded);
        assert!(w.contains(want), "{params}: {w}");
        assert!(w.contains("mem.pbrt:1:"), "{params}: not located: {w}");
        let IntegratorSettings::Sppm(s) = loaded.scene.integrator else {
            panic!("not sppm")
        };
        assert!(s.iterations >= 1 && s.radius > 0.0);
    }
    // `numiterations` is read when `iterations` is absent.
    let loaded = load_text(&scene("\"integer numiterations\" 7"));
    let IntegratorSettings::Sppm(s) = loaded.scene.integrator else {
        panic!()
    };
    assert_eq!(s.iterations, 7);
    // A scene with no lights and a tiny film renders black, without panic.
    let mut d =
        load_text(&scene("\"integer iterations\" 2").replace("LightSource \"point\"", "")).scene;
    d.film.xresolution = 4;
    d.film.yresolution = 3;
    assert_eq!(mean(&render_threads(&d, 2)), 0.0);
}
