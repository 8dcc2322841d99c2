//! Golden images: every scene in `scenes/` is rendered small and compared
//! with its converged reference by noise-aware metrics (relative MSE within a
//! stated factor of the noise expected at that sample count, block means that
//! catch bias, image means within 1%). Failures leave the render, the
//! reference and a false-colour difference in `target/test-output/NAME/`.
//! References are never rewritten by tests; pbrs-made ones are regenerated
//! deliberately with `cargo run --release --example make_references`.

mod common;
#[allow(dead_code)]
#[path = "common/golden.rs"]
mod golden;

use common::*;
use golden::{manifest, Check, PBRS_REFERENCE_SPP};
use pbrs::image::io::read_image;
use pbrs::image::verdict::{self, Noise};

fn walk(dir: &std::path::Path, out: &mut Vec<String>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            walk(&p, out);
        } else if p.extension().is_some_and(|x| x == "pbrt") {
            out.push(
                p.strip_prefix(repo())
                    .unwrap()
                    .to_string_lossy()
                    .replace('\\', "/"),
            );
        }
    }
}

#[test]
fn every_scene_has_a_golden_entry() {
    let entries = manifest(&repo());
    let mut scenes = Vec::new();
    walk(&repo().join("scenes"), &mut scenes);
    for s in &scenes {
        assert!(
            entries.iter().any(|e| &e.scene == s),
            "{s} has no entry in scenes/references/golden.txt"
        );
    }
    for e in &entries {
        assert!(
            repo().join(&e.scene).exists(),
            "golden.txt names a missing scene {}",
            e.scene
        );
        match &e.check {
            Check::Pbrt(stem) | Check::PbrtOwnNoise(stem) => {
                assert!(reference_path(stem).exists())
            }
            Check::Pbrs(name) => assert!(
                repo()
                    .join(format!("scenes/references/{name}-128-pbrs.pfm"))
                    .exists(),
                "{name}: run make_references"
            ),
            Check::Test(file) => {
                let text = std::fs::read_to_string(repo().join(file)).unwrap();
                assert!(text.contains(&e.scene), "{file} does not test {}", e.scene);
            }
        }
    }
}

/// The golden renders: 64 spp with a given sampler seed, at the size of the
/// reference (128×128 for most scenes).
fn render_golden(
    scene: &str,
    reference: &pbrs::image::Image,
    seed: u64,
) -> (pbrs::image::Image, pbrs::render::driver::RenderStats) {
    render_seeded_wh(load(scene), reference.width, reference.height, 64, seed)
}

fn check(kind: &str) {
    let mut checked = 0;
    let mut failed: Vec<String> = Vec::new();
    for e in manifest(&repo()) {
        let name = e
            .scene
            .trim_start_matches("scenes/")
            .trim_end_matches(".pbrt")
            .replace('/', "-");
        match &e.check {
            Check::Pbrt(stem) if kind == "pbrt" => {
                checked += 1;
                // Every scene is checked and reported, not only up to the
                // first that fails.
                let run = std::panic::catch_unwind(|| {
                    let r = reference(stem);
                    let (img, stats) = render_golden(&e.scene, &r, 0);
                    assert_eq!(stats.dropped_samples(), 0, "{}", e.scene);
                    assert_matches(&name, &img, &r, Bounds::against_pbrt(stem));
                });
                if run.is_err() {
                    failed.push(name);
                }
            }
            Check::Pbrs(_) | Check::PbrtOwnNoise(_) if kind == "own-noise" => {
                checked += 1;
                let reference = match &e.check {
                    Check::Pbrs(r) => {
                        read_image(&repo().join(format!("scenes/references/{r}-128-pbrs.pfm")))
                            .unwrap()
                    }
                    Check::PbrtOwnNoise(stem) => reference(stem),
                    _ => unreachable!(),
                };
                let (a, stats) = render_golden(&e.scene, &reference, 0);
                assert_eq!(stats.dropped_samples(), 0, "{}", e.scene);
                // The noise of one 64-spp render, measured against a second,
                // independently seeded one: E[relMSE(a, b)] = 2 × noise. The
                // estimate is itself noisy (relative MSE is dominated by a few
                // pixels at light edges), so the stated factor is 2, not 1.5.
                let (b, _) = render_golden(&e.scene, &reference, 1);
                // The reference's own noise is 64/PBRS_REFERENCE_SPP of a
                // render's; the means are held to 1%.
                let noise = Noise::measure(&a, &b);
                let bounds = verdict::Bounds {
                    max_mean_difference: 0.01,
                    ..noise.bounds(PBRS_REFERENCE_SPP as f64 / 64.0, 2.0, 1.0)
                };
                assert_matches(&name, &a, &reference, bounds);
            }
            _ => {}
        }
    }
    assert!(checked > 0, "no scene of kind {kind} was checked");
    assert!(
        failed.is_empty(),
        "scenes that do not match: {}",
        failed.join(", ")
    );
}

#[test]
fn scenes_with_pbrt_references_match() {
    check("pbrt");
}

#[test]
fn scenes_checked_against_their_own_noise_match() {
    check("own-noise");
}

#[test]
fn the_metric_catches_bias_that_noise_hides() {
    // pbrt-v3's own 64-spp render passes its bounds; scaled by 3% it must
    // fail them (the block means see it although per-pixel noise is larger).
    let stem = "cornell-path";
    let b = Bounds::against_pbrt(stem);
    let mut img = pbrt_64(stem);
    assert!(within(&img, &reference(stem), b));
    for v in &mut img.data {
        *v *= 1.03;
    }
    assert!(!within(&img, &reference(stem), b));
}
