//! Distribution1D / Distribution2D: the seed's check, properties over random
//! inputs, degenerate inputs, and chi-square fits of the sampled histograms.

use glam::Vec2;
use pbrs::sampling::chi2::{chi2_square, sidak_significance, Chi2Config};
use pbrs::sampling::{DiscreteCdf, Distribution1D, Distribution2D, Pcg32, ONE_MINUS_EPSILON};

/// Chi-square tests in this file (for the Šidák correction).
const N_CHI2_TESTS: usize = 2 * 8;

fn significance() -> f64 {
    sidak_significance(0.01, N_CHI2_TESTS)
}

#[test]
fn seed_check_pdf_of_sample_matches_pdf() {
    #[rustfmt::skip]
    let f = [
        1.0, 4.5, 7.6, 2.1,
        4.1, 9.1, 1.8, 2.6,
        11.4, 16.3, 6.4, 7.2,
        1.5, 1.9, 2.1, 5.4,
    ];
    let d = Distribution2D::new(&f, 4, 4);
    let (p, pdf) = d.sample_continuous(Vec2::new(0.423, 0.769));
    assert!(pdf > 0.0);
    assert_eq!(
        pdf,
        d.pdf(p),
        "sampled pdf {pdf} vs pdf({p}) = {}",
        d.pdf(p)
    );
    // And the pdf is the function value over its integral.
    let total: f32 = f.iter().sum::<f32>() / 16.0;
    let iu = (p.x * 4.0) as usize;
    let iv = (p.y * 4.0) as usize;
    assert!((pdf - f[iv * 4 + iu] / total).abs() < 1e-5 * pdf);
}

fn random_func(rng: &mut Pcg32, n: usize) -> Vec<f32> {
    (0..n)
        .map(|_| {
            // Some zeros, some spikes, mostly ordinary values.
            match rng.uniform_u32_below(10) {
                0 => 0.0,
                1 => 100.0 * rng.uniform_f32(),
                _ => rng.uniform_f32(),
            }
        })
        .collect()
}

#[test]
fn distribution1d_properties_on_random_inputs() {
    let mut rng = Pcg32::with_sequence(1);
    for trial in 0..200 {
        let n = 1 + rng.uniform_u32_below(64) as usize;
        let f = random_func(&mut rng, n);
        let d = Distribution1D::new(&f);
        assert_eq!(d.count(), n);
        let expect_int: f32 = f.iter().sum::<f32>() / n as f32;
        assert!((d.func_int() - expect_int).abs() <= 1e-5 * expect_int.max(1e-6));
        // pdf integrates to 1; discrete probabilities sum to 1.
        let integral: f64 = (0..n)
            .map(|i| d.pdf((i as f32 + 0.5) / n as f32) as f64)
            .sum::<f64>()
            / n as f64;
        let psum: f64 = (0..n).map(|i| d.discrete_pdf(i) as f64).sum();
        if expect_int > 0.0 {
            assert!((integral - 1.0).abs() < 1e-5, "trial {trial}: {integral}");
            assert!((psum - 1.0).abs() < 1e-5);
        }
        for k in 0..1000 {
            let u = if k == 0 {
                0.0
            } else if k == 1 {
                ONE_MINUS_EPSILON
            } else {
                rng.uniform_f32()
            };
            let (x, pdf, off) = d.sample_continuous(u);
            assert!((0.0..1.0).contains(&x), "x = {x}");
            assert!(pdf > 0.0, "sampled a zero bin: u={u} off={off} f={:?}", f);
            assert_eq!(pdf, d.pdf(x));
            assert_eq!(((x * n as f32) as usize).min(n - 1), off);
            let (i, p, ur) = d.sample_discrete(u);
            assert_eq!(i, off);
            assert_eq!(p, d.discrete_pdf(i));
            assert!((0.0..1.0).contains(&ur));
        }
    }
}

#[test]
fn distribution2d_properties_on_random_inputs() {
    let mut rng = Pcg32::with_sequence(2);
    for _ in 0..50 {
        let nu = 1 + rng.uniform_u32_below(16) as usize;
        let nv = 1 + rng.uniform_u32_below(16) as usize;
        let f = random_func(&mut rng, nu * nv);
        let d = Distribution2D::new(&f, nu, nv);
        let mut integral = 0.0f64;
        for v in 0..nv {
            for u in 0..nu {
                let p = Vec2::new((u as f32 + 0.5) / nu as f32, (v as f32 + 0.5) / nv as f32);
                integral += d.pdf(p) as f64;
            }
        }
        integral /= (nu * nv) as f64;
        assert!((integral - 1.0).abs() < 1e-5, "{integral}");
        for _ in 0..1000 {
            let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
            let (p, pdf) = d.sample_continuous(u);
            assert!(p.x < 1.0 && p.y < 1.0 && p.x >= 0.0 && p.y >= 0.0);
            assert!(pdf > 0.0);
            assert_eq!(pdf, d.pdf(p));
        }
        let (p, pdf) = d.sample_continuous(Vec2::splat(ONE_MINUS_EPSILON));
        assert!(p.x < 1.0 && p.y < 1.0 && pdf == d.pdf(p));
    }
}

#[test]
fn degenerate_inputs() {
    // All zero: uniform.
    let d = Distribution1D::new(&[0.0; 7]);
    assert_eq!(d.func_int(), 0.0);
    for k in 0..100 {
        let u = k as f32 / 100.0;
        let (x, pdf, _) = d.sample_continuous(u);
        assert!((x - u).abs() < 1e-6);
        assert_eq!(pdf, 1.0);
    }
    assert!((d.discrete_pdf(3) - 1.0 / 7.0).abs() < 1e-7);
    // Single bin.
    let d = Distribution1D::new(&[3.0]);
    assert_eq!(d.count(), 1);
    assert_eq!(d.func_int(), 3.0);
    let (x, pdf, off) = d.sample_continuous(0.25);
    assert_eq!((x, pdf, off), (0.25, 1.0, 0));
    assert_eq!(d.sample_discrete(0.7), (0, 1.0, 0.7));
    let (x, _, _) = d.sample_continuous(ONE_MINUS_EPSILON);
    assert!(x < 1.0);
    // Single zero bin, empty slice.
    for d in [Distribution1D::new(&[0.0]), Distribution1D::new(&[])] {
        assert_eq!(d.sample_continuous(0.5).1, 1.0);
    }
    // Negative and NaN count as zero.
    let d = Distribution1D::new(&[-1.0, f32::NAN, 2.0, f32::NEG_INFINITY]);
    for k in 0..100 {
        let (x, pdf, off) = d.sample_continuous(k as f32 / 100.0);
        assert_eq!(off, 2);
        assert!((0.5..0.75).contains(&x));
        assert_eq!(pdf, 4.0);
    }
    assert_eq!(d.pdf(0.1), 0.0);
    // 2D all zero: uniform; 2D with one zero row never samples it.
    let d = Distribution2D::new(&[0.0; 6], 3, 2);
    let (_, pdf) = d.sample_continuous(Vec2::new(0.3, 0.9));
    assert_eq!(pdf, 1.0);
    let d = Distribution2D::new(&[1.0, 2.0, 0.0, 0.0, 5.0, 1.0], 2, 3);
    let mut rng = Pcg32::with_sequence(9);
    for _ in 0..1000 {
        let (p, pdf) = d.sample_continuous(Vec2::new(rng.uniform_f32(), rng.uniform_f32()));
        assert!(!(1.0 / 3.0..2.0 / 3.0).contains(&p.y));
        assert!(pdf > 0.0 && pdf == d.pdf(p));
    }
    // Out-of-range and NaN u are clamped, never panic or loop.
    let d = Distribution1D::new(&[1.0, 0.0, 3.0]);
    for u in [f32::NAN, -1.0, 1.0, 2.0, f32::INFINITY] {
        let (x, pdf, _) = d.sample_continuous(u);
        assert!(
            (0.0..1.0).contains(&x) && pdf > 0.0 && pdf == d.pdf(x),
            "u={u}"
        );
        let (i, p, ur) = d.sample_discrete(u);
        assert!(i != 1 && p > 0.0 && (0.0..1.0).contains(&ur));
    }
    // Single bin 2D.
    let d = Distribution2D::new(&[4.0], 1, 1);
    assert_eq!(
        d.sample_continuous(Vec2::new(0.2, 0.6)),
        (Vec2::new(0.2, 0.6), 1.0)
    );
}

#[test]
fn distribution1d_histogram_chi_square() {
    let mut rng = Pcg32::with_sequence(3);
    for t in 0..8 {
        let n = 2 + rng.uniform_u32_below(40) as usize;
        let f = random_func(&mut rng, n);
        let d = Distribution1D::new(&f);
        let cfg = Chi2Config {
            theta_res: n,
            phi_res: 1,
            sample_count: 200_000,
            seed: t,
            ..Default::default()
        };
        let r = chi2_square(
            |u| Some(Vec2::new(d.sample_continuous(u.x).0, u.y)),
            |p| d.pdf(p.x),
            &cfg,
        );
        assert!((r.pdf_integral - 1.0).abs() < 1e-4, "{r}");
        assert!(r.passed(significance()), "trial {t}: {r}");
    }
}

#[test]
fn distribution2d_histogram_chi_square() {
    let mut rng = Pcg32::with_sequence(4);
    for t in 0..8 {
        let nu = 1 + rng.uniform_u32_below(12) as usize;
        let nv = 1 + rng.uniform_u32_below(12) as usize;
        let f = random_func(&mut rng, nu * nv);
        let d = Distribution2D::new(&f, nu, nv);
        let cfg = Chi2Config {
            theta_res: nu,
            phi_res: nv,
            sample_count: 300_000,
            seed: 100 + t,
            ..Default::default()
        };
        let r = chi2_square(|u| Some(d.sample_continuous(u).0), |p| d.pdf(p), &cfg);
        assert!((r.pdf_integral - 1.0).abs() < 1e-4, "{r}");
        assert!(r.passed(significance()), "trial {t}: {r}");
    }
}

#[test]
fn chi_square_rejects_a_wrong_distribution() {
    // Sample one function, claim another that differs a little.
    let f = [1.0, 2.0, 3.0, 4.0];
    let g = [1.0, 2.1, 3.0, 3.9];
    let df = Distribution1D::new(&f);
    let dg = Distribution1D::new(&g);
    let cfg = Chi2Config {
        theta_res: 4,
        phi_res: 1,
        sample_count: 500_000,
        ..Default::default()
    };
    let r = chi2_square(
        |u| Some(Vec2::new(df.sample_continuous(u.x).0, u.y)),
        |p| dg.pdf(p.x),
        &cfg,
    );
    assert!(!r.passed(significance()), "{r}");
}

/// `DiscreteCdf` chooses the bin `Distribution1D::sample_discrete` chooses,
/// for every u (random ones, each CDF entry and its neighbours, the ends,
/// out-of-range and NaN), and has the same `func_int`, bit for bit: on
/// random functions with zeros, negatives, NaN and infinities, all-zero
/// ones, a single bin, the empty function and a long one.
#[test]
fn discrete_cdf_chooses_distribution1ds_bins() {
    let mut rng = Pcg32::with_sequence(0x05ee_dcdf);
    let mut funcs: Vec<Vec<f32>> = vec![
        vec![],
        vec![0.0],
        vec![3.0],
        vec![0.0; 7],
        vec![f32::NAN, -1.0, 0.0],
        vec![1.0, f32::INFINITY, 2.0, f32::INFINITY],
        vec![f32::MAX, f32::MAX, 1.0],
        vec![1e-30, 1.0, 1e-30, 0.0, 5.0],
    ];
    for n in [2, 3, 17, 100, 1000] {
        for _ in 0..6 {
            funcs.push(random_func(&mut rng, n));
        }
    }
    funcs.push(
        (0..100_000)
            .map(|i| {
                if i % 7 == 0 {
                    0.0
                } else {
                    rng.uniform_f32() * 10.0
                }
            })
            .collect(),
    );
    for f in &funcs {
        let d = Distribution1D::new(f);
        let c = DiscreteCdf::new(f);
        assert_eq!(c.func_int().to_bits(), d.func_int().to_bits(), "{f:?}");
        let n = d.count();
        let mut us: Vec<f32> = (0..2000).map(|_| rng.uniform_f32()).collect();
        // The CDF entries (as Distribution1D's documentation defines them:
        // f64 prefix sums of the values, NaN and negatives as 0, over the
        // total) and the floats beside them.
        let clean = |v: f32| {
            if v.is_nan() || v <= 0.0 {
                0.0
            } else {
                v.min(f32::MAX) as f64
            }
        };
        let total: f64 = f.iter().map(|&v| clean(v)).sum();
        let mut acc = 0.0f64;
        for &v in f {
            acc += clean(v);
            let edge = (acc / total) as f32;
            for u in [
                edge,
                f32::from_bits(edge.to_bits().saturating_sub(1)),
                f32::from_bits(edge.to_bits() + 1),
            ] {
                us.push(u);
            }
        }
        us.extend([
            0.0,
            -0.0,
            -1.0,
            1.0,
            2.0,
            ONE_MINUS_EPSILON,
            f32::NAN,
            f32::INFINITY,
        ]);
        for u in us {
            assert_eq!(
                c.sample_index(u),
                d.sample_discrete(u).0,
                "u = {u} over {} bins",
                n
            );
        }
    }
}
