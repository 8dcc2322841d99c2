//! Stiff and extreme cases (`scenes/stress/`): each asserts the right answer,
//! not only finiteness, and that no sample was NaN, infinite or negative.

mod common;
use common::*;
use pbrs::image::Image;
use pbrs::render::driver::RenderStats;

fn render_file(rel: &str, res: Option<u32>, spp: Option<u32>) -> (Image, RenderStats) {
    let mut desc = load(rel);
    if let Some(r) = res {
        desc.film.xresolution = r;
        desc.film.yresolution = r;
    }
    if let Some(s) = spp {
        desc.sampler.pixel_samples = s;
    }
    let (img, stats) =
        pbrs::render::driver::render(&desc, &Default::default(), &|_, _| {}).unwrap();
    assert_eq!(
        stats.dropped_samples(),
        0,
        "{rel}: NaN/Inf/negative samples"
    );
    assert!(
        img.data.iter().all(|v| v.is_finite()),
        "{rel}: non-finite pixel"
    );
    (img, stats)
}

/// Mean of the first channel over pixels, and its standard error estimated
/// from the spread of the pixels (each pixel is an independent estimate).
fn mean_and_stderr(img: &Image) -> (f64, f64) {
    let v: Vec<f64> = img.data.chunks(3).map(|p| p[0] as f64).collect();
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (n - 1.0);
    (m, (var / n).sqrt())
}

#[test]
fn albedo_099_in_an_emitting_sphere_converges_to_one() {
    // Le / (1 - ρ) = 0.01 / 0.01 = 1; paths reach thousands of bounces, far
    // past the 1000 Halton dimensions at which pbrt-v3 aborts.
    let (img, _) = render_file("scenes/stress/albedo99.pbrt", None, Some(256));
    let (m, se) = mean_and_stderr(&img);
    eprintln!("albedo 0.99: mean {m:.4} ± {se:.4}");
    assert!(
        (m - 1.0).abs() < 4.0 * se + 1e-3,
        "mean {m}, standard error {se}"
    );
    assert!(se < 0.02, "suspiciously noisy: {se}");
}

#[test]
fn tiny_light_matches_the_point_light_limit() {
    // Plane radiance 0.5 / d⁴ (see the scene file), averaged over each pixel.
    // 256 spp: the pixel-footprint (antialiasing) noise drops to ~0.2%.
    let (img, _) = render_file("scenes/stress/tiny-light.pbrt", None, Some(256));
    let t = (15.0f64).to_radians().tan();
    let n = img.width;
    let mut worst = 0.0f64;
    let mut sum_ratio = 0.0f64;
    for j in 0..n {
        for i in 0..n {
            let mut sum = 0.0;
            let k = 16;
            for sj in 0..k {
                for si in 0..k {
                    let sx = -1.0 + 2.0 * (i as f64 + (si as f64 + 0.5) / k as f64) / n as f64;
                    let sy = 1.0 - 2.0 * (j as f64 + (sj as f64 + 0.5) / k as f64) / n as f64;
                    let (x, y) = (5.0 * sx * t, 5.0 * sy * t);
                    let d2 = x * x + y * y + 1.0;
                    sum += 0.5 / (d2 * d2);
                }
            }
            let expect = sum / (k * k) as f64;
            let got = img.pixel(i, j).x as f64;
            worst = worst.max((got - expect).abs() / expect);
            sum_ratio += got / expect;
        }
    }
    let mean_ratio = sum_ratio / (n * n) as f64;
    eprintln!("tiny light: worst relative pixel error {worst:.2e}, mean ratio {mean_ratio:.5}");
    assert!(worst < 0.01, "worst relative error {worst}");
    assert!(
        (mean_ratio - 1.0).abs() < 1e-3,
        "bias: mean ratio {mean_ratio}"
    );
}

/// White furnace: every pixel must be `expect`. Single samples are exact
/// except where Russian roulette fires (β·etaScale rounds just below 1), so
/// pixels agree within their own noise and the mean within 4 standard errors.
fn furnace(rel: &str, expect: f64) {
    let (img, _) = render_file(rel, None, Some(64));
    let (m, se) = mean_and_stderr(&img);
    eprintln!("{rel}: mean {m:.5} ± {se:.5} (expect {expect})");
    assert!(
        (m - expect).abs() < 4.0 * se + 1e-4 * expect,
        "{rel}: mean {m}, expected {expect}"
    );
    for p in img.data.chunks(3) {
        assert!(
            (p[0] as f64 - expect).abs() < 0.1 * expect,
            "{rel}: pixel {}",
            p[0]
        );
    }
}

#[test]
fn glass_in_a_white_furnace_stays_one() {
    furnace("scenes/stress/furnace-glass.pbrt", 1.0);
    furnace("scenes/stress/furnace-glass-index10.pbrt", 1.0);
    furnace("scenes/stress/furnace-slab-grazing.pbrt", 1.0);
}

#[test]
fn glass_of_index_one_disappears() {
    let (img, _) = render_file("scenes/stress/furnace-glass-index1.pbrt", None, None);
    assert!(img.data.iter().all(|&v| (v - 1.0).abs() < 1e-6));
}

#[test]
fn camera_inside_glass_sees_radiance_scaled_by_eta_squared() {
    furnace("scenes/stress/furnace-glass-inside.pbrt", 2.25);
}

#[test]
fn degenerate_input_renders_without_nan() {
    let (img, stats) = render_file("scenes/stress/degenerate.pbrt", None, None);
    // The box is still lit (the degenerate pieces add nothing that emits).
    let (m, _) = mean_and_stderr(&img);
    assert!(m > 0.05, "mean {m}");
    assert!(
        stats
            .notes
            .iter()
            .any(|n| n.contains("zero-area triangles left out")),
        "{:?}",
        stats.notes
    );
    assert!(
        stats.notes.iter().any(|n| n.contains("zero power")),
        "{:?}",
        stats.notes
    );
}

#[test]
fn no_lights_and_empty_scenes_are_black() {
    for rel in ["scenes/stress/no-lights.pbrt", "scenes/stress/empty.pbrt"] {
        let (img, _) = render_file(rel, None, None);
        assert!(img.data.iter().all(|&v| v == 0.0), "{rel}");
    }
    let (_, stats) = render_file("scenes/stress/empty.pbrt", None, None);
    assert!(
        stats.notes.iter().any(|n| n.contains("no BVH")),
        "{:?}",
        stats.notes
    );
}

#[test]
fn disabling_russian_roulette_keeps_the_expected_image() {
    let (img, _) = render_file(
        "scenes/stress/cornell-no-roulette.pbrt",
        Some(128),
        Some(64),
    );
    assert_matches(
        "cornell-no-roulette",
        &img,
        &reference("cornell-path"),
        Bounds::against_pbrt("cornell-path"),
    );
}

#[test]
fn a_hall_of_mirrors_100000_deep_does_not_exhaust_the_stack() {
    for integrator in ["directlighting", "whitted"] {
        let mut desc = load("scenes/stress/mirrors-deep.pbrt");
        if integrator == "whitted" {
            desc.integrator =
                pbrs::scene::IntegratorSettings::Whitted(pbrs::scene::WhittedSettings {
                    max_depth: 100_000,
                });
        }
        let (img, stats) =
            pbrs::render::driver::render(&desc, &Default::default(), &|_, _| {}).unwrap();
        assert_eq!(stats.dropped_samples(), 0);
        assert!(
            img.data.iter().all(|&v| v == 0.0),
            "{integrator}: a point light is invisible to specular paths"
        );
        // 16 camera rays, nearly all bouncing between the mirrors to maxdepth.
        assert!(
            stats.rays.closest > 1_000_000,
            "{integrator}: only {} rays",
            stats.rays.closest
        );
    }
}

#[test]
fn singular_transforms_leave_shapes_out_without_nan() {
    // The lit unit sphere alone: its centre pixel sees the point light head on,
    // L = Kd/π · I / d² · cos = 0.5/π · 25 / 16 at the nearest point (d = 4).
    let (img, _) = render_file("scenes/stress/singular.pbrt", None, None);
    let c = img.pixel(8, 8).x as f64;
    let expect = 0.5 / std::f64::consts::PI * 25.0 / 16.0;
    assert!(
        (c - expect).abs() < 0.03 * expect,
        "centre {c}, expected about {expect}"
    );
}
