//! The microfacet machinery against its definitions: distribution
//! normalisation and Smith masking by quadrature, chi-square tests of every
//! sampler (facet normals; reflection, transmission and Fresnel-blend lobes)
//! against its density for both distributions, isotropic and anisotropic,
//! with visible-normal and full-distribution sampling, sampled values against
//! `f`, reciprocity, Snell's law through the generalised half vector, and a
//! white furnace of the rough conductor.

use glam::{DVec3, Vec2, Vec3};
use pbrs::bxdf::{
    Beckmann, Bxdf, BxdfModel, Fresnel, FresnelBlend, MicrofacetDistribution, MicrofacetModel,
    MicrofacetReflection, MicrofacetTransmission, TrowbridgeReitz,
};
use pbrs::sampling::chi2::{chi2_sphere, sidak_significance, Chi2Config};
use pbrs::sampling::Pcg32;
use std::f64::consts::{PI, TAU};

/// Distribution settings: kind, αx, αy, visible-normal sampling.
#[derive(Clone, Copy, Debug)]
struct Dist {
    beckmann: bool,
    ax: f32,
    ay: f32,
    visible: bool,
}

impl Dist {
    fn make(self) -> MicrofacetDistribution {
        if self.beckmann {
            Beckmann::new(self.ax, self.ay)
                .with_visible_sampling(self.visible)
                .into()
        } else {
            TrowbridgeReitz::new(self.ax, self.ay)
                .with_visible_sampling(self.visible)
                .into()
        }
    }
    fn name(self) -> String {
        format!(
            "{} α=({}, {}) {}",
            if self.beckmann { "Beckmann" } else { "TR" },
            self.ax,
            self.ay,
            if self.visible { "visible" } else { "all" }
        )
    }
}

/// Both distributions, isotropic and anisotropic, both samplers.
fn dists() -> Vec<Dist> {
    let mut v = Vec::new();
    for beckmann in [false, true] {
        for (ax, ay) in [(0.3, 0.3), (0.15, 0.5)] {
            for visible in [true, false] {
                v.push(Dist {
                    beckmann,
                    ax,
                    ay,
                    visible,
                });
            }
        }
    }
    v
}

/// wo at polar angle `deg` and an azimuth off the axes (so the anisotropic
/// terms matter).
fn wo_at(deg: f32) -> Vec3 {
    let t = deg.to_radians();
    let phi = 0.7f32;
    Vec3::new(t.sin() * phi.cos(), t.sin() * phi.sin(), t.cos())
}

const REFLECT_ANGLES: [f32; 4] = [0.0, 40.0, 75.0, 120.0];
/// Outside and inside index-1.5 glass (135° is beyond the critical angle
/// of a smooth interface).
const TRANSMIT_ANGLES: [f32; 5] = [0.0, 40.0, 75.0, 160.0, 135.0];
/// Chi-square tests in this file (for the Šidák correction).
const N_CHI2: usize = 8 * (4 + 4 + 5 + 4) + 3;

fn chi2_cfg(seed: u64) -> Chi2Config {
    Chi2Config {
        theta_res: 12,
        phi_res: 24,
        sample_count: 100_000,
        seed,
        // Expected counts to ~1e-6·n = 0.2 samples: far below the noise
        // of any cell that is not pooled (≥ 5 expected).
        cell_tolerance: Some(1e-6),
        ..Default::default()
    }
}

/// True if the generalised half vector of a transmission pair has wo or wi
/// behind its facet (`wo·wh` or `wi·wh` of the wrong sign for its side):
/// pairs no facet can refract into each other.
fn back_facing(wo: Vec3, wi: Vec3, eta_a: f32, eta_b: f32) -> bool {
    if wo.z * wi.z >= 0.0 {
        return false;
    }
    let eta = if wo.z > 0.0 {
        eta_b / eta_a
    } else {
        eta_a / eta_b
    };
    let wh = (wo + wi * eta).normalize();
    let wh = if wh.z < 0.0 { -wh } else { wh };
    wo.dot(wh) * wo.z < 0.0 || wi.dot(wh) * wi.z < 0.0
}

/// The lobe's density where its sampler can go: pbrt-v3's transmission
/// density (as its `f`) is also non-zero for back-facing facets, which the
/// sampler never picks (pbrt-v4 excludes them from both).
fn front_facing_pdf(b: &Bxdf, wo: Vec3, wi: Vec3) -> f32 {
    match b {
        Bxdf::MicrofacetTransmission(t) if back_facing(wo, wi, t.eta_a, t.eta_b) => 0.0,
        _ => b.pdf(wo, wi),
    }
}

/// Chi-square of a lobe's `sample_f` against its `pdf`; samples with a zero
/// density count as rejected (the BSDF drops them).
fn chi2_lobe(name: &str, b: &Bxdf, wo: Vec3, seed: u64) -> f64 {
    let r = chi2_sphere(
        |u| b.sample_f(wo, u).filter(|s| s.pdf > 0.0).map(|s| s.wi),
        |wi| front_facing_pdf(b, wo, wi),
        &chi2_cfg(seed),
    );
    println!("{name}: {r}");
    let accepted = 1.0 - r.rejected_samples as f64 / r.sample_count as f64;
    // The density integrates to the probability that sampling succeeds.
    assert!(
        (r.pdf_integral - accepted).abs() < 0.01,
        "{name}: pdf integral {} vs accepted fraction {accepted}",
        r.pdf_integral
    );
    assert!(r.passed(sidak_significance(0.01, N_CHI2)), "{name}: {r}");
    accepted
}

/// Sampled value and density agree with `f` and `pdf`, and `f_pdf` with
/// both; `sample_wi` gives `sample_f`'s direction, density and flags bit for
/// bit (and fails where it fails).
fn check_sampled_f(name: &str, b: &Bxdf, wo: Vec3) {
    let mut rng = Pcg32::with_sequence(11);
    let mut n = 0;
    for _ in 0..5_000 {
        let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
        let sampled = b.sample_f(wo, u);
        let only_wi = b.sample_wi(wo, u);
        assert_eq!(
            sampled.map(|s| (s.wi.to_array().map(f32::to_bits), s.pdf.to_bits(), s.flags)),
            only_wi.map(|s| (s.wi.to_array().map(f32::to_bits), s.pdf.to_bits(), s.flags)),
            "{name}: sample_wi against sample_f at wo {wo}, u {u}"
        );
        let Some(s) = sampled else { continue };
        if s.pdf == 0.0 {
            continue;
        }
        n += 1;
        assert_eq!(s.flags, b.flags(), "{name}");
        let f = b.f(wo, s.wi);
        let tol = 2e-4 * f.max_element().max(s.f.max_element()) + 1e-6;
        assert!(
            (f - s.f).abs().max_element() <= tol,
            "{name}: sampled f {} vs f {f} at wi {}",
            s.f,
            s.wi
        );
        let pdf = b.pdf(wo, s.wi);
        assert!(
            (pdf - s.pdf).abs() <= 2e-4 * pdf,
            "{name}: sampled pdf {} vs pdf {pdf}",
            s.pdf
        );
        let (f2, pdf2) = b.f_pdf(wo, s.wi);
        assert!((f2 - f).abs().max_element() <= 1e-6 * f.max_element());
        assert!(
            (pdf2 - pdf).abs() <= 1e-6 * pdf,
            "{name}: f_pdf {pdf2} vs pdf {pdf}"
        );
        assert!(f.min_element() >= 0.0 && f.is_finite(), "{name}: f {f}");
    }
    assert!(n > 500, "{name}: only {n} samples");
}

fn reflection(d: Dist, fresnel: Fresnel) -> Bxdf<'static> {
    MicrofacetReflection {
        r: Vec3::new(0.9, 0.7, 0.5),
        distribution: d.make(),
        fresnel,
    }
    .into()
}

fn transmission(d: Dist) -> Bxdf<'static> {
    MicrofacetTransmission {
        t: Vec3::new(0.9, 0.7, 0.5),
        distribution: d.make(),
        eta_a: 1.0,
        eta_b: 1.5,
    }
    .into()
}

fn blend(d: Dist) -> Bxdf<'static> {
    FresnelBlend {
        rd: Vec3::new(0.6, 0.4, 0.2),
        rs: Vec3::new(0.05, 0.1, 0.3),
        distribution: d.make(),
    }
    .into()
}

// ------------------------------------------------------------ distributions

/// ∫ g(wh) dωh over the upper hemisphere, in tan θ = α·s/(1 − s) (which puts
/// the points where D lives for any α) and φ, by the midpoint rule (f64).
fn hemisphere_integral(alpha: f64, g: impl Fn(DVec3) -> f64) -> f64 {
    let (ns, np) = (1500, 360);
    let mut sum = 0.0;
    for i in 0..ns {
        let s = (i as f64 + 0.5) / ns as f64;
        let x = alpha * s / (1.0 - s);
        let dx_ds = alpha / ((1.0 - s) * (1.0 - s));
        let theta = x.atan();
        // dθ = dx/(1 + x²); dω = sin θ dθ dφ.
        let w_theta = theta.sin() / (1.0 + x * x) * dx_ds;
        for j in 0..np {
            let phi = (j as f64 + 0.5) / np as f64 * TAU;
            let wh = DVec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            );
            sum += g(wh) * w_theta;
        }
    }
    sum / ns as f64 * (TAU / np as f64)
}

#[test]
fn distributions_are_normalised() {
    // ∫ D(wh) cos θh dωh = 1: the projected facet area is the macro surface.
    for d in dists().into_iter().filter(|d| d.visible) {
        for scale in [0.2f32, 1.0, 3.0] {
            let d = Dist {
                ax: d.ax * scale,
                ay: d.ay * scale,
                ..d
            };
            let m = d.make();
            let alpha = (d.ax * d.ay).sqrt() as f64;
            let v = hemisphere_integral(alpha, |wh| m.d(wh.as_vec3()) as f64 * wh.z);
            println!("{}: ∫ D cos = {v:.6}", d.name());
            assert!((v - 1.0).abs() < 1e-3, "{}: ∫ D cos θ = {v}", d.name());
        }
    }
}

#[test]
fn g1_is_smith_masking_of_d() {
    // Smith: G1(wo) ∫ D(wh) max(0, wo·wh) dωh = cos θo. Exact for
    // Trowbridge–Reitz; pbrt-v3's Beckmann Λ is a rational fit, good to
    // a few 1e-3 relative.
    for d in dists().into_iter().filter(|d| d.visible) {
        let m = d.make();
        let alpha = (d.ax * d.ay).sqrt() as f64;
        for deg in [0.0f32, 30.0, 60.0, 80.0, 88.0] {
            let wo = wo_at(deg);
            let wod = wo.as_dvec3();
            let proj =
                hemisphere_integral(alpha, |wh| m.d(wh.as_vec3()) as f64 * wod.dot(wh).max(0.0));
            let g1 = m.g1(wo) as f64;
            let got = g1 * proj / wod.z;
            let tol = if d.beckmann { 6e-3 } else { 2e-3 };
            println!("{} θo={deg}: G1·∫D⟨wo,wh⟩/cos θo = {got:.6}", d.name());
            assert!((got - 1.0).abs() < tol, "{} θo={deg}: {got}", d.name());
        }
        // G(wo, wi) ≤ min(G1(wo), G1(wi)) and G1 → 1 at normal incidence.
        assert!((m.g1(Vec3::Z) - 1.0).abs() < 1e-6);
        let (a, b) = (wo_at(70.0), wo_at(-50.0));
        assert!(m.g(a, b) <= m.g1(a).min(m.g1(b)) + 1e-7);
    }
}

#[test]
fn facet_normal_sampling_matches_its_density() {
    let mut seed = 0;
    for d in dists() {
        let m = d.make();
        for &deg in &REFLECT_ANGLES {
            let wo = wo_at(deg);
            let name = format!("wh {} θo={deg}", d.name());
            let r = chi2_sphere(
                |u| Some(m.sample_wh(wo, u)),
                // pbrt-v3's density takes |wo·wh|; the visible normals
                // are those with wo·wh > 0.
                |wh| {
                    let visible = !m.sample_visible() || wo.dot(wh) > 0.0;
                    if wh.z * wo.z > 0.0 && visible {
                        m.pdf(wo, wh)
                    } else {
                        0.0
                    }
                },
                &chi2_cfg(seed),
            );
            seed += 1;
            println!("{name}: {r}");
            assert!((r.pdf_integral - 1.0).abs() < 3e-3, "{name}: {r}");
            assert!(r.passed(sidak_significance(0.01, N_CHI2)), "{name}: {r}");
        }
    }
}

#[test]
fn chi2_fails_for_the_wrong_density() {
    // The harness rejects visible-normal samples judged by the density of
    // all normals (the difference between the two samplers matters).
    let d = Dist {
        beckmann: false,
        ax: 0.5,
        ay: 0.5,
        visible: true,
    };
    let vis = d.make();
    let all = Dist {
        visible: false,
        ..d
    }
    .make();
    let wo = wo_at(70.0);
    let r = chi2_sphere(
        |u| Some(vis.sample_wh(wo, u)),
        |wh| if wh.z > 0.0 { all.pdf(wo, wh) } else { 0.0 },
        &chi2_cfg(99),
    );
    assert!(!r.passed(0.01), "{r}");
    // And a reflection lobe judged with the other sampler's density.
    let b = reflection(d, Fresnel::NoOp);
    let b_all = reflection(
        Dist {
            visible: false,
            ..d
        },
        Fresnel::NoOp,
    );
    let r = chi2_sphere(
        |u| b.sample_f(wo, u).map(|s| s.wi),
        |wi| b_all.pdf(wo, wi),
        &chi2_cfg(98),
    );
    assert!(!r.passed(0.01), "{r}");
    // An anisotropic lobe with its axes swapped.
    let an = Dist {
        ax: 0.15,
        ay: 0.5,
        ..d
    };
    let swapped = Dist {
        ax: 0.5,
        ay: 0.15,
        ..d
    };
    let (b, bs) = (
        reflection(an, Fresnel::NoOp),
        reflection(swapped, Fresnel::NoOp),
    );
    let wo = wo_at(45.0);
    let r = chi2_sphere(
        |u| b.sample_f(wo, u).map(|s| s.wi),
        |wi| bs.pdf(wo, wi),
        &chi2_cfg(97),
    );
    assert!(!r.passed(0.01), "{r}");
}

// ------------------------------------------------------------ lobes

#[test]
fn microfacet_reflection_sampling() {
    let fresnel = Fresnel::Dielectric {
        eta_i: 1.0,
        eta_t: 1.5,
    };
    let mut seed = 1000;
    for d in dists() {
        let b = reflection(d, fresnel);
        for &deg in &REFLECT_ANGLES {
            let name = format!("reflection {} θo={deg}", d.name());
            let wo = wo_at(deg);
            chi2_lobe(&name, &b, wo, seed);
            seed += 1;
            check_sampled_f(&name, &b, wo);
        }
    }
}

#[test]
fn microfacet_transmission_sampling() {
    let mut seed = 2000;
    for d in dists() {
        let b = transmission(d);
        for &deg in &TRANSMIT_ANGLES {
            let name = format!("transmission {} θo={deg}", d.name());
            let wo = wo_at(deg);
            let accepted = chi2_lobe(&name, &b, wo, seed);
            seed += 1;
            check_sampled_f(&name, &b, wo);
            // From outside, nearly every visible facet refracts; from
            // inside beyond the critical angle, most facets reflect totally.
            if deg < 90.0 && d.visible {
                assert!(accepted > 0.97, "{name}: accepted {accepted}");
            }
            if deg == 135.0 {
                assert!(accepted < 0.5, "{name}: accepted {accepted}");
            }
        }
    }
}

#[test]
fn fresnel_blend_sampling() {
    let mut seed = 3000;
    for d in dists() {
        let b = blend(d);
        for &deg in &REFLECT_ANGLES {
            let name = format!("fresnel blend {} θo={deg}", d.name());
            let wo = wo_at(deg);
            chi2_lobe(&name, &b, wo, seed);
            seed += 1;
            check_sampled_f(&name, &b, wo);
        }
    }
}

#[test]
fn low_roughness_lobes_sample_their_density() {
    // Narrow lobes (α = 0.05, roughness ≈ 0.01 through roughness_to_alpha)
    // on a finer grid.
    let d = Dist {
        beckmann: false,
        ax: 0.05,
        ay: 0.05,
        visible: true,
    };
    let lobes = [
        ("reflection", reflection(d, Fresnel::NoOp)),
        ("transmission", transmission(d)),
        ("fresnel blend", blend(d)),
    ];
    for (i, (name, b)) in lobes.iter().enumerate() {
        let wo = wo_at(50.0);
        let r = chi2_sphere(
            |u| b.sample_f(wo, u).filter(|s| s.pdf > 0.0).map(|s| s.wi),
            |wi| front_facing_pdf(b, wo, wi),
            &Chi2Config {
                theta_res: 40,
                phi_res: 80,
                ..chi2_cfg(4000 + i as u64)
            },
        );
        println!("{name} α=0.05: {r}");
        assert!(r.passed(sidak_significance(0.01, N_CHI2)), "{name}: {r}");
    }
}

#[test]
fn reflection_lobes_are_reciprocal() {
    let mut rng = Pcg32::with_sequence(5);
    let fresnels = [
        Fresnel::NoOp,
        Fresnel::Dielectric {
            eta_i: 1.0,
            eta_t: 1.5,
        },
        Fresnel::Conductor {
            eta_i: Vec3::ONE,
            eta_t: Vec3::new(0.2, 0.9, 1.1),
            k: Vec3::new(3.9, 2.4, 2.2),
        },
    ];
    for d in dists() {
        let mut lobes: Vec<Bxdf> = fresnels.iter().map(|&f| reflection(d, f)).collect();
        lobes.push(blend(d));
        for b in &lobes {
            let mut nonzero = 0;
            for _ in 0..5000 {
                let wo = pbrs::sampling::uniform_sample_hemisphere(Vec2::new(
                    rng.uniform_f32(),
                    rng.uniform_f32(),
                ));
                let wi = pbrs::sampling::uniform_sample_hemisphere(Vec2::new(
                    rng.uniform_f32(),
                    rng.uniform_f32(),
                ));
                let (a, c) = (b.f(wo, wi), b.f(wi, wo));
                // Rounding only: 1/(wi·wh) amplifies it where the pair is
                // nearly opposite.
                assert!(
                    (a - c).abs().max_element() <= 1e-3 * a.max_element() + 1e-7,
                    "{} {b:?}: f(wo, wi) {a} vs f(wi, wo) {c}",
                    d.name()
                );
                if a.max_element() > 0.0 {
                    nonzero += 1;
                }
            }
            assert!(nonzero > 4000, "{}: {nonzero}", d.name());
        }
    }
}

#[test]
fn transmission_is_reciprocal_up_to_the_radiance_factor() {
    // A radiance BTDF carries 1/η² of the side it leaves into:
    // f(wo, wi)/f(wi, wo) = (η_o/η_i)², with η_o the index on wo's side.
    let mut rng = Pcg32::with_sequence(6);
    for d in dists() {
        let b = transmission(d);
        let mut checked = 0;
        for _ in 0..5000 {
            let wo = pbrs::sampling::uniform_sample_sphere(Vec2::new(
                rng.uniform_f32(),
                rng.uniform_f32(),
            ));
            let Some(s) = b.sample_f(wo, Vec2::new(rng.uniform_f32(), rng.uniform_f32())) else {
                continue;
            };
            if s.pdf == 0.0 {
                continue;
            }
            let (eta_o, eta_i) = if wo.z > 0.0 { (1.0, 1.5) } else { (1.5, 1.0) };
            // Pairs grazing their facet are left out: there the generalised
            // half vector, D and 1 − F amplify f32 rounding to ~1e-3 (the
            // f64 ratio is exact to 1e-10 there too).
            let h = (eta_o * wo + eta_i * s.wi).normalize();
            if wo.dot(h).abs().min(s.wi.dot(h).abs()) < 0.05 {
                continue;
            }
            let back = b.f(s.wi, wo);
            let want = s.f * (eta_i * eta_i) / (eta_o * eta_o);
            assert!(
                (back - want).abs().max_element() <= 1e-3 * want.max_element() + 1e-7,
                "{}: f(wi, wo) {back} vs {want}; wo {:?} wi {:?}",
                d.name(),
                wo,
                s.wi
            );
            checked += 1;
        }
        // Half the wo are inside, where total internal reflection rejects
        // a good part of the samples.
        assert!(checked > 2500, "{}: {checked}", d.name());
    }
}

#[test]
fn transmission_follows_snell_through_the_generalised_half_vector() {
    let mut rng = Pcg32::with_sequence(8);
    for d in dists() {
        let b = transmission(d);
        for &deg in &TRANSMIT_ANGLES {
            let wo = wo_at(deg);
            let (eta_o, eta_i) = if wo.z > 0.0 {
                (1.0f64, 1.5f64)
            } else {
                (1.5, 1.0)
            };
            for _ in 0..2000 {
                let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
                let Some(s) = b.sample_f(wo, u) else { continue };
                if s.pdf == 0.0 {
                    continue;
                }
                let (o, i) = (wo.as_dvec3(), s.wi.as_dvec3());
                assert!(o.z * i.z < 0.0, "not transmitted");
                assert!((i.length() - 1.0).abs() < 1e-5);
                // The facet normal: −(η_o wo + η_i wi), normalised.
                let h = -(eta_o * o + eta_i * i).normalize();
                let h = if h.z < 0.0 { -h } else { h };
                // Snell about the facet: η_o sin θo = η_i sin θi ...
                let (co, ci) = (o.dot(h), i.dot(h));
                let (so, si) = (
                    (1.0 - co * co).max(0.0).sqrt(),
                    (1.0 - ci * ci).max(0.0).sqrt(),
                );
                assert!(
                    (eta_o * so - eta_i * si).abs() < 2e-4,
                    "{} θo={deg}: Snell {} vs {}",
                    d.name(),
                    eta_o * so,
                    eta_i * si
                );
                // ... on opposite sides of the facet, and coplanar with it.
                assert!(co * ci < 0.0);
                assert!(o.cross(i).dot(h).abs() < 1e-4, "not coplanar");
            }
        }
    }
}

/// Albedo ∫ f cos θi dωi of a lobe by its own sampler: (mean, standard error).
fn albedo(b: &Bxdf, wo: Vec3, n: usize, seed: u64) -> (f64, f64) {
    let mut rng = Pcg32::with_sequence(seed);
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
        let w = match b.sample_f(wo, u) {
            Some(s) if s.pdf > 0.0 => (s.f.x * s.wi.z.abs() / s.pdf) as f64,
            _ => 0.0,
        };
        sum += w;
        sum2 += w * w;
    }
    let mean = sum / n as f64;
    let var = (sum2 / n as f64 - mean * mean).max(0.0);
    (mean, (var / n as f64).sqrt())
}

/// Single-scattering albedo of a white GGX conductor from the textbook
/// formulas in f64 (D, Smith Λ, height-correlated G), by quadrature over the
/// facet normal: E = ∫ D(wh) G(wo, wi) (wo·wh)/cos θo dωh over the facets
/// whose reflection wi stays above the surface.
fn ggx_albedo_quadrature(alpha: f64, wo: DVec3) -> f64 {
    let lambda = |w: DVec3| {
        let t2 = (1.0 - w.z * w.z) / (w.z * w.z);
        0.5 * ((1.0 + alpha * alpha * t2).sqrt() - 1.0)
    };
    let d = |h: DVec3| {
        let c2 = h.z * h.z;
        let e = c2 + (1.0 - c2) / (alpha * alpha);
        1.0 / (PI * alpha * alpha * e * e)
    };
    hemisphere_integral(alpha, |h| {
        let c = wo.dot(h);
        let wi = 2.0 * c * h - wo;
        if c <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        d(h) / (1.0 + lambda(wo) + lambda(wi)) * c / wo.z
    })
}

#[test]
fn white_furnace_of_the_rough_conductor() {
    // With F = 1 and r = 1 the albedo is ≤ 1: each visible-normal sample
    // weighs G(wo, wi)/G1(wo) ≤ 1. Single scattering loses the light that
    // would bounce again between facets, so the albedo falls below 1 as
    // the roughness grows.
    let n = 100_000;
    for beckmann in [false, true] {
        for alpha in [0.01f32, 0.05, 0.3, 0.7, 1.0] {
            let d = Dist {
                beckmann,
                ax: alpha,
                ay: alpha,
                visible: true,
            };
            let b = MicrofacetReflection {
                r: Vec3::ONE,
                distribution: d.make(),
                fresnel: Fresnel::NoOp,
            }
            .into();
            for deg in [0.0f32, 45.0, 70.0] {
                let wo = wo_at(deg);
                let (e, se) = albedo(&b, wo, n, (alpha * 1000.0) as u64);
                println!("{} θo={deg}: albedo {e:.5} ± {se:.1e}", d.name());
                assert!(e <= 1.0 + 1e-6, "{}: albedo {e} > 1", d.name());
                // Low roughness, normal incidence: the loss is the facets
                // beyond 45° (α²/(1 + α²) for GGX, see below; far less for
                // Beckmann) plus masking Λ(wi)/(1 + Λ(wi)) of the rest,
                // with Λ ≈ α² tan²θi/4 and tan²θi ≈ 4 tan²θh: of order α⁴
                // ln(1/α). So 1 − E ≤ 1.5 α² (+ 4 s.e.).
                if alpha <= 0.05 && deg == 0.0 {
                    let max_loss = 1.5 * (alpha as f64).powi(2) + 4.0 * se;
                    assert!(1.0 - e <= max_loss, "{}: loss {}", d.name(), 1.0 - e);
                }
                if !beckmann {
                    let want = ggx_albedo_quadrature(alpha as f64, wo.as_dvec3());
                    println!("  quadrature {want:.5}");
                    // 4 standard errors plus the quadrature's own error
                    // (the midpoint rule across the horizon cut, ~1e-4).
                    assert!(
                        (e - want).abs() < 4.0 * se + 5e-4,
                        "{} θo={deg}: albedo {e} vs quadrature {want}",
                        d.name()
                    );
                }
            }
        }
    }
    // The known loss of single scattering, derived: at normal incidence
    // the reflection about a facet tilted by θh leaves at 2θh, below the
    // horizon once θh > 45°, and GGX puts the fraction α²/(1 + α²) of its
    // projected area D·cos θh beyond tan θh = 1 (P(tan²θh < t) = t/(α² + t)).
    // So E(0°) ≤ 1/(1 + α²): at most one half at α = 1.
    for alpha in [0.3f32, 0.7, 1.0] {
        let b: Bxdf = MicrofacetReflection {
            r: Vec3::ONE,
            distribution: TrowbridgeReitz::new(alpha, alpha).into(),
            fresnel: Fresnel::NoOp,
        }
        .into();
        let (e, se) = albedo(&b, Vec3::Z, n, 17);
        let bound = 1.0 / (1.0 + (alpha as f64).powi(2));
        println!("α={alpha}: E(0°) = {e:.5}, horizon bound {bound:.5}");
        assert!(e <= bound + 4.0 * se, "α={alpha}: {e} > {bound}");
    }
}
