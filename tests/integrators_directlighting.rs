//! `directlighting` on the Cornell box against pbrt-v3: strategy `all` with
//! the render-core criteria, strategy `one` unbiased (block means and mean),
//! and `path` with `maxdepth 1` with the same expected image.

mod common;
use common::*;
use pbrs::image::compare::block_error;
use pbrs::scene::{DirectStrategy, IntegratorSettings, LightSampleStrategy};

const STEM: &str = "cornell-direct";
const SCENE: &str = "scenes/cornell-direct.pbrt";

fn with_integrator(i: IntegratorSettings) -> pbrs::scene::SceneDescription {
    let mut d = load(SCENE);
    d.integrator = i;
    d
}

#[test]
fn strategy_all_matches_pbrt() {
    let d = load(SCENE);
    assert!(matches!(
        d.integrator,
        IntegratorSettings::DirectLighting(pbrs::scene::DirectLightingSettings {
            strategy: DirectStrategy::All,
            max_depth: 5
        })
    ));
    let (img, stats) = render_at(d, 128, 64, None);
    assert_eq!(stats.dropped_samples(), 0, "NaN/Inf/negative samples");
    assert_matches(STEM, &img, &reference(STEM), Bounds::against_pbrt(STEM));
}

/// Block-mean and mean criteria for an estimator whose noise differs from
/// pbrt-v3's `all`: `k` renders with independent scramblings are averaged,
/// and the block error allowed is twice the larger of pbrt-v3's own at 64 spp
/// and the noise the renders show among themselves (the block error of two
/// halves, scaled to the average of all `k`).
fn check_unbiased(name: &str, desc: pbrs::scene::SceneDescription, spp: u32, k: u64) {
    let imgs: Vec<_> = (0..k)
        .map(|s| {
            let (img, stats) = render_seeded(desc.clone(), 128, spp, 1 + s);
            assert_eq!(stats.dropped_samples(), 0, "{name}: dropped samples");
            img
        })
        .collect();
    let half = (k / 2) as usize;
    let a = average(&imgs[..half]);
    let b = average(&imgs[half..2 * half]);
    // a − b has twice the variance of one half, four times that of the
    // average of both halves (k even).
    let own_noise = block_error(&a, &b) / 2.0;
    let avg = average(&imgs);
    let pbrt = Bounds::against_pbrt(STEM);
    let bounds = Bounds {
        max_relative_mse: f64::INFINITY,
        max_block_error: pbrt.max_block_error.max(2.0 * own_noise),
        max_mean_difference: 0.01,
    };
    eprintln!("{name}: own block noise {own_noise:.5}");
    assert_matches(name, &avg, &reference(STEM), bounds);
}

#[test]
fn strategy_one_is_unbiased() {
    let d = with_integrator(IntegratorSettings::DirectLighting(
        pbrs::scene::DirectLightingSettings {
            max_depth: 5,
            strategy: DirectStrategy::One,
        },
    ));
    check_unbiased("cornell-direct-one", d, 64, 2);
}

#[test]
fn path_maxdepth_1_equals_directlighting() {
    for strategy in [
        LightSampleStrategy::Uniform,
        LightSampleStrategy::Power,
        LightSampleStrategy::Spatial,
    ] {
        let d = with_integrator(IntegratorSettings::Path(pbrs::scene::PathSettings {
            max_depth: 1,
            rr_threshold: 1.0,
            light_sample_strategy: strategy,
        }));
        check_unbiased(&format!("cornell-path-maxdepth1-{strategy:?}"), d, 64, 2);
    }
}

#[test]
fn whitted_matches_directlighting() {
    // All surfaces are matte and the lights are area lights, so Whitted's
    // light sampling (no MIS) has the same expectation as directlighting.
    let d = with_integrator(IntegratorSettings::Whitted(pbrs::scene::WhittedSettings {
        max_depth: 5,
    }));
    check_unbiased("cornell-whitted", d, 64, 2);
}

#[test]
fn strategy_all_with_several_light_samples_is_unbiased() {
    // nsamples 4 on the light: per-pixel arrays of 4 (Halton rounds counts
    // to powers of two) for each of the two light triangles at every depth.
    let mut d = load(SCENE);
    let mut n = 0;
    for s in d.shapes.iter_mut() {
        if let Some(a) = s.area_light.as_mut() {
            a.n_samples = 4;
            n += 1;
        }
    }
    assert!(n > 0);
    check_unbiased("cornell-direct-nsamples4", d, 64, 2);
}
