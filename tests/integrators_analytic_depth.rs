//! Analytic scenes with exact answers (scenes/analytic/depth-*.pbrt): the
//! camera inside a closed unit sphere with inward normals and Kd 0.5.
//! - point light of intensity π at the centre (or several summing to π):
//!   path with maxdepth D gives 1 − 0.5^D, directlighting gives 0.5;
//! - the sphere emitting Le = 0.5: path gives 1 − 0.5^(D+1), directlighting 0.75.
//!
//! Checked for both samplers (halton, random). The tolerance comes from the
//! render itself: the mean over pixels must be within 4 standard errors,
//! estimated from the spread of the pixels (each pixel an independent
//! estimate), plus 1e-5 for float rounding where a render has no variance.

mod common;
use common::*;
use pbrs::render::driver::{render, RenderOptions};
use pbrs::scene::{DirectStrategy, IntegratorSettings, LightSampleStrategy, SamplerKind};

fn check(scene: &str, integrator: IntegratorSettings, sampler: SamplerKind, expect: f64) {
    let mut desc = load(scene);
    desc.integrator = integrator;
    desc.sampler.kind = sampler;
    desc.sampler.pixel_samples = 128;
    let (img, stats) = render(&desc, &RenderOptions::default(), &|_, _| {}).unwrap();
    assert_eq!(stats.dropped_samples(), 0);
    let v: Vec<f64> = img.data.iter().map(|&x| x as f64).collect();
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1.0);
    let se = (var / n).sqrt();
    eprintln!("{scene} {integrator:?} {sampler:?}: {mean:.5} ± {se:.5}, expected {expect:.5}");
    assert!(
        (mean - expect).abs() <= 4.0 * se + 1e-5,
        "{scene} {integrator:?} {sampler:?}: mean {mean} ± {se}, expected {expect}"
    );
}

fn path(d: u32) -> IntegratorSettings {
    IntegratorSettings::Path(pbrs::scene::PathSettings {
        max_depth: d,
        rr_threshold: 1.0,
        light_sample_strategy: LightSampleStrategy::Spatial,
    })
}

const SAMPLERS: [SamplerKind; 2] = [SamplerKind::Halton, SamplerKind::Random];

#[test]
fn point_light_at_the_centre_gives_one_minus_half_to_the_depth() {
    for scene in [
        "scenes/analytic/depth-point.pbrt",
        "scenes/analytic/depth-point-split.pbrt",
    ] {
        for s in SAMPLERS {
            for d in [1, 2, 3, 5, 8] {
                check(scene, path(d), s, 1.0 - 0.5f64.powi(d as i32));
            }
            for strategy in [DirectStrategy::All, DirectStrategy::One] {
                check(
                    scene,
                    IntegratorSettings::DirectLighting(pbrs::scene::DirectLightingSettings {
                        max_depth: 5,
                        strategy,
                    }),
                    s,
                    0.5,
                );
            }
        }
    }
}

#[test]
fn emitting_sphere_gives_one_minus_half_to_the_depth_plus_one() {
    let scene = "scenes/analytic/depth-emitting.pbrt";
    for s in SAMPLERS {
        for d in [1, 2, 3, 5] {
            check(scene, path(d), s, 1.0 - 0.5f64.powi(d as i32 + 1));
        }
        for strategy in [DirectStrategy::All, DirectStrategy::One] {
            check(
                scene,
                IntegratorSettings::DirectLighting(pbrs::scene::DirectLightingSettings {
                    max_depth: 5,
                    strategy,
                }),
                s,
                0.75,
            );
        }
    }
}
