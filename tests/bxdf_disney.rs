//! The Disney lobes one by one (local frame): chi-square of `sample_f`
//! against `pdf` at several incident angles, sampled value and density
//! against `f` and `pdf`, reciprocity, the GTR1 normalisation, and albedo
//! bounds: the ones each lobe satisfies and, where pbrt-v3's model exceeds
//! 1, that it does so as much as its formulas say.

use glam::{DVec3, Vec2, Vec3};
use pbrs::bxdf::{
    gtr1, Bxdf, BxdfFlags, BxdfModel, DisneyClearcoat, DisneyDiffuse, DisneyFakeSS, DisneyRetro,
    DisneySheen,
};
use pbrs::sampling::chi2::{chi2_sphere, sidak_significance, Chi2Config};
use pbrs::sampling::Pcg32;
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// Polar angles of wo (degrees); 135 is below the surface (the lobes are
/// two-sided, as pbrt-v3's).
const ANGLES: [f32; 5] = [0.0, 30.0, 60.0, 85.0, 135.0];

fn wo_at(deg: f32) -> Vec3 {
    let t = deg.to_radians();
    let phi = 0.7f32;
    Vec3::new(t.sin() * phi.cos(), t.sin() * phi.sin(), t.cos())
}

fn lobes() -> Vec<(&'static str, Bxdf<'static>)> {
    let r = Vec3::new(0.8, 0.5, 0.3);
    vec![
        ("diffuse", DisneyDiffuse { r }.into()),
        ("fakess", DisneyFakeSS { r, roughness: 0.3 }.into()),
        ("retro", DisneyRetro { r, roughness: 0.6 }.into()),
        ("sheen", DisneySheen { r }.into()),
        (
            "clearcoat α=0.1",
            DisneyClearcoat {
                weight: 1.0,
                alpha: 0.1,
            }
            .into(),
        ),
        (
            "clearcoat α=0.03",
            DisneyClearcoat {
                weight: 0.7,
                alpha: 0.03,
            }
            .into(),
        ),
    ]
}

#[test]
fn sampling_matches_pdf() {
    let lobes = lobes();
    let n_tests = lobes.len() * ANGLES.len();
    for (k, (name, b)) in lobes.iter().enumerate() {
        for (i, &deg) in ANGLES.iter().enumerate() {
            let wo = wo_at(deg);
            let cfg = Chi2Config {
                theta_res: 10,
                phi_res: 20,
                sample_count: 300_000,
                seed: 100 + (k * ANGLES.len() + i) as u64,
                // The f32 densities cannot be integrated to 1e-9 per cell;
                // 1e-6 is far below a cell's sampling noise here.
                cell_tolerance: Some(1e-6),
                ..Default::default()
            };
            let t0 = std::time::Instant::now();
            let r = chi2_sphere(
                |u| b.sample_f(wo, u).map(|s| s.wi),
                |wi| b.pdf(wo, wi),
                &cfg,
            );
            println!("{name} θo={deg}: {r} ({:.2} s)", t0.elapsed().as_secs_f64());
            // Rejected samples (clearcoat reflections below the horizon)
            // are the density the pdf does not cover.
            let accepted = 1.0 - r.rejected_samples as f64 / cfg.sample_count as f64;
            assert!(
                (r.pdf_integral - accepted).abs() < 3e-3,
                "{name} θo={deg}: pdf integrates to {}, {accepted} of the samples accepted",
                r.pdf_integral
            );
            assert!(
                r.passed(sidak_significance(0.01, n_tests)),
                "{name} θo={deg}: {r}"
            );
        }
    }
}

#[test]
fn sampled_value_and_density_are_f_and_pdf_and_lobes_are_reciprocal() {
    let mut rng = Pcg32::with_sequence(11);
    for (name, b) in lobes() {
        assert!(b.flags().is_reflection() && !b.flags().is_transmission());
        for &deg in &ANGLES {
            let wo = wo_at(deg);
            let mut n_ok = 0;
            for _ in 0..20_000 {
                let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
                let Some(s) = b.sample_f(wo, u) else {
                    continue;
                };
                n_ok += 1;
                assert_eq!(s.flags, b.flags(), "{name}");
                assert!(s.wi.z * wo.z > 0.0, "{name}: wi on the other side");
                let (f, pdf) = (b.f(wo, s.wi), b.pdf(wo, s.wi));
                assert!(
                    (f - s.f).abs().max_element() <= 1e-5 * f.max_element().max(1.0),
                    "{name}: sampled {:?} vs f {f:?}",
                    s.f
                );
                assert!(
                    (pdf - s.pdf).abs() <= 1e-4 * pdf,
                    "{name}: {pdf} vs {}",
                    s.pdf
                );
                assert!(s.pdf > 0.0 && f.is_finite() && f.min_element() >= 0.0);
                let back = b.f(s.wi, wo);
                assert!(
                    (back - f).abs().max_element() <= 2e-4 * f.max_element().max(1e-3),
                    "{name}: f(wo, wi) {f:?}, f(wi, wo) {back:?}"
                );
                // Across the surface a reflection lobe has no density.
                let through = Vec3::new(s.wi.x, s.wi.y, -s.wi.z);
                assert_eq!(b.pdf(wo, through), 0.0, "{name}");
            }
            // Clearcoat reflections below the horizon are rejected (many at
            // grazing incidence); the diffuse lobes never reject.
            let least = if b.flags().intersects(BxdfFlags::GLOSSY) {
                5_000
            } else {
                20_000
            };
            assert!(n_ok >= least, "{name} θo={deg}: {n_ok} samples");
        }
    }
}

/// ∫ f(wo, wi) cos θi dωi over wo's hemisphere by the midpoint rule, red
/// channel, for `r` = 1 lobes.
fn albedo_quadrature(b: &impl BxdfModel, wo: Vec3) -> f64 {
    let (nt, np) = (400, 400);
    let mut sum = 0.0;
    for i in 0..nt {
        let t = (i as f64 + 0.5) / nt as f64 * FRAC_PI_2;
        for j in 0..np {
            let p = (j as f64 + 0.5) / np as f64 * TAU;
            let mut wi = DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos());
            if wo.z < 0.0 {
                wi.z = -wi.z;
            }
            sum += b.f(wo, wi.as_vec3()).x as f64 * t.cos() * t.sin();
        }
    }
    sum * (FRAC_PI_2 / nt as f64) * (TAU / np as f64)
}

/// Mean of f·cos/pdf over sampled directions, with its standard error.
fn albedo_sampled(b: &impl BxdfModel, wo: Vec3, n: usize, seed: u64) -> (f64, f64) {
    let mut rng = Pcg32::with_sequence(seed);
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
        if let Some(s) = b.sample_f(wo, u) {
            let w = (s.f.x * s.wi.z.abs() / s.pdf) as f64;
            sum += w;
            sum2 += w * w;
        }
    }
    let mean = sum / n as f64;
    (
        mean,
        ((sum2 / n as f64 - mean * mean).max(0.0) / n as f64).sqrt(),
    )
}

#[test]
fn gtr1_is_normalised() {
    // ∫ D(θh) cos θh dωh = 1 over the hemisphere, for the α range of
    // clearcoatgloss 0..1 (0.1..0.001).
    for alpha in [0.1f32, 0.03, 0.01, 0.001] {
        // In μ = cos²θh, dω cos θh = π dμ; the peak at μ = 1 has width α²,
        // so integrate over x = 1 − μ on a logarithmic grid down to 1e-14.
        let n = 100_000;
        let (lo, hi) = (1e-14f64.ln(), 0.0f64);
        let h = (hi - lo) / n as f64;
        let mut sum = 0.0f64;
        for i in 0..n {
            let x = (lo + (i as f64 + 0.5) * h).exp();
            sum += gtr1((1.0 - x).sqrt() as f32, alpha) as f64 * PI * x * h;
        }
        assert!((sum - 1.0).abs() < 3e-3, "α={alpha}: ∫D cos = {sum}");
    }
}

#[test]
fn albedo_bounds_of_each_lobe() {
    let one = Vec3::ONE;
    for &deg in &[0.0f32, 30.0, 60.0, 80.0, 89.0] {
        let wo = wo_at(deg);
        // Diffuse: (1 − Fo/2)(1 − Fi/2) ≤ 1, so ≤ r; at normal incidence
        // exactly 1 − ∫₀¹ (1 − μ)⁵ μ dμ = 41/42.
        let d = albedo_quadrature(&DisneyDiffuse { r: one }, wo);
        assert!(d <= 1.0, "diffuse θo={deg}: {d}");
        if deg == 0.0 {
            assert!(
                (d - 41.0 / 42.0).abs() < 1e-4,
                "diffuse at normal incidence {d}"
            );
        }
        // Clearcoat: its Smith terms are G1/(2 cos θ) and it has a further
        // 1/4, so with F ≤ 1 and G1 ≤ 1 it reflects at most weight/4.
        for alpha in [0.1f32, 0.001] {
            let b = DisneyClearcoat { weight: 1.0, alpha };
            let (c, se) = albedo_sampled(&b, wo, 200_000, 5);
            assert!(c <= 0.25 + 4.0 * se, "clearcoat α={alpha} θo={deg}: {c}");
            // F ≥ 0.04 and G1 → 1 for a smooth coat seen from above.
            assert!(c >= 0.04 * 0.25 * 0.7, "clearcoat α={alpha} θo={deg}: {c}");
        }
        // Sheen alone stays far below 1 (at most about 0.09 at grazing).
        let s = albedo_quadrature(&DisneySheen { r: one }, wo);
        assert!((0.0..0.1).contains(&s), "sheen θo={deg}: {s}");
    }
}

#[test]
fn diffuse_with_retro_and_fake_subsurface_exceed_one_as_pbrt_v3() {
    // pbrt-v3's Disney diffuse is not energy conserving: the retro lobe is
    // added to the diffuse lobe unattenuated, and the fake subsurface lobe
    // has a 1.25 scale. These are the values of their formulas (quadrature
    // here, sampling below); a lobe "fixed" to conserve energy would differ
    // from pbrt-v3 and fail.
    let one = Vec3::ONE;
    let cases: [(f32, f32, f64); 3] = [
        // (θo, roughness, lower bound of diffuse + retro)
        (0.0, 0.5, 1.003),
        (80.0, 1.0, 1.25),
        (89.0, 1.0, 1.5),
    ];
    for (deg, rough, at_least) in cases {
        let wo = wo_at(deg);
        let d = albedo_quadrature(&DisneyDiffuse { r: one }, wo);
        let rr = albedo_quadrature(
            &DisneyRetro {
                r: one,
                roughness: rough,
            },
            wo,
        );
        println!("θo={deg} roughness {rough}: diffuse {d:.4} + retro {rr:.4}");
        assert!(d + rr > at_least, "θo={deg}: {}", d + rr);
        let (rs, se) = albedo_sampled(
            &DisneyRetro {
                r: one,
                roughness: rough,
            },
            wo,
            400_000,
            9,
        );
        assert!(
            (rs - rr).abs() < 4.0 * se + 2e-3,
            "retro: sampled {rs}, quadrature {rr}"
        );
    }
    // Fake subsurface above 1 from about 55° (its 1.25 scale), 1.44 at 80°
    // for roughness 1; below 1 near normal incidence.
    let f80 = albedo_quadrature(
        &DisneyFakeSS {
            r: one,
            roughness: 1.0,
        },
        wo_at(80.0),
    );
    let f0 = albedo_quadrature(
        &DisneyFakeSS {
            r: one,
            roughness: 1.0,
        },
        wo_at(0.0),
    );
    println!("fake subsurface: {f0:.4} at 0°, {f80:.4} at 80°");
    assert!(f80 > 1.4 && f0 < 0.8, "{f0} {f80}");
}

#[test]
fn clearcoat_sampling_is_rejected_by_a_wrong_pdf() {
    // The chi-square test can fail: samples of a coat with α = 0.05 against
    // the density of one twice as rough.
    let b = DisneyClearcoat {
        weight: 1.0,
        alpha: 0.05,
    };
    let wrong = DisneyClearcoat {
        weight: 1.0,
        alpha: 0.1,
    };
    let wo = wo_at(30.0);
    let r = chi2_sphere(
        |u| b.sample_f(wo, u).map(|s| s.wi),
        |wi| wrong.pdf(wo, wi),
        &Chi2Config {
            theta_res: 10,
            phi_res: 20,
            sample_count: 100_000,
            cell_tolerance: Some(1e-6),
            ..Default::default()
        },
    );
    assert!(!r.passed(0.01), "{r}");
}
