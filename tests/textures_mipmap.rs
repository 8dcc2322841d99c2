//! MIP maps against brute force on small known images: the pyramid's
//! levels (box averages of the finest level), pbrt-v3's resampling of
//! sizes that are not powers of two (separable four-tap Lanczos, f64 here),
//! the EWA weight table, and trilinear and EWA lookups against filtering
//! every texel of the level directly.

use glam::{Vec2, Vec3};
use pbrs::sampling::rng::Pcg32;
use pbrs::textures::{ewa_weights, MipMap, Wrap};

fn rng() -> Pcg32 {
    Pcg32::with_sequence(7)
}

fn random_image(r: &mut Pcg32, w: usize, h: usize) -> Vec<f32> {
    (0..w * h).map(|_| r.uniform_f32() * 4.0).collect()
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + b.abs())
}

#[test]
fn levels_are_box_averages_of_the_finest() {
    let mut r = rng();
    let (w, h) = (8usize, 4usize);
    let img = random_image(&mut r, w, h);
    let m = MipMap::new(w, h, img.clone(), false, 8.0, Wrap::Repeat).unwrap();
    assert_eq!(m.levels(), 4, "1 + log2(max(8, 4))");
    let sizes: Vec<_> = (0..4).map(|l| m.level_size(l)).collect();
    assert_eq!(sizes, vec![(8, 4), (4, 2), (2, 1), (1, 1)]);
    for l in 0..4 {
        let (lw, lh) = m.level_size(l);
        let (bw, bh) = (w / lw, h / lh);
        for t in 0..lh {
            for s in 0..lw {
                let mut sum = 0.0f64;
                for j in 0..bh {
                    for i in 0..bw {
                        sum += img[(t * bh + j) * w + s * bw + i] as f64;
                    }
                }
                let mean = sum / (bw * bh) as f64;
                let got = m.texel(l, s as i32, t as i32) as f64;
                assert!(
                    close(got, mean, 1e-6),
                    "level {l} ({s}, {t}): {got} vs {mean}"
                );
            }
        }
    }
    // pbrt-v3 averages 2×2 texels through the wrap mode: with "black", a
    // level of height 1 averages with black rows, so the 1×1 level of an
    // 8×4 image is half its mean.
    let b = MipMap::new(w, h, img.clone(), false, 8.0, Wrap::Black).unwrap();
    let mean = img.iter().map(|&v| v as f64).sum::<f64>() / img.len() as f64;
    assert!(close(b.texel(3, 0, 0) as f64, 0.5 * mean, 1e-6));
    // Out-of-range texels by wrap mode.
    assert_eq!(b.texel(0, -1, 0), 0.0);
    assert_eq!(m.texel(0, -1, 0), img[7]);
    let c = MipMap::new(w, h, img.clone(), false, 8.0, Wrap::Clamp).unwrap();
    assert_eq!(c.texel(0, 9, -3), img[7]);
}

/// pbrt-v3's Lanczos(x, τ = 2) in f64.
fn lanczos(x: f64) -> f64 {
    let x = x.abs();
    if x < 1e-5 {
        return 1.0;
    }
    if x > 1.0 {
        return 0.0;
    }
    let sinc = |y: f64| (std::f64::consts::PI * y).sin() / (std::f64::consts::PI * y);
    sinc(2.0 * x) * sinc(x)
}

/// One axis of pbrt-v3's resampling from `old` to `new` texels in f64:
/// output `i` is centred at (i + ½)·old/new, its four taps start at the
/// nearest texel to centre − 2, weighted by Lanczos((tap − centre)/2),
/// normalised.
fn taps(old: usize, new: usize, i: usize) -> Vec<(i64, f64)> {
    let center = (i as f64 + 0.5) * old as f64 / new as f64;
    let first = (center - 2.0 + 0.5).floor() as i64;
    let w: Vec<f64> = (0..4)
        .map(|j| lanczos(((first + j) as f64 + 0.5 - center) / 2.0))
        .collect();
    let sum: f64 = w.iter().sum();
    (0..4).map(|j| (first + j as i64, w[j] / sum)).collect()
}

fn resampled(img: &[f64], w: usize, h: usize, pw: usize, ph: usize, wrap: Wrap) -> Vec<f64> {
    let tap_index = |i: i64, n: usize| -> Option<usize> {
        let n = n as i64;
        let i = match wrap {
            Wrap::Repeat => i.rem_euclid(n),
            Wrap::Clamp => i.clamp(0, n - 1),
            Wrap::Black => i,
        };
        (0..n).contains(&i).then_some(i as usize)
    };
    let mut rows = vec![0.0; pw * h];
    for t in 0..h {
        for s in 0..pw {
            rows[t * pw + s] = taps(w, pw, s)
                .into_iter()
                .filter_map(|(i, wt)| tap_index(i, w).map(|i| wt * img[t * w + i]))
                .sum();
        }
    }
    let mut out = vec![0.0; pw * ph];
    for t in 0..ph {
        for s in 0..pw {
            let v: f64 = taps(h, ph, t)
                .into_iter()
                .filter_map(|(i, wt)| tap_index(i, h).map(|i| wt * rows[i * pw + s]))
                .sum();
            out[t * pw + s] = v.max(0.0);
        }
    }
    out
}

#[test]
fn sizes_not_powers_of_two_are_resampled_as_pbrt_v3() {
    let mut r = rng();
    for (w, h) in [(5usize, 3usize), (3, 7), (6, 1)] {
        // Some negative values too, so the clamp after the t pass shows.
        let img: Vec<f32> = random_image(&mut r, w, h).iter().map(|v| v - 1.0).collect();
        let img64: Vec<f64> = img.iter().map(|&v| v as f64).collect();
        let (pw, ph) = (w.next_power_of_two(), h.next_power_of_two());
        for wrap in [Wrap::Repeat, Wrap::Clamp, Wrap::Black] {
            let m = MipMap::new(w, h, img.clone(), false, 8.0, wrap).unwrap();
            assert_eq!(m.level_size(0), (pw, ph));
            let e = resampled(&img64, w, h, pw, ph, wrap);
            for t in 0..ph {
                for s in 0..pw {
                    let got = m.texel(0, s as i32, t as i32) as f64;
                    let want = e[t * pw + s];
                    assert!(
                        (got - want).abs() < 2e-5 * (1.0 + want.abs()),
                        "{w}×{h} {wrap:?} ({s}, {t}): {got} vs {want}"
                    );
                }
            }
        }
    }
    // A constant stays constant (the weights are normalised).
    let m = MipMap::new(3, 5, vec![Vec3::splat(0.7); 15], false, 8.0, Wrap::Clamp).unwrap();
    for t in 0..8 {
        for s in 0..4 {
            assert!((m.texel(0, s, t) - Vec3::splat(0.7)).abs().max_element() < 1e-6);
        }
    }
}

#[test]
fn ewa_weight_table_is_pbrt_v3s_gaussian() {
    let w = ewa_weights();
    assert_eq!(w.len(), 128);
    for (i, &v) in w.iter().enumerate() {
        let r2 = i as f64 / 127.0;
        let e = (-2.0 * r2).exp() - (-2.0f64).exp();
        assert!((v as f64 - e).abs() < 1e-6, "{i}: {v} vs {e}");
    }
    assert!(w[127].abs() < 1e-6 && w[0] > w[64] && w[64] > w[126]);
}

/// Bilinear interpolation at `st` on a level of `m` (f64, from its texels).
fn bilerp(m: &MipMap<f32>, level: usize, st: Vec2) -> f64 {
    let (w, h) = m.level_size(level);
    let s = st.x as f64 * w as f64 - 0.5;
    let t = st.y as f64 * h as f64 - 0.5;
    let (s0, t0) = (s.floor(), t.floor());
    let (ds, dt) = (s - s0, t - t0);
    let tx = |i: f64, j: f64| m.texel(level, i as i32, j as i32) as f64;
    (1.0 - ds) * (1.0 - dt) * tx(s0, t0)
        + (1.0 - ds) * dt * tx(s0, t0 + 1.0)
        + ds * (1.0 - dt) * tx(s0 + 1.0, t0)
        + ds * dt * tx(s0 + 1.0, t0 + 1.0)
}

#[test]
fn trilinear_lookups_blend_two_levels() {
    let mut r = rng();
    let img = random_image(&mut r, 16, 8);
    let m = MipMap::new(16, 8, img, true, 8.0, Wrap::Repeat).unwrap();
    let n = m.levels() as f64;
    for _ in 0..200 {
        let st = Vec2::new(r.uniform_f32() * 3.0 - 1.0, r.uniform_f32() * 3.0 - 1.0);
        let width = (r.uniform_f32() * 10.0 - 8.0).exp2();
        let level = n - 1.0 + (width as f64).log2();
        let e = if level < 0.0 {
            bilerp(&m, 0, st)
        } else if level >= n - 1.0 {
            m.texel(m.levels() - 1, 0, 0) as f64
        } else {
            let i = level.floor();
            let d = level - i;
            (1.0 - d) * bilerp(&m, i as usize, st) + d * bilerp(&m, i as usize + 1, st)
        };
        // The widest differential component is the width.
        let got = m.lookup(
            st,
            Vec2::new(width, -0.5 * width),
            Vec2::new(0.1 * width, 0.0),
        );
        assert!(
            close(got as f64, e, 1e-4),
            "st {st} width {width}: {got} vs {e}"
        );
    }
    // No differentials: a bilinear lookup of the finest level.
    let st = Vec2::new(0.3, 0.6);
    assert!(close(
        m.lookup(st, Vec2::ZERO, Vec2::ZERO) as f64,
        bilerp(&m, 0, st),
        1e-6
    ));
}

/// pbrt-v3's EWA on one level by brute force: every texel in a generous
/// window, weighted by the table at the ellipse's radius².
fn ewa_brute(m: &MipMap<f32>, level: usize, st: Vec2, d0: Vec2, d1: Vec2) -> f64 {
    if level >= m.levels() {
        return m.texel(m.levels() - 1, 0, 0) as f64;
    }
    let (w, h) = m.level_size(level);
    let (w, h) = (w as f64, h as f64);
    let (s, t) = (st.x as f64 * w - 0.5, st.y as f64 * h - 0.5);
    let d0 = [d0.x as f64 * w, d0.y as f64 * h];
    let d1 = [d1.x as f64 * w, d1.y as f64 * h];
    let a = d0[1] * d0[1] + d1[1] * d1[1] + 1.0;
    let b = -2.0 * (d0[0] * d0[1] + d1[0] * d1[1]);
    let c = d0[0] * d0[0] + d1[0] * d1[0] + 1.0;
    let f = a * c - b * b / 4.0;
    let (a, b, c) = (a / f, b / f, c / f);
    let table = |r2: f64| {
        let i = ((r2 * 128.0) as usize).min(127) as f64;
        (-2.0 * i / 127.0).exp() - (-2.0f64).exp()
    };
    let reach = 64i64;
    let (mut sum, mut sw) = (0.0, 0.0);
    for it in (t.floor() as i64 - reach)..=(t.floor() as i64 + reach) {
        for is in (s.floor() as i64 - reach)..=(s.floor() as i64 + reach) {
            let (x, y) = (is as f64 - s, it as f64 - t);
            let r2 = a * x * x + b * x * y + c * y * y;
            if r2 < 1.0 {
                let wt = table(r2);
                sum += wt * m.texel(level, is as i32, it as i32) as f64;
                sw += wt;
            }
        }
    }
    sum / sw
}

#[test]
fn ewa_lookups_match_brute_force_filtering() {
    let mut r = rng();
    let img = random_image(&mut r, 32, 16);
    for max_aniso in [8.0f32, 2.0] {
        let m = MipMap::new(32, 16, img.clone(), false, max_aniso, Wrap::Repeat).unwrap();
        let n = m.levels() as f64;
        for k in 0..150 {
            let st = Vec2::new(r.uniform_f32() * 2.0 - 0.5, r.uniform_f32() * 2.0 - 0.5);
            let scale = (r.uniform_f32() * 8.0 - 8.0).exp2();
            let mut d0 = Vec2::new(r.uniform_f32() - 0.5, r.uniform_f32() - 0.5) * scale;
            let mut d1 = Vec2::new(r.uniform_f32() - 0.5, r.uniform_f32() - 0.5) * scale * 0.3;
            if k % 3 == 0 {
                std::mem::swap(&mut d0, &mut d1);
            }
            // The reference's own axis ordering and eccentricity clamp.
            let (mut a, mut b) = (d0, d1);
            if a.length_squared() < b.length_squared() {
                std::mem::swap(&mut a, &mut b);
            }
            let (major, mut minor) = (a.length() as f64, b.length() as f64);
            if minor * (max_aniso as f64) < major && minor > 0.0 {
                let sc = major / (minor * max_aniso as f64);
                b *= sc as f32;
                minor *= sc;
            }
            let lod = (n - 1.0 + minor.log2()).max(0.0);
            let il = lod.floor();
            let e = (1.0 - (lod - il)) * ewa_brute(&m, il as usize, st, a, b)
                + (lod - il) * ewa_brute(&m, il as usize + 1, st, a, b);
            let got = m.lookup(st, d0, d1) as f64;
            assert!(
                close(got, e, 2e-4),
                "{k}: st {st} d0 {d0} d1 {d1}: {got} vs {e}"
            );
        }
    }
    // A constant image filters to the constant; a ramp in s, at a point
    // whose footprint lies inside it, to about its value there (the
    // filter is symmetric).
    let c = MipMap::new(8, 8, vec![Vec3::splat(0.25); 64], false, 8.0, Wrap::Clamp).unwrap();
    let v = c.lookup(
        Vec2::splat(0.4),
        Vec2::new(0.05, 0.01),
        Vec2::new(-0.01, 0.03),
    );
    assert!((v - Vec3::splat(0.25)).abs().max_element() < 1e-6);
    let ramp: Vec<f32> = (0..64 * 64).map(|i| (i % 64) as f32).collect();
    let m = MipMap::new(64, 64, ramp, false, 8.0, Wrap::Clamp).unwrap();
    let v = m.lookup(
        Vec2::new(0.5, 0.5),
        Vec2::new(0.02, 0.0),
        Vec2::new(0.0, 0.02),
    );
    assert!((v - 31.5).abs() < 0.05, "{v}");
}
