//! Light distributions (which light `directlighting` strategy `one` and
//! `path` sample) and area-light sampling against its density.
//!
//! - power: lights are picked in proportion to their emitted power,
//!   computed here from the scene's numbers, not from `Light::power`;
//! - uniform: 1/n each; spatial: a valid distribution at every point that
//!   favours the light next to it; exactly one light: every kind is uniform;
//! - `Light::sample_li` against `Light::pdf_li` by chi-square for a sphere
//!   light seen from outside (cone sampling) and from inside (area
//!   sampling). (Triangle lights sample by area with pbrt-v3's uniform
//!   triangle warp, chi-square-tested in `sampling_warps_chi2.rs`; a
//!   direction-space test of them is left out: the nested adaptive
//!   quadrature of the harness takes minutes on a triangle's edges.)

mod common;
use common::*;
use glam::{Vec2, Vec3};
use pbrs::integrators::RenderScene;
use pbrs::lights::{AreaShape, DiffuseLight, Light, LightSampler, LightSamplerKind};
use pbrs::sampling::chi2::{chi2_sphere, sidak_significance, Chi2Config};
use pbrs::shapes::SurfacePoint;
use std::f64::consts::PI;

fn scene(rel: &str) -> RenderScene {
    RenderScene::new(&load(rel))
}

/// Emitted power of each light of `scenes/analytic/lights.pbrt`, from the
/// numbers in the file.
fn expected_power(l: &Light) -> f64 {
    match *l {
        Light::Point(p) => 4.0 * PI * p.intensity.x as f64,
        Light::Diffuse(DiffuseLight {
            shape: AreaShape::Analytic(_),
            ..
        }) => 4.0 * (4.0 * PI * 0.25) * PI,
        Light::Diffuse(DiffuseLight {
            shape: AreaShape::Triangle { .. },
            ..
        }) => 3.0 * 2.0 * PI,
        _ => panic!("unexpected light {l:?}"),
    }
}

/// Frequencies of each light over `n` stratified u, and the pmf reported
/// with each pick (which must not depend on u).
fn pick_frequencies(
    ls: &LightSampler,
    sc: &RenderScene,
    p: Vec3,
    n: usize,
) -> (Vec<f64>, Vec<f64>) {
    let mut freq = vec![0.0; sc.lights.len()];
    let mut pmf = vec![0.0; sc.lights.len()];
    for k in 0..n {
        let u = (k as f32 + 0.5) / n as f32;
        let (i, p_i) = ls
            .sample(p, Vec3::ZERO, u, &sc.lights, &sc.aggregate)
            .expect("a light");
        let i = i as usize;
        freq[i] += 1.0 / n as f64;
        if pmf[i] == 0.0 {
            pmf[i] = p_i as f64;
        }
        assert_eq!(pmf[i], p_i as f64, "pmf of light {i} depends on u");
    }
    (freq, pmf)
}

#[test]
fn power_picks_lights_in_proportion_to_power() {
    let sc = scene("scenes/analytic/lights.pbrt");
    assert_eq!(sc.lights.len(), 5);
    let total: f64 = sc.lights.iter().map(expected_power).sum();
    let ls = LightSampler::new(LightSamplerKind::Power, &sc.lights, &sc.aggregate);
    assert_eq!(ls.kind(), LightSamplerKind::Power);
    let n = 100_000;
    let (freq, pmf) = pick_frequencies(&ls, &sc, Vec3::ZERO, n);
    for (i, l) in sc.lights.iter().enumerate() {
        let want = expected_power(l) / total;
        println!(
            "light {i}: share {want:.5}, picked {:.5}, pmf {:.5}",
            freq[i], pmf[i]
        );
        assert!(
            (pmf[i] - want).abs() < 1e-5,
            "light {i}: pmf {} vs {want}",
            pmf[i]
        );
        // Stratified u: the frequency is the pmf to within 1/n.
        assert!(
            (freq[i] - want).abs() < 2.0 / n as f64,
            "light {i}: {}",
            freq[i]
        );
    }
}

#[test]
fn uniform_picks_every_light_equally() {
    let sc = scene("scenes/analytic/lights.pbrt");
    let ls = LightSampler::new(LightSamplerKind::Uniform, &sc.lights, &sc.aggregate);
    let (freq, pmf) = pick_frequencies(&ls, &sc, Vec3::ZERO, 10_000);
    for i in 0..5 {
        assert_eq!(pmf[i], 0.2f32 as f64);
        assert!((freq[i] - 0.2).abs() < 1e-4);
    }
}

/// Index of the point light of intensity `i`.
fn point_light(sc: &RenderScene, i: f32) -> usize {
    sc.lights
        .iter()
        .position(|l| matches!(l, Light::Point(p) if p.intensity.x == i))
        .unwrap()
}

#[test]
fn spatial_is_a_valid_distribution_favouring_nearby_lights() {
    let sc = scene("scenes/analytic/lights.pbrt");
    let ls = LightSampler::new(LightSamplerKind::Spatial, &sc.lights, &sc.aggregate);
    assert_eq!(ls.kind(), LightSamplerKind::Spatial);
    let points = [
        (Vec3::new(-1.9, 0.05, 0.05), Some(point_light(&sc, 1.0))),
        (Vec3::new(1.9, 0.05, 0.05), Some(point_light(&sc, 2.0))),
        // Above the geometry's bounds: clamped into the top voxels (as in
        // pbrt-v3), where no light dominates.
        (Vec3::new(0.05, 1.9, 0.05), None),
        (Vec3::new(0.0, -1.0, 0.0), None), // inside the sphere light
        (Vec3::new(0.0, -0.5, 2.5), None), // in front of the triangle
        (Vec3::new(3.9, -1.9, -3.9), None), // a corner of the floor
    ];
    for (p, nearest) in points {
        let n = 1_000_000;
        let (freq, pmf) = pick_frequencies(&ls, &sc, p, n);
        let sum: f64 = pmf.iter().sum();
        println!("{p}: pmf {pmf:.6?}");
        // Lights never picked in n stratified draws hold < 1/n of the mass.
        assert!(
            (sum - 1.0).abs() < 1e-5 + 5.0 / n as f64,
            "{p}: pmfs sum to {sum}"
        );
        for i in 0..5 {
            assert!((freq[i] - pmf[i]).abs() < 2.0 / n as f64, "{p}: light {i}");
        }
        if let Some(j) = nearest {
            assert!(
                pmf[j] > 0.9,
                "{p}: the nearby light {j} has only {}",
                pmf[j]
            );
        }
    }
    // pbrt-v3 floors every light at 0.1% of the average (per-sample sum)
    // contribution, so even the triangle seen from behind (no contribution)
    // can be picked where no light dominates.
    let (_, pmf) = pick_frequencies(&ls, &sc, Vec3::new(3.9, -1.9, -3.9), 1_000_000);
    assert!(pmf.iter().all(|&p| p > 0.0), "{pmf:?}");
}

#[test]
fn one_light_is_uniform_for_every_strategy() {
    let sc = scene("scenes/analytic/one-light.pbrt");
    assert_eq!(sc.lights.len(), 1);
    for kind in [
        LightSamplerKind::Uniform,
        LightSamplerKind::Power,
        LightSamplerKind::Spatial,
        LightSamplerKind::Bvh,
    ] {
        let ls = LightSampler::new(kind, &sc.lights, &sc.aggregate);
        assert_eq!(ls.kind(), LightSamplerKind::Uniform, "{kind:?}");
        for u in [0.0, 0.3, 0.999_999] {
            let (i, pmf) = ls
                .sample(
                    Vec3::new(0.3, -1.5, 0.2),
                    Vec3::ZERO,
                    u,
                    &sc.lights,
                    &sc.aggregate,
                )
                .unwrap();
            assert_eq!((i, pmf), (0, 1.0), "{kind:?}");
        }
    }
}

fn at(p: Vec3) -> SurfacePoint {
    SurfacePoint {
        p,
        p_error: Vec3::ZERO,
        n: Vec3::ZERO,
        ns: Vec3::ZERO,
    }
}

#[test]
fn area_light_sampling_matches_its_density() {
    let sc = scene("scenes/analytic/lights.pbrt");
    let find = |f: &dyn Fn(&Light) -> bool| sc.lights.iter().find(|l| f(l)).unwrap().clone();
    let sphere = find(&|l| {
        matches!(
            l,
            Light::Diffuse(DiffuseLight {
                shape: AreaShape::Analytic(_),
                ..
            })
        )
    });
    let cases = [
        (
            "sphere from outside",
            sphere.clone(),
            Vec3::new(0.3, 0.2, -0.4),
        ),
        ("sphere from inside", sphere, Vec3::new(0.1, -1.2, 0.15)),
    ];
    // Seen from outside, pbrt-v3's Sphere::Pdf returns the cone density for
    // any direction (callers only use it for rays that hit the light), so
    // the density tested is restricted to the subtended cone.
    let (centre, radius) = (Vec3::new(0.0, -1.0, 0.0), 0.5f32);
    let n_cases = cases.len();
    for (k, (name, light, p)) in cases.into_iter().enumerate() {
        let r = at(p);
        let in_cone = |wi: Vec3| {
            let d = centre - p;
            let cos_max = (1.0 - radius * radius / d.length_squared()).max(0.0).sqrt();
            d.length() <= radius || wi.dot(d.normalize()) >= cos_max
        };
        let res = chi2_sphere(
            |u: Vec2| light.sample_li(&r, u, &sc.aggregate).map(|s| s.wi),
            |wi| {
                if in_cone(wi) {
                    light.pdf_li(&r, wi, &sc.aggregate)
                } else {
                    0.0
                }
            },
            &Chi2Config {
                theta_res: 20,
                phi_res: 40,
                sample_count: 4_000_000,
                seed: 50 + k as u64,
                ..Default::default()
            },
        );
        println!("{name}: {res}");
        assert!(
            (res.pdf_integral - 1.0).abs() < 2e-3,
            "{name}: pdf integrates to {}",
            res.pdf_integral
        );
        assert!(
            res.passed(sidak_significance(0.01, n_cases)),
            "{name}: {res}"
        );
    }
}
