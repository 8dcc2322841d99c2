//! Many lights: the light BVH's choice probabilities (they sum to one and
//! are the frequencies with which lights are chosen), MIS with it on the
//! Cornell box, and one many-lights scene rendered alike by every strategy.

mod common;

use common::*;
use pbrs::image::compare::compare;
use pbrs::integrators::RenderScene;
use pbrs::lights::{LightSampler, LightSamplerKind};
use pbrs::sampling::Pcg32;
use pbrs::scene::{IntegratorSettings, LightSampleStrategy};

/// `n` small downward-facing emissive triangles scattered over a floor
/// (deterministic), plus optional extra light lines, at `res` pixels.
fn many_lights_scene(n: usize, res: u32, spp: u32, strategy: &str, extra: &str) -> String {
    let mut rng = Pcg32::with_sequence(7);
    let mut p = String::new();
    let mut idx = String::new();
    for i in 0..n {
        let x = rng.uniform_f32() * 8.0 - 4.0;
        let z = rng.uniform_f32() * 8.0 - 4.0;
        let y = 0.3 + rng.uniform_f32() * 1.5;
        let s = 0.15;
        p += &format!("{x} {y} {z} {} {y} {z} {x} {y} {} ", x + s, z + s);
        let b = 3 * i;
        idx += &format!("{b} {} {} ", b + 1, b + 2);
    }
    format!(
        r#"LookAt 0 5 7 0 0 0 0 1 0
Camera "perspective" "float fov" 50
Film "image" "integer xresolution" {res} "integer yresolution" {res} "string filename" "x.exr"
Sampler "halton" "integer pixelsamples" {spp}
Integrator "path" "string lightsamplestrategy" "{strategy}" "integer maxdepth" 3
WorldBegin
{extra}
Material "matte" "rgb Kd" [0.6 0.6 0.6]
Shape "trianglemesh" "point P" [-6 0 -6 6 0 -6 6 0 6 -6 0 6] "integer indices" [0 1 2 0 2 3]
AttributeBegin
AreaLightSource "diffuse" "rgb L" [3 2.5 2]
Shape "trianglemesh" "point P" [{p}] "integer indices" [{idx}]
AttributeEnd
WorldEnd
"#
    )
}

/// Σ pmf = 1 at several points and normals, and sampling frequencies agree
/// with the pmf by a chi-square test over lights (expected counts below 5
/// pooled), with area, point, spot, distant and infinite lights together.
#[test]
fn bvh_pmf_sums_to_one_and_matches_sampling() {
    let extra = r#"LightSource "point" "point from" [1 2 1] "rgb I" [2 2 2]
LightSource "spot" "point from" [-2 3 0] "point to" [-2 0 0] "float coneangle" 40 "rgb I" [5 5 5]
LightSource "distant" "point from" [0 1 0] "point to" [0 0 0] "rgb L" [0.3 0.3 0.3]
LightSource "infinite" "rgb L" [0.1 0.1 0.1]"#;
    let loaded = load_text(&many_lights_scene(300, 8, 1, "bvh", extra));
    let scene = RenderScene::new(&loaded.scene);
    let ls = LightSampler::new(LightSamplerKind::Bvh, &scene.lights, &scene.aggregate);
    assert_eq!(ls.kind(), LightSamplerKind::Bvh);
    let n_lights = scene.lights.len();
    assert!(n_lights >= 304);
    let points = [
        (glam::Vec3::new(0.0, 0.0, 0.0), glam::Vec3::Y),
        (glam::Vec3::new(3.5, 0.0, -3.0), glam::Vec3::Y),
        (glam::Vec3::new(-1.0, 1.0, 2.0), glam::Vec3::ZERO), // in a medium
        (glam::Vec3::new(0.0, 5.0, 0.0), -glam::Vec3::Y),
    ];
    let mut rng = Pcg32::with_sequence(11);
    for (p, nrm) in points {
        let pmf: Vec<f64> = (0..n_lights as u32)
            .map(|i| ls.pmf(p, nrm, i, &scene.lights, &scene.aggregate) as f64)
            .collect();
        let sum: f64 = pmf.iter().sum();
        // A light of pmf 0 must be one that cannot reach p (else the
        // estimate would miss it): its bounds face away.
        let zeros: Vec<usize> = (0..n_lights).filter(|&i| pmf[i] == 0.0).collect();
        for &z in &zeros {
            for k in 0..16 {
                let u = glam::Vec2::new((k % 4) as f32 / 4.0 + 0.1, (k / 4) as f32 / 4.0 + 0.1);
                let c = scene.lights[z].contribution_estimate(p, u, &scene.aggregate);
                assert!(c == 0.0, "light {z} has pmf 0 at {p} but contributes {c}");
            }
        }
        // Where every light can contribute the pmf sums to one; elsewhere
        // sampling may fail (pbrt-v4: both children of a node of positive
        // importance can have none), with the probability the sum lacks.
        if zeros.is_empty() {
            assert!((sum - 1.0).abs() < 1e-4, "Σ pmf = {sum} at {p}");
        } else {
            assert!(sum <= 1.0 + 1e-4, "Σ pmf = {sum} at {p}");
        }
        let draws = 200_000usize;
        let mut counts = vec![0u64; n_lights];
        let mut failed = 0usize;
        for _ in 0..draws {
            let u = rng.uniform_f32();
            let Some((i, q)) = ls.sample(p, nrm, u, &scene.lights, &scene.aggregate) else {
                failed += 1;
                continue;
            };
            let want = pmf[i as usize] as f32;
            assert!(
                (q - want).abs() <= 1e-4 * want.max(1e-6),
                "sample's pmf {q} vs pmf() {want}"
            );
            counts[i as usize] += 1;
        }
        let miss = 1.0 - sum.min(1.0);
        let sd = (miss * (1.0 - miss) / draws as f64).sqrt();
        let got = failed as f64 / draws as f64;
        assert!(
            (got - miss).abs() <= 5.0 * sd + 1e-4,
            "sampling failed {got} of the time, 1 - Σ pmf = {miss} at {p}"
        );
        // Chi-square with pooling of small expected counts.
        let (mut chi2, mut dof) = (0.0f64, 0usize);
        let (mut pool_e, mut pool_o) = (0.0f64, 0.0f64);
        for i in 0..n_lights {
            let e = pmf[i] * draws as f64;
            let o = counts[i] as f64;
            if e < 5.0 {
                pool_e += e;
                pool_o += o;
                continue;
            }
            chi2 += (o - e) * (o - e) / e;
            dof += 1;
        }
        if pool_e >= 5.0 {
            chi2 += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
            dof += 1;
        }
        let dof = (dof - 1) as f64;
        // Wilson–Hilferty: the 1e-6 upper quantile is about dof + 7√(2 dof).
        let limit = dof + 7.0 * (2.0 * dof).sqrt() + 10.0;
        assert!(chi2 < limit, "chi² {chi2} > {limit} (dof {dof}) at {p}");
        if zeros.is_empty() {
            assert!(dof > 30.0, "too few bins ({dof}) at {p}");
        }
    }
}

fn with_strategy(desc: &mut pbrs::scene::SceneDescription, s: LightSampleStrategy) {
    if let IntegratorSettings::Path(pbrs::scene::PathSettings {
        light_sample_strategy,
        ..
    }) = &mut desc.integrator
    {
        *light_sample_strategy = s;
    } else {
        panic!("not a path scene");
    }
}

/// MIS with the light BVH (emission reached by BSDF samples weighted with
/// the pmf at the vertex they left) gives the Cornell box's expected image,
/// within the golden bounds against pbrt-v3.
#[test]
fn cornell_with_the_bvh_matches_pbrt() {
    let mut desc = load("scenes/cornell-path.pbrt");
    with_strategy(&mut desc, LightSampleStrategy::Bvh);
    let (img, _) = render_at(desc, 128, 64, None);
    let stem = "cornell-path";
    assert_matches(
        "many_lights_cornell_bvh",
        &img,
        &reference(stem),
        Bounds::against_pbrt(stem),
    );
}

/// 400 lights over a floor: uniform, power, spatial and bvh at 64 spp agree
/// with a 1024-spp uniform render in block means (4% of the mean) and image
/// means (4%).
#[test]
fn every_strategy_gives_the_same_image() {
    let res = 32;
    let reference = {
        let l = load_text(&many_lights_scene(400, res, 1024, "uniform", ""));
        render_at(l.scene, res, 1024, None).0
    };
    for s in ["uniform", "power", "spatial", "bvh"] {
        let l = load_text(&many_lights_scene(400, res, 64, s, ""));
        let (img, _) = render_at(l.scene, res, 64, None);
        let c = compare(&img, &reference);
        let mean_diff = (0..3)
            .map(|i| ((c.mean_a[i] - c.mean_r[i]) / c.mean_r[i]).abs())
            .fold(0.0f64, f64::max);
        eprintln!(
            "{s}: relative MSE {:.5}, block error {:.5}, mean difference {:.4}",
            c.relative_mse, c.block_error, mean_diff
        );
        // The image mean's own noise at 64 spp is about 1% (uniform, the
        // noisiest: 2.4% measured); a biased strategy would miss lights.
        assert!(mean_diff < 0.04, "{s}: image mean off by {mean_diff}");
        assert!(c.block_error < 0.05, "{s}: block error {}", c.block_error);
    }
}

/// Past `SPATIAL_MAX_LIGHTS` lights, "spatial" chooses by the BVH and says so.
#[test]
fn spatial_falls_back_to_the_bvh_past_the_light_limit() {
    let n = pbrs::lights::SPATIAL_MAX_LIGHTS + 1;
    let l = load_text(&many_lights_scene(n, 4, 1, "spatial", ""));
    let scene = RenderScene::new(&l.scene);
    let ls = LightSampler::new(LightSamplerKind::Spatial, &scene.lights, &scene.aggregate);
    assert_eq!(ls.kind(), LightSamplerKind::Bvh);
    assert!(ls.spatial_fallback());
    let l = load_text(&many_lights_scene(n - 1, 4, 1, "spatial", ""));
    let scene = RenderScene::new(&l.scene);
    let ls = LightSampler::new(LightSamplerKind::Spatial, &scene.lights, &scene.aggregate);
    assert_eq!(ls.kind(), LightSamplerKind::Spatial);
}
