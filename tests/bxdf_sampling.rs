//! BSDF sampling checked against its density and its value: Mitsuba-style
//! chi-square tests of `Bsdf::sample` (non-specular lobes) against
//! `Bsdf::pdf` at several incident angles, sampled `f` against `Bsdf::f`,
//! Oren–Nayar against an independent evaluation of its formula, and the
//! specular lobes' Fresnel probabilities and throughputs against Fresnel's
//! equations written out independently here (in f64).

use glam::{Vec2, Vec3};
use pbrs::geometry::Frame;
mod common;

use common::material_bsdf;
use pbrs::bxdf::{Bxdf, BxdfModel, FresnelSpecular, LambertianReflection};
use pbrs::materials::{Bsdf, BxdfFlags};
use pbrs::sampling::chi2::{chi2_sphere, sidak_significance, Chi2Config};
use pbrs::sampling::Pcg32;

/// Incident directions: polar angles (degrees) of wo, above the surface,
/// plus one from below (both-sided matte surfaces shade either side).
const ANGLES: [f32; 5] = [0.0, 30.0, 60.0, 85.0, 135.0];
const SIGMAS: [f32; 3] = [10.0, 30.0, 60.0];
/// Chi-square tests in this file: Lambertian + Oren–Nayar at each angle.
const N_TESTS: usize = ANGLES.len() * (1 + SIGMAS.len());

fn wo_at(deg: f32) -> Vec3 {
    let t = deg.to_radians();
    // An azimuth off the axes so that φ-dependent terms are exercised.
    let phi = 0.7f32;
    Vec3::new(t.sin() * phi.cos(), t.sin() * phi.sin(), t.cos())
}

fn matte(kd: Vec3, sigma: f32) -> Bsdf<'static> {
    material_bsdf(
        &format!(
            "\"matte\" \"rgb Kd\" [{} {} {}] \"float sigma\" {sigma}",
            kd.x, kd.y, kd.z
        ),
        false,
    )
}

fn is_oren_nayar(b: &Bsdf) -> bool {
    matches!(b.lobes(), [l] if matches!(l.bxdf, Bxdf::OrenNayar(_)))
}

fn chi2_bsdf(name: &str, bsdf: &Bsdf, wo: Vec3, seed: u64) {
    let cfg = Chi2Config {
        theta_res: 10,
        phi_res: 20,
        sample_count: 500_000,
        seed,
        ..Default::default()
    };
    let r = chi2_sphere(
        |u| bsdf.sample(wo, u, BxdfFlags::NON_SPECULAR).map(|s| s.wi),
        |wi| bsdf.pdf(wo, wi, BxdfFlags::ALL),
        &cfg,
    );
    println!("{name}: {r}");
    assert!(
        (r.pdf_integral - 1.0).abs() < 1e-3,
        "{name}: pdf integrates to {}",
        r.pdf_integral
    );
    assert_eq!(r.rejected_samples, 0, "{name}");
    assert!(r.passed(sidak_significance(0.01, N_TESTS)), "{name}: {r}");
}

/// Sampled value, pdf and direction agree with `f` and `pdf` queries.
fn check_f_agrees(name: &str, bsdf: &Bsdf, wo: Vec3) {
    let mut rng = Pcg32::with_sequence(7);
    for _ in 0..20_000 {
        let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
        let s = bsdf
            .sample(wo, u, BxdfFlags::NON_SPECULAR)
            .unwrap_or_else(|| panic!("{name}: no sample"));
        assert!(!s.is_specular() && !s.is_transmission(), "{name}");
        assert!(
            s.wi.z * wo.z > 0.0,
            "{name}: wi on the wrong side: {:?}",
            s.wi
        );
        let f = bsdf.f(wo, s.wi, BxdfFlags::ALL);
        assert!(
            (f - s.f).abs().max_element() <= 1e-6 * f.max_element().max(1.0),
            "{name}: sampled f {:?} vs f {:?}",
            s.f,
            f
        );
        let pdf = bsdf.pdf(wo, s.wi, BxdfFlags::ALL);
        assert!(
            (pdf - s.pdf).abs() <= 1e-5 * pdf,
            "{name}: {pdf} vs {}",
            s.pdf
        );
        // Specular filters never return a sample from a matte surface.
        for filter in [
            BxdfFlags::SPECULAR_REFLECTION,
            BxdfFlags::SPECULAR_TRANSMISSION,
        ] {
            assert!(bsdf.sample(wo, u, filter).is_none(), "{name}");
        }
    }
}

#[test]
fn lambertian_chi2_and_f() {
    let kd = Vec3::new(0.5, 0.25, 0.8);
    let b = matte(kd, 0.0);
    assert!(b.single_lambertian().is_some());
    for (i, &deg) in ANGLES.iter().enumerate() {
        let wo = wo_at(deg);
        chi2_bsdf(&format!("lambertian θo={deg}"), &b, wo, i as u64);
        check_f_agrees(&format!("lambertian θo={deg}"), &b, wo);
        // f·cos/pdf = Kd exactly for every cosine-weighted sample.
        let s = b.sample(wo, Vec2::new(0.3, 0.6), BxdfFlags::ALL).unwrap();
        let w = s.f * s.wi.z.abs() / s.pdf;
        assert!((w - kd).abs().max_element() < 1e-5, "{w:?}");
    }
}

/// `Bsdf` evaluates and samples a Lambertian reflection lobe from the
/// cosines alone: the values are, bit for bit, the lobe's own from the
/// whole local directions, in tilted frames whose geometric normal differs
/// from the shading one (so the sides by `ng` and by the frame disagree at
/// grazing angles), from both sides.
#[test]
fn lambertian_from_cosines_is_the_lobe_from_local_directions() {
    let kd = Vec3::new(0.5, 0.25, 0.8);
    let lobe = LambertianReflection { r: kd };
    let mut rng = Pcg32::with_sequence(7);
    let unit = |rng: &mut Pcg32| {
        let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
        pbrs::sampling::warps::uniform_sample_sphere(u)
    };
    let (mut nonzero, mut zero) = (0, 0);
    for _ in 0..20_000 {
        let n = unit(&mut rng);
        let ng = (n + 0.3 * unit(&mut rng)).normalize();
        let frame = Frame::from_normal(n);
        let mut b = Bsdf::new(frame, ng, 1.0);
        b.add(lobe);
        let (wo_w, wi_w) = (unit(&mut rng), unit(&mut rng));
        let (wo, wi) = (frame.to_local(wo_w), frame.to_local(wi_w));
        let reflect = wi_w.dot(ng) * wo_w.dot(ng) > 0.0;
        let f = if wo.z == 0.0 || !reflect {
            Vec3::ZERO
        } else {
            lobe.f(wo, wi)
        };
        let pdf = if wo.z == 0.0 { 0.0 } else { lobe.pdf(wo, wi) };
        assert_eq!(b.f_pdf(wo_w, wi_w, BxdfFlags::ALL), (f, pdf));
        assert_eq!(b.pdf(wo_w, wi_w, BxdfFlags::ALL).to_bits(), pdf.to_bits());
        if f == Vec3::ZERO {
            zero += 1;
        } else {
            nonzero += 1;
        }
        let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
        let s = b.sample(wo_w, u, BxdfFlags::ALL).expect("a sample");
        let e = lobe.sample_f(wo, u).expect("a sample");
        let e_wi = frame.from_local(e.wi);
        let side = e_wi.dot(ng) * wo_w.dot(ng) > 0.0;
        assert_eq!(s.wi, e_wi);
        assert_eq!(s.pdf.to_bits(), e.pdf.to_bits());
        assert_eq!(s.f, if side { e.f } else { Vec3::ZERO });
    }
    assert!(nonzero > 5_000 && zero > 5_000, "{nonzero} {zero}");
}

/// Oren–Nayar written from its definition with angles (f64), independently
/// of pbrs's trigonometry-free evaluation.
fn oren_nayar_reference(kd: f64, sigma_deg: f64, wo: Vec3, wi: Vec3) -> f64 {
    let s = sigma_deg.to_radians();
    let s2 = s * s;
    let a = 1.0 - s2 / (2.0 * (s2 + 0.33));
    let b = 0.45 * s2 / (s2 + 0.09);
    let (wo, wi) = (wo.as_dvec3(), wi.as_dvec3());
    let ti = wi.z.abs().min(1.0).acos();
    let to = wo.z.abs().min(1.0).acos();
    let pi = wi.y.atan2(wi.x);
    let po = wo.y.atan2(wo.x);
    let alpha = ti.max(to);
    let beta = ti.min(to);
    let c = if ti.sin() > 1e-4 && to.sin() > 1e-4 {
        (pi - po).cos().max(0.0)
    } else {
        0.0
    };
    kd / std::f64::consts::PI * (a + b * c * alpha.sin() * beta.tan())
}

#[test]
fn oren_nayar_chi2_and_f() {
    let kd = 0.6;
    for (k, &sigma) in SIGMAS.iter().enumerate() {
        let b = matte(Vec3::splat(kd), sigma);
        assert!(is_oren_nayar(&b));
        for (i, &deg) in ANGLES.iter().enumerate() {
            let name = format!("oren-nayar σ={sigma} θo={deg}");
            let wo = wo_at(deg);
            chi2_bsdf(&name, &b, wo, 100 + (k * ANGLES.len() + i) as u64);
            check_f_agrees(&name, &b, wo);
            // Value against the formula, and reciprocity.
            let mut rng = Pcg32::with_sequence(k as u64);
            for _ in 0..2000 {
                let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
                let s = b.sample(wo, u, BxdfFlags::NON_SPECULAR).unwrap();
                let want = oren_nayar_reference(kd as f64, sigma as f64, wo, s.wi);
                assert!(
                    (s.f.x as f64 - want).abs() < 2e-4 * want.max(1.0),
                    "{name}: f {} vs formula {want} at wi {:?}",
                    s.f.x,
                    s.wi
                );
                let back = b.f(s.wi, wo, BxdfFlags::ALL);
                assert!(
                    (back - s.f).abs().max_element() < 1e-5,
                    "{name}: reciprocity"
                );
            }
        }
    }
}

/// ∫ f cos θi dωi of the reference formula by the midpoint rule (f64).
fn oren_nayar_albedo_quadrature(sigma: f64, wo: Vec3) -> f64 {
    let (nt, np) = (400, 800);
    let mut sum = 0.0;
    for i in 0..nt {
        let t = (i as f64 + 0.5) / nt as f64 * std::f64::consts::FRAC_PI_2;
        for j in 0..np {
            let p = (j as f64 + 0.5) / np as f64 * std::f64::consts::TAU;
            let wi = glam::DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos());
            let f = oren_nayar_reference(1.0, sigma, wo, wi.as_vec3());
            sum += f * t.cos() * t.sin();
        }
    }
    sum * (std::f64::consts::FRAC_PI_2 / nt as f64) * (std::f64::consts::TAU / np as f64)
}

#[test]
fn oren_nayar_albedo_matches_quadrature() {
    // The estimator f·cos/pdf of sampled directions has the mean ∫ f cos dω.
    // Oren–Nayar's qualitative model is not energy conserving: at grazing
    // incidence its albedo exceeds 1 (1.011 for σ = 10°, θo = 85°), in
    // pbrt-v3 as here, so the test compares with a quadrature of the
    // formula rather than bounding by Kd. Tolerance: 4 standard errors of
    // the Monte Carlo mean plus 1e-4 for the quadrature.
    let mut rng = Pcg32::with_sequence(3);
    for &sigma in &SIGMAS {
        let b = matte(Vec3::ONE, sigma);
        for &deg in &ANGLES[..4] {
            let wo = wo_at(deg);
            let n = 200_000;
            let (mut sum, mut sum2) = (0.0f64, 0.0f64);
            for _ in 0..n {
                let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
                let s = b.sample(wo, u, BxdfFlags::NON_SPECULAR).unwrap();
                let w = (s.f.x * s.wi.z.abs() / s.pdf) as f64;
                sum += w;
                sum2 += w * w;
            }
            let mean = sum / n as f64;
            let se = ((sum2 / n as f64 - mean * mean).max(0.0) / n as f64).sqrt();
            let want = oren_nayar_albedo_quadrature(sigma as f64, wo);
            println!("σ={sigma} θo={deg}: albedo {mean:.5} ± {se:.1e}, quadrature {want:.5}");
            assert!(
                (mean - want).abs() < 4.0 * se + 1e-4,
                "σ={sigma} θo={deg}: albedo {mean} vs {want}"
            );
        }
    }
    // sigma 0 is Lambertian (pbrt-v3's MatteMaterial).
    assert!(matte(Vec3::ONE, 0.0).single_lambertian().is_some());
}

#[test]
fn wrong_pdf_is_rejected() {
    // The harness can fail: cosine samples against a uniform-hemisphere pdf.
    let b = matte(Vec3::ONE, 0.0);
    let wo = wo_at(30.0);
    let r = chi2_sphere(
        |u| b.sample(wo, u, BxdfFlags::NON_SPECULAR).map(|s| s.wi),
        |wi| {
            if wi.z > 0.0 {
                0.5 / std::f32::consts::PI
            } else {
                0.0
            }
        },
        &Chi2Config {
            sample_count: 100_000,
            ..Default::default()
        },
    );
    assert!(!r.passed(0.01), "{r}");
}

/// Fresnel reflectance of an unpolarised wave from a medium of index `n1` at
/// cos θ1 into `n2`, straight from Fresnel's equations (f64).
fn fresnel(cos1: f64, n1: f64, n2: f64) -> f64 {
    let sin1 = (1.0 - cos1 * cos1).max(0.0).sqrt();
    let sin2 = n1 / n2 * sin1;
    if sin2 >= 1.0 {
        return 1.0;
    }
    let cos2 = (1.0 - sin2 * sin2).sqrt();
    let rs = (n1 * cos1 - n2 * cos2) / (n1 * cos1 + n2 * cos2);
    let rp = (n2 * cos1 - n1 * cos2) / (n2 * cos1 + n1 * cos2);
    0.5 * (rs * rs + rp * rp)
}

/// Polar angles of wo: outside (z > 0) and inside the glass (z < 0),
/// including one beyond the critical angle (41.8° for index 1.5).
const GLASS_ANGLES: [f32; 7] = [0.0, 30.0, 60.0, 80.0, 160.0, 145.0, 120.0];

fn side(wo: Vec3, eta: f64) -> (f64, f64, f64) {
    if wo.z > 0.0 {
        (wo.z as f64, 1.0, eta)
    } else {
        (-wo.z as f64, eta, 1.0)
    }
}

fn check_transmitted(name: &str, wo: Vec3, wi: Vec3, n1: f64, n2: f64) {
    assert!(wi.z * wo.z < 0.0, "{name}: not transmitted");
    let so = ((wo.x * wo.x + wo.y * wo.y) as f64).sqrt();
    let si = ((wi.x * wi.x + wi.y * wi.y) as f64).sqrt();
    assert!((n1 * so - n2 * si).abs() < 1e-5, "{name}: Snell");
    // In the plane of incidence, on the other side of the normal.
    assert!((wo.x * wi.y - wo.y * wi.x).abs() < 1e-5, "{name}: plane");
    assert!(wo.x * wi.x + wo.y * wi.y <= 1e-6, "{name}: side");
}

#[test]
fn fresnel_specular_picks_reflection_with_the_fresnel_probability() {
    let eta = 1.5f32;
    let (r, t) = (Vec3::new(0.9, 0.8, 0.7), Vec3::new(0.6, 0.7, 0.8));
    let mut b = Bsdf::new(Frame::from_normal(Vec3::Z), Vec3::Z, eta);
    b.add(FresnelSpecular {
        r,
        t,
        eta_a: 1.0,
        eta_b: eta,
    });
    // 4% at normal incidence for index 1.5.
    assert!((fresnel(1.0, 1.0, 1.5) - 0.04).abs() < 1e-12);
    for &deg in &GLASS_ANGLES {
        let wo = wo_at(deg);
        let name = format!("fresnel specular θo={deg}");
        let (cos1, n1, n2) = side(wo, eta as f64);
        let fr = fresnel(cos1, n1, n2);
        let n = 100_000;
        let (mut n_refl, mut mean) = (0usize, Vec3::ZERO.as_dvec3());
        for k in 0..n {
            // Stratified u.x: the reflected fraction is F to within 1/n.
            let u = Vec2::new((k as f32 + 0.5) / n as f32, 0.5);
            let s = b
                .sample(wo, u, BxdfFlags::ALL)
                .unwrap_or_else(|| panic!("{name}: no sample"));
            assert!(s.is_specular(), "{name}");
            let w = s.f * s.wi.z.abs() / s.pdf;
            mean += w.as_dvec3() / n as f64;
            if s.is_transmission() {
                check_transmitted(&name, wo, s.wi, n1, n2);
                assert!((s.pdf as f64 - (1.0 - fr)).abs() < 1e-5, "{name}: pdf");
                // Radiance scaled by (η_i/η_t)².
                let want = t.as_dvec3() * (n1 * n1) / (n2 * n2);
                assert!(
                    (w.as_dvec3() - want).abs().max_element() < 1e-4,
                    "{name}: {w:?}"
                );
            } else {
                n_refl += 1;
                assert!((s.wi - Vec3::new(-wo.x, -wo.y, wo.z)).length() < 1e-6);
                assert!((s.pdf as f64 - fr).abs() < 1e-5, "{name}: pdf");
                assert!((w - r).abs().max_element() < 1e-5, "{name}: {w:?}");
            }
        }
        let p_refl = n_refl as f64 / n as f64;
        println!("{name}: reflected {p_refl:.5}, Fresnel {fr:.5}");
        assert!((p_refl - fr).abs() < 2e-5, "{name}: {p_refl} vs {fr}");
        if fr == 1.0 {
            println!("{name}: total internal reflection");
        }
        // Expected throughput: F·R + (1 − F)·T·(η_i/η_t)².
        let want = r.as_dvec3() * fr + t.as_dvec3() * (1.0 - fr) * (n1 * n1) / (n2 * n2);
        assert!(
            (mean - want).abs().max_element() < 1e-4,
            "{name}: {mean:?} vs {want:?}"
        );
        // No non-specular part: NonSpecular sampling and pdf give nothing.
        assert!(b
            .sample(wo, Vec2::splat(0.3), BxdfFlags::NON_SPECULAR)
            .is_none());
        assert_eq!(
            b.f(wo, Vec3::new(-wo.x, -wo.y, wo.z), BxdfFlags::ALL),
            Vec3::ZERO
        );
    }
    // Beyond the critical angle from inside every sample reflects.
    let wo = wo_at(135.0);
    let (cos1, n1, n2) = side(wo, 1.5);
    assert_eq!(fresnel(cos1, n1, n2), 1.0);
    for k in 0..1000 {
        let s = b
            .sample(wo, Vec2::new(k as f32 / 1000.0, 0.5), BxdfFlags::ALL)
            .unwrap();
        assert!(!s.is_transmission() && s.pdf == 1.0);
    }
}

#[test]
fn split_glass_and_mirror_throughputs_are_fresnel_weighted_colours() {
    let eta = 1.5f32;
    let (r, t) = (Vec3::new(0.9, 0.8, 0.7), Vec3::new(0.6, 0.7, 0.8));
    // What directlighting and whitted use for smooth glass.
    let b = material_bsdf(
        &format!(
            "\"glass\" \"rgb Kr\" [{} {} {}] \"rgb Kt\" [{} {} {}] \"float index\" {eta}",
            r.x, r.y, r.z, t.x, t.y, t.z
        ),
        false,
    );
    assert_eq!(b.lobes().len(), 2);
    let u = Vec2::new(0.3, 0.7);
    for &deg in &GLASS_ANGLES {
        let wo = wo_at(deg);
        let name = format!("split glass θo={deg}");
        let (cos1, n1, n2) = side(wo, eta as f64);
        let fr = fresnel(cos1, n1, n2);
        let s = b.sample(wo, u, BxdfFlags::SPECULAR_REFLECTION).unwrap();
        assert!(
            s.is_specular() && !s.is_transmission() && s.pdf == 1.0,
            "{name}"
        );
        assert!((s.wi - Vec3::new(-wo.x, -wo.y, wo.z)).length() < 1e-6);
        let w = (s.f * s.wi.z.abs() / s.pdf).as_dvec3();
        assert!(
            (w - r.as_dvec3() * fr).abs().max_element() < 1e-5,
            "{name}: {w:?}"
        );
        match b.sample(wo, u, BxdfFlags::SPECULAR_TRANSMISSION) {
            Some(s) => {
                assert!(
                    fr < 1.0,
                    "{name}: transmitted under total internal reflection"
                );
                assert!(
                    s.is_specular() && s.is_transmission() && s.pdf == 1.0,
                    "{name}"
                );
                check_transmitted(&name, wo, s.wi, n1, n2);
                let w = (s.f * s.wi.z.abs() / s.pdf).as_dvec3();
                let want = t.as_dvec3() * (1.0 - fr) * (n1 * n1) / (n2 * n2);
                assert!(
                    (w - want).abs().max_element() < 1e-5,
                    "{name}: {w:?} vs {want:?}"
                );
            }
            None => assert_eq!(fr, 1.0, "{name}: no transmission without TIR"),
        }
        // Both lobes under `All`: one is chosen, with probability 1/2.
        let s = b.sample(wo, u, BxdfFlags::ALL).unwrap();
        assert_eq!(s.pdf, 0.5, "{name}");
        assert!(b.sample(wo, u, BxdfFlags::NON_SPECULAR).is_none());
    }
    // Mirror: no Fresnel term, throughput Kr at every angle.
    let kr = Vec3::new(0.8, 0.5, 0.3);
    let m = material_bsdf(
        &format!("\"mirror\" \"rgb Kr\" [{} {} {}]", kr.x, kr.y, kr.z),
        false,
    );
    for &deg in &ANGLES {
        let wo = wo_at(deg);
        let s = m.sample(wo, u, BxdfFlags::SPECULAR_REFLECTION).unwrap();
        assert!((s.f * s.wi.z.abs() / s.pdf - kr).abs().max_element() < 1e-5);
        assert!(m.sample(wo, u, BxdfFlags::SPECULAR_TRANSMISSION).is_none());
        assert!(m.sample(wo, u, BxdfFlags::NON_SPECULAR).is_none());
    }
}

/// `Bsdf::reaches` (which lets light sampling skip the lobes) is false only
/// where `f_pdf`'s value is exactly zero, and is false somewhere when the
/// lobes the flags select (all of them, or the non-specular ones) all
/// reflect or all transmit.
#[test]
fn reaches_is_false_only_where_the_value_is_zero() {
    // The material, and whether its selected lobes are on one side only
    // for flags ALL and NON_SPECULAR.
    let materials = [
        (
            "\"plastic\" \"rgb Kd\" [0.5 0.3 0.8] \"float roughness\" 0.1",
            [true, true],
        ),
        ("\"matte\" \"rgb Kd\" [0.5 0.5 0.5]", [true, true]),
        (
            "\"matte\" \"rgb Kd\" [0.5 0.5 0.5] \"float sigma\" 20",
            [true, true],
        ),
        ("\"metal\" \"float roughness\" 0.05", [true, true]),
        (
            "\"substrate\" \"float uroughness\" 0.2 \"float vroughness\" 0.05",
            [true, true],
        ),
        (
            "\"glass\" \"float uroughness\" 0.2 \"float vroughness\" 0.2",
            [false, false],
        ),
        // Smooth glass: no non-specular lobe at all.
        ("\"glass\"", [false, true]),
        (
            "\"translucent\" \"rgb Kd\" [0.5 0.5 0.5] \"rgb Ks\" [0.3 0.3 0.3]",
            [false, false],
        ),
        // The pass-through lobe is specular.
        ("\"uber\" \"rgb opacity\" [0.5 0.5 0.5]", [false, true]),
    ];
    let mut rng = Pcg32::with_sequence(7);
    let mut dir = || {
        let z = 2.0 * rng.uniform_f32() - 1.0;
        let phi = std::f32::consts::TAU * rng.uniform_f32();
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    };
    for (decl, one_side) in materials {
        let b = material_bsdf(decl, true);
        for (flags, one_side) in [BxdfFlags::ALL, BxdfFlags::NON_SPECULAR]
            .into_iter()
            .zip(one_side)
        {
            let mut skipped = 0;
            for _ in 0..4000 {
                let (wo, wi) = (dir(), dir());
                let (f, _) = b.f_pdf(wo, wi, flags);
                if !b.reaches(wo, wi, flags) {
                    skipped += 1;
                    assert_eq!(f, Vec3::ZERO, "{decl}, {flags:?}: wo {wo}, wi {wi}");
                }
            }
            assert_eq!(
                skipped > 0,
                one_side,
                "{decl}, {flags:?}: {skipped} skipped"
            );
        }
    }
}
