//! Closed-form checks: a camera at the centre of a closed sphere with inward
//! normals, matte Kd = 0.5 (scenes in `scenes/analytic/`, derivations in
//! their headers).
//!
//! - point light of intensity π at the centre: 0.5 in every pixel;
//! - the sphere emitting Le = 0.5 inward: 0.75 with one scattering event
//!   (directlighting, whitted, path maxdepth 1), Le·(1 + ρ + … + ρⁿ) with n.
//!
//! Tolerance: every pixel of these scenes has the same expectation, so the
//! spread of the pixel values measures the per-pixel standard deviation σ of
//! the estimator at this sample count. The image mean must lie within 4
//! standard errors (σ/√pixels) of the exact value, and every pixel within
//! 5.5σ (a Bonferroni bound for 3072 pixel channels: a Gaussian exceeds it
//! with probability 4e-8 each).
//!
//! Most of these estimators have no variance at all: with a point light at
//! the centre every sample is Kd/π · I/r²; inside the emitting sphere light
//! sampling by area has the solid-angle density cos θ/π, the same as cosine
//! BSDF sampling, so the MIS weights are ½ and every sample is exactly
//! ρ·Le. What is left is f32 rounding, largest for BSDF samples at grazing
//! angles (cos θ ≈ 1e-3: the hit point's rounding, ~3e-8 relative, becomes
//! a ~3e-8/cos²θ relative error of the light pdf, a few percent for that
//! one sample). So a floor of 1e-4·value is added to both bounds; the
//! measured worst pixel is below 4e-5. Path tracing with all bounces
//! (Russian roulette) has real variance and exercises the statistical bound.

mod common;
use common::*;
use pbrs::image::Image;
use pbrs::scene::{DirectStrategy, IntegratorSettings, LightSampleStrategy, SceneDescription};

fn direct(strategy: DirectStrategy) -> IntegratorSettings {
    IntegratorSettings::DirectLighting(pbrs::scene::DirectLightingSettings {
        max_depth: 5,
        strategy,
    })
}

fn path(max_depth: u32) -> IntegratorSettings {
    IntegratorSettings::Path(pbrs::scene::PathSettings {
        max_depth,
        rr_threshold: 1.0,
        light_sample_strategy: LightSampleStrategy::Spatial,
    })
}

fn check(name: &str, scene: &str, integrator: IntegratorSettings, spp: u32, expected: f64) -> f64 {
    let mut d: SceneDescription = load(scene);
    d.integrator = integrator;
    let (img, stats) = render_at(d, 32, spp, None);
    assert_eq!(stats.dropped_samples(), 0, "{name}: dropped samples");
    check_image(name, &img, expected)
}

fn check_image(name: &str, img: &Image, expected: f64) -> f64 {
    let v: Vec<f64> = img.data.iter().map(|&x| x as f64).collect();
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let sigma = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    let floor = 1e-4 * expected;
    let se = sigma / n.sqrt();
    let worst = v
        .iter()
        .map(|x| (x - expected).abs())
        .fold(0.0f64, f64::max);
    eprintln!(
        "{name}: mean {mean:.6} (exact {expected}), per-pixel σ {sigma:.2e}, standard error {se:.2e}, worst pixel off by {worst:.2e}"
    );
    assert!(
        (mean - expected).abs() <= 4.0 * se + floor,
        "{name}: mean {mean} is {:.1} standard errors from {expected}",
        (mean - expected).abs() / se
    );
    assert!(
        worst <= 5.5 * sigma + floor,
        "{name}: a pixel is {worst} from {expected} (σ {sigma})"
    );
    sigma
}

const POINT: &str = "scenes/analytic/sphere-point.pbrt";
const EMITTING: &str = "scenes/analytic/sphere-emitting.pbrt";

#[test]
fn point_light_at_the_centre_gives_one_half() {
    for (name, i) in [
        ("point/all", direct(DirectStrategy::All)),
        ("point/one", direct(DirectStrategy::One)),
        (
            "point/whitted",
            IntegratorSettings::Whitted(pbrs::scene::WhittedSettings { max_depth: 5 }),
        ),
        ("point/path-1", path(1)),
    ] {
        let sigma = check(name, POINT, i, 16, 0.5);
        // Every sample is exactly Kd/π · I/r² · cos 0: no variance.
        assert!(sigma < 1e-5, "{name}: σ {sigma}");
    }
}

#[test]
fn emitting_sphere_with_one_bounce_gives_three_quarters() {
    for (name, i) in [
        ("emitting/all", direct(DirectStrategy::All)),
        ("emitting/one", direct(DirectStrategy::One)),
        (
            "emitting/whitted",
            IntegratorSettings::Whitted(pbrs::scene::WhittedSettings { max_depth: 5 }),
        ),
        ("emitting/path-1", path(1)),
    ] {
        check(name, EMITTING, i, 64, 0.75);
    }
}

#[test]
fn emitting_sphere_with_more_bounces_sums_the_series() {
    // Le (1 + ρ + ρ²) with ρ = Le = 0.5; and all bounces (Russian roulette
    // after 3): Le / (1 − ρ) · (1 − ρ^65) = 1 to 2e-20.
    check("emitting/path-2", EMITTING, path(2), 64, 0.875);
    check("emitting/path-64", EMITTING, path(64), 256, 1.0);
}

const MIRROR: &str = "scenes/analytic/sphere-mirror.pbrt";
const GLASS: &str = "scenes/analytic/sphere-glass.pbrt";

/// Le (1 + r + … + r^(n−1)).
fn series(le: f64, r: f64, n: u32) -> f64 {
    (0..n).map(|k| le * r.powi(k as i32)).sum()
}

#[test]
fn specular_recursion_stops_at_maxdepth() {
    for max_depth in 1..=5 {
        for (scene, r) in [(MIRROR, 0.5), (GLASS, 0.04)] {
            let want = series(0.5, r, max_depth);
            for (kind, i) in [
                (
                    "all",
                    IntegratorSettings::DirectLighting(pbrs::scene::DirectLightingSettings {
                        max_depth,
                        strategy: DirectStrategy::All,
                    }),
                ),
                (
                    "one",
                    IntegratorSettings::DirectLighting(pbrs::scene::DirectLightingSettings {
                        max_depth,
                        strategy: DirectStrategy::One,
                    }),
                ),
                (
                    "whitted",
                    IntegratorSettings::Whitted(pbrs::scene::WhittedSettings { max_depth }),
                ),
            ] {
                let name = format!("{scene} {kind} maxdepth {max_depth}");
                let sigma = check(&name, scene, i, 4, want);
                assert!(sigma < 1e-5, "{name}: σ {sigma}");
            }
        }
    }
    // path counts emission after each specular bounce up to maxdepth
    // bounces (no Russian roulette before bounce 4).
    check("mirror path-3", MIRROR, path(3), 4, series(0.5, 0.5, 4));
}

#[test]
fn rays_with_negative_zero_direction_components_hit() {
    // Camera rays through pixel column 16 have x = 0, their mirror
    // reflections -0.0: these missed the sphere in the BVH (obvhs picks slab
    // planes by `d < 0.0`, false for -0.0, while the reciprocal was -1e30).
    use glam::Vec3;
    use pbrs::geometry::Ray;
    let sc = pbrs::integrators::RenderScene::new(&load(MIRROR));
    for d in [
        Vec3::new(-0.0, 0.590_631, -0.806_942),
        Vec3::new(0.0, 0.590_631, -0.806_942),
        Vec3::new(-0.0, -0.0, 1.0),
        Vec3::new(0.3, -0.0, -0.954),
    ] {
        let o = Vec3::new(0.0, -0.590_630_6, 0.806_941_2);
        assert!(
            sc.aggregate.intersect(&Ray::new(o, d)).is_some(),
            "{d:?} misses"
        );
        assert!(sc.aggregate.intersect(&Ray::new(Vec3::ZERO, d)).is_some());
    }
}
