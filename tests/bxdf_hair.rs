//! pbrt-v3's hair BSDF against pbrt-v3's own hair tests (src/tests/hair.cpp:
//! the white furnace by uniform and by importance sampling, sample weights
//! of 1 without absorption, importance against uniform sampling of a
//! lighting function), plus: the density integrates to one, `sample_f`'s
//! density and value are `pdf` and `f` of the sampled direction, a
//! chi-square test of the sampler against `pdf`, and pbrt-v3's σ_a formulas.
//! (The table-driven checks of the `hair` material are in
//! tests/materials_table.rs.)

use glam::{Vec2, Vec3};
use pbrs::bxdf::hair::{sigma_a_from_concentration, sigma_a_from_reflectance};
use pbrs::bxdf::{BxdfModel, HairBsdf};
use pbrs::geometry::luminance;
use pbrs::sampling::chi2::{chi2_sphere, sidak_significance, Chi2Config};
use pbrs::sampling::{uniform_sample_sphere, Pcg32};
use std::f32::consts::PI;

fn u2(rng: &mut Pcg32) -> Vec2 {
    Vec2::new(rng.uniform_f32(), rng.uniform_f32())
}

fn betas(from: f32) -> Vec<(f32, f32)> {
    let steps = |a: f32| {
        (0..)
            .map(move |k| a + 0.2 * k as f32)
            .take_while(|&b| b < 1.0)
    };
    steps(0.1)
        .flat_map(|m| steps(from).map(move |n| (m, n)))
        .collect()
}

fn hair(h: f32, sigma_a: f32, beta_m: f32, beta_n: f32) -> HairBsdf {
    HairBsdf::new(h, 1.55, Vec3::splat(sigma_a), beta_m, beta_n, 0.0)
}

/// Uniform incident radiance, no absorption, h uniform: the reflected
/// radiance is 1 within 5% (pbrt-v3's `WhiteFurnace`).
#[test]
fn white_furnace() {
    let mut rng = Pcg32::new();
    let wo = uniform_sample_sphere(u2(&mut rng));
    for (bm, bn) in betas(0.1) {
        let count = 300_000;
        let mut sum = Vec3::ZERO;
        for _ in 0..count {
            let h = -1.0 + 2.0 * rng.uniform_f32();
            let wi = uniform_sample_sphere(u2(&mut rng));
            sum += hair(h, 0.0, bm, bn).f(wo, wi) * wi.z.abs();
        }
        let avg = luminance(sum) / (count as f32 / (4.0 * PI));
        assert!((0.95..=1.05).contains(&avg), "β_m {bm} β_n {bn}: {avg}");
    }
}

/// The same by importance sampling, within 1% (`WhiteFurnaceSampled`).
#[test]
fn white_furnace_sampled() {
    let mut rng = Pcg32::new();
    let wo = uniform_sample_sphere(u2(&mut rng));
    for (bm, bn) in betas(0.1) {
        let count = 300_000;
        let mut sum = Vec3::ZERO;
        for _ in 0..count {
            let h = -1.0 + 2.0 * rng.uniform_f32();
            let s = hair(h, 0.0, bm, bn).sample_f(wo, u2(&mut rng)).unwrap();
            if s.pdf > 0.0 {
                sum += s.f * s.wi.z.abs() / s.pdf;
            }
        }
        let avg = luminance(sum) / count as f32;
        assert!((0.99..=1.01).contains(&avg), "β_m {bm} β_n {bn}: {avg}");
    }
}

/// Without absorption every sample's weight f·|cos θ|/pdf is 1 within
/// 0.1% (`SamplingWeights`; β_n ≥ 0.4 as there).
#[test]
fn sample_weights_are_one() {
    let mut rng = Pcg32::new();
    for (bm, bn) in betas(0.4) {
        for _ in 0..10_000 {
            let h = -1.0 + 2.0 * rng.uniform_f32();
            let b = hair(h, 0.0, bm, bn);
            let wo = uniform_sample_sphere(u2(&mut rng));
            let s = b.sample_f(wo, u2(&mut rng)).unwrap();
            if s.pdf > 0.0 {
                let w = luminance(s.f) * s.wi.z.abs() / s.pdf;
                assert!(w > 0.999 && w < 1.001, "β_m {bm} β_n {bn} h {h}: {w}");
            }
        }
    }
}

/// Importance and uniform sampling estimate the same reflected radiance
/// of Li(w) = w_z², within 5% (`SamplingConsistency`).
#[test]
fn importance_and_uniform_sampling_agree() {
    let mut rng = Pcg32::new();
    let steps = |a: f32| {
        (0..)
            .map(move |k| a + 0.2 * k as f32)
            .take_while(|&b| b < 1.0)
    };
    for bm in steps(0.2) {
        for bn in steps(0.4) {
            let count = 64 * 1024;
            let wo = uniform_sample_sphere(u2(&mut rng));
            let li = |w: Vec3| w.z * w.z;
            let (mut imp, mut uni) = (Vec3::ZERO, Vec3::ZERO);
            for _ in 0..count {
                let h = -1.0 + 2.0 * rng.uniform_f32();
                let b = hair(h, 0.25, bm, bn);
                let u = u2(&mut rng);
                let s = b.sample_f(wo, u).unwrap();
                if s.pdf > 0.0 {
                    imp += s.f * li(s.wi) * s.wi.z.abs() / (count as f32 * s.pdf);
                }
                let wi = uniform_sample_sphere(u);
                uni += b.f(wo, wi) * li(wi) * wi.z.abs() * (4.0 * PI) / count as f32;
            }
            let err = (luminance(imp) - luminance(uni)).abs() / luminance(uni);
            assert!(err < 0.05, "β_m {bm} β_n {bn}: {err}");
        }
    }
}

/// ∫ pdf dω = 1 (uniform sphere estimate, fixed h), and `sample_f`
/// returns `f` and `pdf` of the direction it samples.
#[test]
fn pdf_integrates_to_one_and_samples_agree_with_evaluation() {
    let mut rng = Pcg32::with_sequence(3);
    for &(h, sa, bm, bn) in &[
        (0.0, 0.0, 0.3, 0.3),
        (-0.7, 0.5, 0.15, 0.6),
        (0.9, 2.0, 0.8, 0.2),
    ] {
        let b = hair(h, sa, bm, bn);
        for k in 0..4 {
            let wo = uniform_sample_sphere(u2(&mut rng));
            // Midpoint rule in the hair's own coordinates: sin θ along the
            // hair and φ around it (dω = d sin θ dφ).
            let (ns, nphi) = (2000, 720);
            let mut sum = 0.0f64;
            for i in 0..ns {
                let sin_t = -1.0 + 2.0 * (i as f32 + 0.5) / ns as f32;
                let cos_t = (1.0 - sin_t * sin_t).sqrt();
                for j in 0..nphi {
                    let phi = 2.0 * PI * (j as f32 + 0.5) / nphi as f32;
                    let wi = Vec3::new(sin_t, cos_t * phi.cos(), cos_t * phi.sin());
                    sum += b.pdf(wo, wi) as f64;
                }
            }
            let integral = sum * (2.0 / ns as f64) * (2.0 * std::f64::consts::PI / nphi as f64);
            // pbrt-v3's m_p is normalised only approximately (the |cos|
            // fold of tilted directions): within 1%.
            println!("h {h} β {bm} {bn} wo {k}: ∫pdf = {integral}");
            assert!(
                (integral - 1.0).abs() < 0.03,
                "h {h} β {bm} {bn} wo {k}: ∫pdf = {integral}"
            );
            for _ in 0..2000 {
                let s = b.sample_f(wo, u2(&mut rng)).unwrap();
                if s.wi.x.abs() > 0.9999 {
                    continue;
                }
                let pdf = b.pdf(wo, s.wi);
                assert!(
                    (s.pdf - pdf).abs() <= 0.01 * pdf.max(1e-3),
                    "pdf {} vs {pdf}",
                    s.pdf
                );
                assert_eq!(s.f, b.f(wo, s.wi));
            }
        }
    }
}

/// The sampler follows `pdf` (chi-square over the sphere).
#[test]
fn sampling_matches_pdf_chi2() {
    let cases = [
        (0.0, 0.0, 0.3, 0.3),
        (0.5, 0.3, 0.2, 0.5),
        (-0.8, 1.0, 0.6, 0.8),
    ];
    let wos = [
        Vec3::new(0.3, 0.5, 0.81).normalize(),
        Vec3::new(-0.8, 0.1, -0.59).normalize(),
    ];
    let n_tests = cases.len() * wos.len();
    for (i, &(h, sa, bm, bn)) in cases.iter().enumerate() {
        let b = HairBsdf::new(h, 1.55, Vec3::splat(sa), bm, bn, 2f32.to_radians());
        for (j, &wo) in wos.iter().enumerate() {
            let r = chi2_sphere(
                |u| b.sample_f(wo, u).filter(|s| s.pdf > 0.0).map(|s| s.wi),
                |wi| b.pdf(wo, wi),
                &Chi2Config {
                    sample_count: 500_000,
                    seed: (10 * i + j) as u64,
                    cell_tolerance: Some(1e-6),
                    ..Chi2Config::default()
                },
            );
            let name = format!("hair h {h} σ {sa} β {bm} {bn}, wo {wo}");
            assert!(
                (r.pdf_integral - 1.0).abs() < 2e-2,
                "{name}: pdf integrates to {}",
                r.pdf_integral
            );
            assert!(r.passed(sidak_significance(0.01, n_tests)), "{name}: {r}");
        }
    }
}

/// pbrt-v3's σ_a from melanin concentrations and from a colour.
#[test]
fn absorption_formulas() {
    let s = sigma_a_from_concentration(1.3, 0.5);
    let want = [
        1.3 * 0.419 + 0.5 * 0.187,
        1.3 * 0.697 + 0.5 * 0.4,
        1.3 * 1.37 + 0.5 * 1.05,
    ];
    for c in 0..3 {
        assert!((s[c] - want[c]).abs() < 1e-6, "{s}");
    }
    let bn = 0.3f32;
    let d = 5.969 - 0.215 * bn + 2.532 * bn * bn - 10.73 * bn.powi(3)
        + 5.574 * bn.powi(4)
        + 0.245 * bn.powi(5);
    let c = Vec3::new(0.8, 0.5, 0.2);
    let s = sigma_a_from_reflectance(c, bn);
    for k in 0..3 {
        let want = (c[k].ln() / d).powi(2);
        assert!((s[k] - want).abs() < 1e-5 * want, "{s}");
    }
}
