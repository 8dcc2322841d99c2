//! Mitsuba-style chi-square tests of every warp against its pdf, with a
//! Šidák correction for the number of tests, and proof that the harness can
//! fail (deliberately wrong pdfs are rejected).

use glam::{Vec2, Vec3};
use pbrs::sampling::chi2::{chi2_sphere, chi2_square, sidak_significance, Chi2Config};
use pbrs::sampling::*;

/// Number of chi-square tests that must pass in this file.
const N_TESTS: usize = 9;

fn alpha() -> f64 {
    sidak_significance(0.01, N_TESTS)
}

fn cfg(seed: u64) -> Chi2Config {
    Chi2Config {
        theta_res: 10,
        phi_res: 20,
        sample_count: 1_000_000,
        seed,
        ..Default::default()
    }
}

fn check_sphere(
    name: &str,
    seed: u64,
    sample: impl FnMut(Vec2) -> Option<Vec3>,
    pdf: impl Fn(Vec3) -> f32,
) {
    let r = chi2_sphere(sample, pdf, &cfg(seed));
    println!("{name}: {r}");
    assert!(
        (r.pdf_integral - 1.0).abs() < 1e-3,
        "{name}: pdf integrates to {}",
        r.pdf_integral
    );
    assert!(r.passed(alpha()), "{name}: {r}");
}

fn check_square(
    name: &str,
    seed: u64,
    sample: impl FnMut(Vec2) -> Option<Vec2>,
    pdf: impl Fn(Vec2) -> f32,
) {
    let r = chi2_square(
        sample,
        pdf,
        &Chi2Config {
            theta_res: 16,
            phi_res: 16,
            ..cfg(seed)
        },
    );
    println!("{name}: {r}");
    assert!(
        (r.pdf_integral - 1.0).abs() < 1e-3,
        "{name}: pdf integrates to {}",
        r.pdf_integral
    );
    assert!(r.passed(alpha()), "{name}: {r}");
}

fn hemi(w: Vec3, v: f32) -> f32 {
    if w.z >= 0.0 {
        v
    } else {
        0.0
    }
}

#[test]
fn uniform_sphere() {
    check_sphere(
        "uniform sphere",
        1,
        |u| Some(uniform_sample_sphere(u)),
        |_| uniform_sphere_pdf(),
    );
}

#[test]
fn uniform_hemisphere() {
    check_sphere(
        "uniform hemisphere",
        2,
        |u| Some(uniform_sample_hemisphere(u)),
        |w| hemi(w, uniform_hemisphere_pdf()),
    );
}

#[test]
fn cosine_hemisphere() {
    check_sphere(
        "cosine hemisphere",
        3,
        |u| Some(cosine_sample_hemisphere(u)),
        |w| hemi(w, cosine_hemisphere_pdf(w.z)),
    );
}

fn cone_pdf(w: Vec3, cos_max: f32) -> f32 {
    if w.z >= cos_max {
        uniform_cone_pdf(cos_max)
    } else {
        0.0
    }
}

#[test]
fn uniform_cone_wide() {
    // Edge inside a θ cell (not aligned with the grid).
    let c = 0.3f32;
    check_sphere(
        "cone 0.3",
        4,
        |u| Some(uniform_sample_cone(u, c)),
        |w| cone_pdf(w, c),
    );
}

#[test]
fn uniform_cone_narrow() {
    let c = 0.95f32;
    let r = chi2_sphere(
        |u| Some(uniform_sample_cone(u, c)),
        |w| cone_pdf(w, c),
        &Chi2Config {
            theta_res: 60,
            phi_res: 12,
            ..cfg(5)
        },
    );
    println!("cone 0.95: {r}");
    assert!((r.pdf_integral - 1.0).abs() < 1e-3);
    assert!(r.passed(alpha()), "{r}");
}

fn disk_to_square(p: Vec2) -> Vec2 {
    (p + Vec2::ONE) * 0.5
}

fn disk_pdf_on_square(p: Vec2) -> f32 {
    // Area density on the square [0,1]^2 of a uniform disk point mapped there.
    let d = 2.0 * p - Vec2::ONE;
    if d.length_squared() <= 1.0 {
        4.0 * uniform_disk_pdf()
    } else {
        0.0
    }
}

#[test]
fn concentric_disk() {
    check_square(
        "concentric disk",
        6,
        |u| Some(disk_to_square(concentric_sample_disk(u))),
        disk_pdf_on_square,
    );
}

#[test]
fn uniform_disk() {
    check_square(
        "uniform disk",
        7,
        |u| Some(disk_to_square(uniform_sample_disk(u))),
        disk_pdf_on_square,
    );
}

#[test]
fn uniform_triangle() {
    // Barycentrics (b0, b1) are uniform over the half square: density 2.
    check_square(
        "triangle",
        8,
        |u| Some(uniform_sample_triangle(u)),
        |b| {
            if b.x + b.y <= 1.0 {
                2.0
            } else {
                0.0
            }
        },
    );
}

#[test]
fn uniform_sphere_fine_grid() {
    // A finer grid with pooling of the polar cells.
    let r = chi2_sphere(
        |u| Some(uniform_sample_sphere(u)),
        |_| uniform_sphere_pdf(),
        &Chi2Config {
            theta_res: 40,
            phi_res: 80,
            min_expected: 50.0,
            ..cfg(9)
        },
    );
    println!("sphere fine: {r}");
    assert!(r.passed(alpha()), "{r}");
}

// ---- the harness must be able to fail ----

#[test]
fn rejects_cosine_sampling_with_uniform_pdf() {
    let r = chi2_sphere(
        |u| Some(cosine_sample_hemisphere(u)),
        |w| hemi(w, uniform_hemisphere_pdf()),
        &cfg(10),
    );
    println!("wrong pdf: {r}");
    let (obs, exp) = r.histogram_images();
    assert_eq!((obs.width, obs.height, exp.width), (20, 10, 20));
    assert_eq!(obs.data.iter().sum::<f32>() / 3.0, 1_000_000.0);
    assert!(!r.passed(0.01), "{r}");
    assert!(r.p_value < 1e-12);
}

#[test]
fn rejects_a_slightly_wrong_cone_pdf() {
    // Claimed cone is 1% (in cos θ range) narrower than the sampled one, and
    // renormalised so the pdf still integrates to one.
    let (c_true, c_claim) = (0.5f32, 0.505f32);
    let r = chi2_sphere(
        |u| Some(uniform_sample_cone(u, c_true)),
        |w| cone_pdf(w, c_claim),
        &cfg(11),
    );
    println!("slightly wrong cone: {r}");
    assert!(!r.passed(0.01), "{r}");
}

#[test]
fn rejects_invalid_samples() {
    let r = chi2_sphere(
        |u| Some(Vec3::new(u.x, u.y, 0.0) * 2.0),
        |_| uniform_sphere_pdf(),
        &Chi2Config {
            sample_count: 1000,
            ..cfg(12)
        },
    );
    assert!(r.invalid_samples > 0 && !r.passed(0.01));
}
