//! Samplers: range, statelessness, Halton's pixel dimensions and
//! equidistribution, thousands of dimensions, and the array API.

use glam::{IVec2, Vec2};
use pbrs::geometry::Bounds2i;
use pbrs::samplers::{CameraSample, Sampler};
use pbrs::sampling::chi2::chi2_survival;
use pbrs::scene::{SamplerDesc, SamplerKind};

fn desc(kind: SamplerKind, spp: u32) -> SamplerDesc {
    SamplerDesc {
        kind,
        pixel_samples: spp,
        sample_pixel_center: false,
    }
}

fn bounds(w: i32, h: i32) -> Bounds2i {
    Bounds2i::new(IVec2::ZERO, IVec2::new(w, h))
}

const KINDS: [SamplerKind; 6] = [
    SamplerKind::Halton,
    SamplerKind::Random,
    SamplerKind::Stratified {
        jitter: true,
        xsamples: 4,
        ysamples: 4,
    },
    SamplerKind::Sobol,
    SamplerKind::ZeroTwoSequence { dimensions: 4 },
    SamplerKind::MaxMinDist { dimensions: 4 },
];

fn assert_send_clone<T: Send + Clone + 'static>() {}

#[test]
fn sampler_is_send_and_clone() {
    assert_send_clone::<Sampler>();
    assert!(matches!(
        Sampler::new(&desc(SamplerKind::Sobol, 4), bounds(8, 8), 0),
        Sampler::Sobol(_)
    ));
    assert!(matches!(
        Sampler::new(
            &desc(SamplerKind::MaxMinDist { dimensions: 4 }, 4),
            bounds(8, 8),
            0
        ),
        Sampler::MaxMinDist(_)
    ));
}

fn read_values(s: &mut Sampler, pixel: IVec2, index: u32, n: usize) -> Vec<f32> {
    s.start_pixel_sample(pixel, index);
    let cs = s.get_camera_sample(pixel);
    let mut v = vec![
        cs.p_film.x - pixel.x as f32,
        cs.p_film.y - pixel.y as f32,
        cs.time,
        cs.p_lens.x,
        cs.p_lens.y,
    ];
    for k in 0..n {
        if k % 3 == 0 {
            let p = s.get_2d();
            v.extend([p.x, p.y]);
        } else {
            v.push(s.get_1d());
        }
    }
    v
}

#[test]
fn values_in_unit_interval() {
    for kind in KINDS {
        for seed in [0, 17] {
            let mut s = Sampler::new(
                &desc(kind, 16),
                Bounds2i::new(IVec2::new(-2, -2), IVec2::new(37, 21)),
                seed,
            );
            for y in -2..21 {
                for x in (-2..37).step_by(5) {
                    for i in 0..16 {
                        for v in read_values(&mut s, IVec2::new(x, y), i, 40) {
                            assert!((0.0..1.0).contains(&v), "{kind:?}: {v}");
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn stateless_positioning() {
    for kind in KINDS {
        let mut a = Sampler::new(&desc(kind, 16), bounds(64, 64), 3);
        let mut b = a.clone();
        let reference = read_values(&mut a, IVec2::new(5, 9), 7, 60);
        // Different history: other pixels and samples, partial reads.
        for i in 0..16 {
            read_values(&mut b, IVec2::new(40, 2), i, 3 + i as usize);
        }
        read_values(&mut b, IVec2::new(5, 9), 6, 100);
        assert_eq!(
            read_values(&mut b, IVec2::new(5, 9), 7, 60),
            reference,
            "{kind:?}"
        );
        // And again on a fresh clone used elsewhere first.
        let mut c = a.clone();
        read_values(&mut c, IVec2::new(63, 63), 15, 10);
        assert_eq!(
            read_values(&mut c, IVec2::new(5, 9), 7, 60),
            reference,
            "{kind:?}"
        );
        // A different index or pixel gives different values.
        assert_ne!(read_values(&mut c, IVec2::new(5, 9), 8, 60), reference);
        assert_ne!(read_values(&mut c, IVec2::new(6, 9), 7, 60), reference);
    }
}

fn film_offsets(s: &mut Sampler, pixel: IVec2, spp: u32) -> Vec<Vec2> {
    (0..spp)
        .map(|i| {
            s.start_pixel_sample(pixel, i);
            let CameraSample { p_film, .. } = s.get_camera_sample(pixel);
            assert!(
                p_film.floor().as_ivec2() == pixel,
                "{p_film} outside {pixel}"
            );
            // The offset itself (p_film - pixel loses bits to rounding).
            s.start_pixel_sample(pixel, i);
            s.get_2d()
        })
        .collect()
}

#[test]
fn halton_pixel_dimensions_are_stratified() {
    for (w, h) in [(128, 128), (37, 21), (300, 200)] {
        for seed in [0, 5] {
            let mut s = Sampler::new(&desc(SamplerKind::Halton, 36), bounds(w, h), seed);
            for pixel in [
                IVec2::new(0, 0),
                IVec2::new(w - 1, h - 1),
                IVec2::new(w / 2, h / 3),
                IVec2::new(-1, -2),
            ] {
                let offs = film_offsets(&mut s, pixel, 36);
                // 36 = 4 × 9: one sample per cell of a 4×9 grid, per 1/4 in x, per 1/9 in y.
                let mut cells = [0u32; 36];
                for o in &offs {
                    cells[(o.x * 4.0) as usize * 9 + (o.y * 9.0) as usize] += 1;
                }
                assert!(cells.iter().all(|&c| c == 1), "{w}x{h} {pixel}: {cells:?}");
                // 16 samples: one per 1/16 in x.
                let offs = film_offsets(&mut s, pixel, 16);
                let mut xs = [0u32; 16];
                for o in &offs {
                    xs[(o.x * 16.0) as usize] += 1;
                }
                assert!(xs.iter().all(|&c| c == 1), "{xs:?}");
            }
        }
    }
}

#[test]
fn halton_sample_pixel_center() {
    let d = SamplerDesc {
        kind: SamplerKind::Halton,
        pixel_samples: 8,
        sample_pixel_center: true,
    };
    let mut s = Sampler::new(&d, bounds(16, 16), 0);
    for i in 0..8 {
        s.start_pixel_sample(IVec2::new(3, 4), i);
        assert_eq!(
            s.get_camera_sample(IVec2::new(3, 4)).p_film,
            Vec2::new(3.5, 4.5)
        );
    }
}

#[test]
fn halton_seed_changes_scrambling_not_pixel_dims() {
    let mut a = Sampler::new(&desc(SamplerKind::Halton, 4), bounds(32, 32), 0);
    let mut b = Sampler::new(&desc(SamplerKind::Halton, 4), bounds(32, 32), 1);
    let va = read_values(&mut a, IVec2::new(3, 3), 2, 10);
    let vb = read_values(&mut b, IVec2::new(3, 3), 2, 10);
    assert_eq!(va[..2], vb[..2]);
    assert_ne!(va[2..], vb[2..]);
}

/// Chi-square p-value of counts against a uniform expectation.
fn uniform_p(counts: &[u32]) -> f64 {
    let n: u32 = counts.iter().sum();
    let e = n as f64 / counts.len() as f64;
    let stat: f64 = counts.iter().map(|&c| (c as f64 - e).powi(2) / e).sum();
    chi2_survival(stat, (counts.len() - 1) as f64)
}

/// All samples of all pixels of a `w × h` image at `spp`: dimension `dim`
/// (and `dim + 1`), after skipping `dim` values with get_1d.
fn collect_dims(kind: SamplerKind, w: i32, h: i32, spp: u32, dim: usize) -> Vec<Vec2> {
    let mut s = Sampler::new(&desc(kind, spp), bounds(w, h), 0);
    let mut out = Vec::new();
    for p in bounds(w, h).iter() {
        for i in 0..spp {
            s.start_pixel_sample(p, i);
            for _ in 0..dim {
                s.get_1d();
            }
            let x = s.get_1d();
            let y = s.get_1d();
            out.push(Vec2::new(x, y));
        }
    }
    out
}

#[test]
fn middle_dimension_equidistribution() {
    for kind in KINDS {
        let pts = collect_dims(kind, 32, 32, 16, 9);
        let mut h1 = [0u32; 64];
        let mut h2 = [0u32; 256];
        let mut mean = 0.0f64;
        for p in &pts {
            h1[(p.x * 64.0) as usize] += 1;
            h2[(p.x * 16.0) as usize * 16 + (p.y * 16.0) as usize] += 1;
            mean += p.x as f64;
        }
        mean /= pts.len() as f64;
        let (p1, p2) = (uniform_p(&h1), uniform_p(&h2));
        println!("{kind:?}: mean {mean:.5}, 1D p = {p1:.3e}, 2D p = {p2:.3e}");
        assert!((mean - 0.5).abs() < 0.01, "{kind:?}: mean {mean}");
        assert!(p1 > 1e-4 && p2 > 1e-4, "{kind:?}: 1D p = {p1}, 2D p = {p2}");
        if matches!(kind, SamplerKind::Halton) {
            // Low discrepancy: far more even than random.
            let n = pts.len() as f64 / 64.0;
            assert!(
                h1.iter().all(|&c| (c as f64 - n).abs() < 0.05 * n),
                "{h1:?}"
            );
        }
    }
}

#[test]
fn five_thousand_dimensions() {
    for kind in KINDS {
        let mut s = Sampler::new(&desc(kind, 8), bounds(16, 16), 1);
        let dims = 5000;
        let mut sums = vec![0.0f64; dims];
        let mut n = 0;
        for p in bounds(16, 16).iter() {
            for i in 0..8 {
                s.start_pixel_sample(p, i);
                for sum in sums.iter_mut() {
                    let v = s.get_1d();
                    assert!((0.0..1.0).contains(&v));
                    *sum += v as f64;
                }
                n += 1;
            }
        }
        // Means per dimension past the prime table, and overall.
        let high: f64 = sums[1000..].iter().sum::<f64>() / (4000.0 * n as f64);
        assert!((high - 0.5).abs() < 0.005, "{kind:?}: {high}");
        for (d, s) in sums.iter().enumerate().skip(1000).step_by(97) {
            let m = s / n as f64;
            assert!((m - 0.5).abs() < 0.06, "{kind:?} dim {d}: mean {m}");
        }
    }
}

#[test]
fn array_api() {
    for kind in KINDS {
        let mut s = Sampler::new(&desc(kind, 16), bounds(16, 16), 0);
        // The pixel samplers take arrays of powers of two (pbrt-v3's RoundCount).
        let pow2 = matches!(
            kind,
            SamplerKind::ZeroTwoSequence { .. } | SamplerKind::MaxMinDist { .. }
        );
        assert_eq!(s.round_count(7), if pow2 { 8 } else { 7 });
        let (n3, n5) = (s.round_count(3), s.round_count(5));
        s.request_1d_array(n3);
        s.request_2d_array(n5);
        s.request_2d_array(2);
        let mut firsts = Vec::new();
        for i in 0..16 {
            s.start_pixel_sample(IVec2::new(2, 3), i);
            let _ = s.get_camera_sample(IVec2::new(2, 3));
            let a = s.get_1d_array(n3).expect("1D array").to_vec();
            assert_eq!(a.len(), n3 as usize);
            assert!(a.iter().all(|v| (0.0..1.0).contains(v)));
            let b = s.get_2d_array(n5).expect("2D array").to_vec();
            assert_eq!(b.len(), n5 as usize);
            assert!(b
                .iter()
                .all(|v| (0.0..1.0).contains(&v.x) && (0.0..1.0).contains(&v.y)));
            assert_eq!(s.get_2d_array(2).map(|c| c.len()), Some(2));
            assert!(s.get_2d_array(2).is_none());
            assert!(s.get_1d_array(n3).is_none());
            let v = s.get_1d();
            assert!((0.0..1.0).contains(&v));
            firsts.push(a[0]);
            // Same sample again: same arrays.
            s.start_pixel_sample(IVec2::new(2, 3), i);
            assert_eq!(s.get_1d_array(n3).unwrap(), &a[..]);
        }
        // Array values of a pixel's samples cover [0,1).
        let lo = firsts.iter().filter(|&&v| v < 0.5).count();
        assert!((3..=13).contains(&lo), "{kind:?}: {firsts:?}");
    }
}

/// `get_2d_arrays1` (Halton's one-block fetch of several one-entry 2D
/// arrays) gives what as many `get_2d_array1` calls give, wherever the
/// arrays' dimensions fall (inside one block, across the end of the block
/// dimensions, past the last prime), and consumes nothing when an array is
/// missing or has more entries.
#[test]
fn fused_one_entry_arrays_match_one_by_one() {
    // (1D arrays requested first, 2D arrays of one entry, then a larger one)
    for (n1d, n2d) in [(0, 8), (0, 20), (3, 20), (11, 40), (0, 900)] {
        let make = || {
            let mut s = Sampler::new(&desc(SamplerKind::Halton, 64), bounds(512, 512), 0);
            for _ in 0..n1d {
                s.request_1d_array(1);
            }
            for _ in 0..n2d {
                s.request_2d_array(1);
            }
            s.request_2d_array(3);
            s
        };
        let (mut a, mut b) = (make(), make());
        for (pixel, i) in [(IVec2::new(7, 300), 0), (IVec2::new(511, 511), 63)] {
            a.start_pixel_sample(pixel, i);
            b.start_pixel_sample(pixel, i);
            for _ in 0..n1d {
                assert_eq!(
                    a.get_1d_array(1).map(|v| v[0]),
                    b.get_1d_array(1).map(|v| v[0])
                );
            }
            let mut left = n2d;
            for k in [1usize, 2, 4, 3, 4, 2, 1].into_iter().cycle() {
                if left == 0 {
                    break;
                }
                let k = k.min(left);
                let mut fused = [Vec2::ZERO; 4];
                assert!(a.get_2d_arrays1(&mut fused[..k]), "{n1d} {n2d} {k}");
                for v in &fused[..k] {
                    assert_eq!(Some(*v), b.get_2d_array1(), "{n1d} {n2d} {k}");
                }
                left -= k;
            }
            // The next array has three entries: nothing fused, nothing consumed.
            let mut one = [Vec2::ZERO; 1];
            assert!(!a.get_2d_arrays1(&mut one));
            assert_eq!(a.get_2d_array(3), b.get_2d_array(3));
            assert!(!a.get_2d_arrays1(&mut one));
            assert_eq!(a.get_2d(), b.get_2d());
        }
    }
    // The other samplers always take arrays one by one.
    let mut r = Sampler::new(&desc(SamplerKind::Random, 4), bounds(8, 8), 0);
    r.request_2d_array(1);
    r.start_pixel_sample(IVec2::ZERO, 0);
    assert!(!r.get_2d_arrays1(&mut [Vec2::ZERO; 1]));
    assert!(r.get_2d_array1().is_some());
}

#[test]
fn halton_skips_array_dimensions() {
    let mut s = Sampler::new(&desc(SamplerKind::Halton, 4), bounds(16, 16), 0);
    s.request_1d_array(2);
    s.request_2d_array(2);
    let mut t = Sampler::new(&desc(SamplerKind::Halton, 4), bounds(16, 16), 0);
    s.start_pixel_sample(IVec2::new(1, 1), 1);
    t.start_pixel_sample(IVec2::new(1, 1), 1);
    let _ = s.get_camera_sample(IVec2::new(1, 1)); // dims 0..5
    let _ = t.get_camera_sample(IVec2::new(1, 1));
    // s skips dims 5..8 (arrays); t reads 5, 6, 7 first.
    let (_, _, _) = (t.get_1d(), t.get_1d(), t.get_1d());
    assert_eq!(s.get_1d(), t.get_1d());
    let Sampler::Halton(h) = &s else {
        unreachable!()
    };
    assert_eq!(h.dimension(), 9);
}

/// Throughput of the per-sample path (run with `--ignored --nocapture`).
#[test]
#[ignore]
fn bench_samplers() {
    for kind in KINDS {
        let mut s = Sampler::new(&desc(kind, 64), bounds(512, 512), 0);
        let t = std::time::Instant::now();
        let mut acc = 0.0f32;
        let mut n = 0u64;
        for p in bounds(512, 512).iter().take(20_000) {
            for i in 0..64 {
                s.start_pixel_sample(p, i);
                let cs = s.get_camera_sample(p);
                acc += cs.p_film.x + cs.time;
                for _ in 0..10 {
                    acc += s.get_1d();
                    acc += s.get_2d().x;
                }
                n += 1;
            }
        }
        let dt = t.elapsed().as_secs_f64();
        println!(
            "{kind:?}: {:.1} ns per sample (25 dims), checksum {acc}",
            dt * 1e9 / n as f64
        );
    }
}

/// Every kind of `samplers::SAMPLERS`, loaded from a statement:
/// its settings, and its sampler's values in [0, 1) and the same for the
/// same pixel and index. Unsupported kinds render with halton and say so.
/// A kind of the table without a case here fails.
#[test]
fn every_sampler_kind_loads_and_samples() {
    use pbrs::loader::load_scene_str;
    use pbrs::samplers::SAMPLERS;
    use std::path::Path;
    let cases: &[(&str, &str, SamplerDesc)] = &[
        (
            "halton",
            "\"integer pixelsamples\" 8 \"bool samplepixelcenter\" \"true\"",
            SamplerDesc {
                kind: SamplerKind::Halton,
                pixel_samples: 8,
                sample_pixel_center: true,
            },
        ),
        ("random", "", desc(SamplerKind::Random, 4)),
        (
            "stratified",
            "\"integer xsamples\" 3 \"integer ysamples\" 2 \"bool jitter\" \"false\"",
            desc(
                SamplerKind::Stratified {
                    jitter: false,
                    xsamples: 3,
                    ysamples: 2,
                },
                6,
            ),
        ),
        (
            "sobol",
            "\"integer pixelsamples\" 32",
            desc(SamplerKind::Sobol, 32),
        ),
        (
            "02sequence",
            "",
            desc(SamplerKind::ZeroTwoSequence { dimensions: 4 }, 16),
        ),
        (
            "lowdiscrepancy",
            "\"integer dimensions\" 2",
            desc(SamplerKind::ZeroTwoSequence { dimensions: 2 }, 16),
        ),
        (
            "maxmindist",
            "\"integer pixelsamples\" 4",
            desc(SamplerKind::MaxMinDist { dimensions: 4 }, 4),
        ),
    ];
    for k in SAMPLERS {
        for name in std::iter::once(k.name).chain(k.aliases.iter().copied()) {
            assert!(
                cases.iter().any(|c| c.0 == name),
                "sampler \"{name}\" has no test case"
            );
        }
    }
    for (name, params, want) in cases {
        let text = format!("Sampler \"{name}\" {params}\nWorldBegin\nWorldEnd\n");
        let loaded = load_scene_str(&text, Path::new("s.pbrt")).unwrap();
        assert_eq!(loaded.scene.sampler, *want, "{text}");
        let substituted = loaded
            .warnings
            .iter()
            .any(|w| w.to_string().contains("rendered with the halton sampler"));
        let kind = pbrs::scene::kind::find(SAMPLERS, name).unwrap();
        assert_eq!(
            substituted,
            !kind.is_supported(),
            "{name}: {:?}",
            loaded.warnings
        );
        assert!(loaded.warnings.len() <= 1, "{name}: {:?}", loaded.warnings);
        let mut s = Sampler::new(want, bounds(8, 8), 0);
        let a = read_values(&mut s, IVec2::new(3, 5), 1, 40);
        let b = read_values(&mut s, IVec2::new(3, 5), 1, 40);
        assert_eq!(a, b, "{name}");
        assert!(a.iter().all(|v| (0.0..1.0).contains(v)), "{name}: {a:?}");
    }
}

#[test]
fn bad_sampler_counts_are_located_errors() {
    use pbrs::loader::load_scene_str;
    use std::path::Path;
    for (statement, what) in [
        (
            "Sampler \"halton\" \"integer pixelsamples\" 0",
            "sample count \"pixelsamples\" is 0",
        ),
        (
            "Sampler \"random\" \"integer pixelsamples\" 99999999",
            "it must be between 1 and 16777216",
        ),
        (
            "Sampler \"stratified\" \"integer xsamples\" 8192 \"integer ysamples\" 8192",
            "xsamples × ysamples = 67108864 exceeds 16777216",
        ),
        ("Sampler \"haltom\"", "did you mean \"halton\"?"),
    ] {
        let text = format!("{statement}\nWorldBegin\nWorldEnd\n");
        let Err(err) = load_scene_str(&text, Path::new("bad.pbrt")) else {
            panic!("{statement}: loaded");
        };
        let msg = format!("{err:?}");
        assert!(msg.contains(what), "{statement}: {msg}");
        assert!(
            msg.contains("bad.pbrt:1:"),
            "{statement}: not located: {msg}"
        );
    }
}
