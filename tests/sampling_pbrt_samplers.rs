//! pbrt-v3's Sobol', (0,2)-sequence and max-min-distance samplers: the
//! same values as pbrt-v3 (test data printed by pbrt-v3's own code:
//! tests/inputs/pbrt_v3_sampler_values.txt), the (0,2)-sequence and
//! stratification properties checked directly, and located reports of bad
//! parameters.

use glam::{IVec2, Vec2};
use pbrs::geometry::Bounds2i;
use pbrs::samplers::sobolmatrices::{sobol_matrices, SOBOL_MATRIX_SIZE};
use pbrs::samplers::Sampler;
use pbrs::scene::{SamplerDesc, SamplerKind};

struct Case {
    name: String,
    spp: u32,
    dims: u32,
    bounds: Bounds2i,
    n1: u32,
    n2: u32,
    calls: String,
    /// (pixel, sample, value bits)
    lines: Vec<(IVec2, u32, Vec<u32>)>,
}

fn cases() -> Vec<Case> {
    let text = include_str!("inputs/pbrt_v3_sampler_values.txt");
    let mut out: Vec<Case> = Vec::new();
    for line in text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.is_empty())
    {
        let f: Vec<&str> = line.split_whitespace().collect();
        if f[0] == "case" {
            let n = |i: usize| f[i].parse::<i32>().unwrap();
            out.push(Case {
                name: f[1].to_string(),
                spp: n(2) as u32,
                dims: n(3) as u32,
                bounds: Bounds2i::new(IVec2::new(n(4), n(5)), IVec2::new(n(6), n(7))),
                n1: n(8) as u32,
                n2: n(9) as u32,
                calls: f[10].to_string(),
                lines: Vec::new(),
            });
        } else {
            let p = IVec2::new(f[0].parse().unwrap(), f[1].parse().unwrap());
            let s = f[2].parse().unwrap();
            let v = f[3..]
                .iter()
                .map(|h| u32::from_str_radix(h, 16).unwrap())
                .collect();
            out.last_mut().unwrap().lines.push((p, s, v));
        }
    }
    out
}

fn kind(c: &Case) -> SamplerKind {
    match c.name.as_str() {
        "sobol" => SamplerKind::Sobol,
        "02sequence" => SamplerKind::ZeroTwoSequence { dimensions: c.dims },
        "maxmindist" => SamplerKind::MaxMinDist { dimensions: c.dims },
        n => panic!("unknown sampler {n}"),
    }
}

fn sampler(c: &Case) -> Sampler {
    let desc = SamplerDesc {
        kind: kind(c),
        pixel_samples: c.spp,
        sample_pixel_center: false,
    };
    let mut s = Sampler::new(&desc, c.bounds, 0);
    if c.n1 > 0 {
        s.request_1d_array(c.n1);
    }
    if c.n2 > 0 {
        s.request_2d_array(c.n2);
    }
    s
}

fn values(s: &mut Sampler, c: &Case, pixel: IVec2, index: u32) -> Vec<u32> {
    s.start_pixel_sample(pixel, index);
    let mut v = Vec::new();
    for ch in c.calls.chars() {
        match ch {
            '1' => v.push(s.get_1d().to_bits()),
            '2' => {
                let p = s.get_2d();
                v.extend([p.x.to_bits(), p.y.to_bits()]);
            }
            'a' => v.extend(s.get_1d_array(c.n1).unwrap().iter().map(|x| x.to_bits())),
            'b' => {
                for p in s.get_2d_array(c.n2).unwrap() {
                    v.extend([p.x.to_bits(), p.y.to_bits()]);
                }
            }
            _ => panic!("call {ch}"),
        }
    }
    v
}

/// Every value pbrt-v3 printed, bit for bit: with the lines in order, in
/// reverse order (the pixel samplers replay their tile's RNG), and with a
/// fresh sampler for each line.
#[test]
fn values_equal_pbrt_v3s() {
    let cases = cases();
    assert_eq!(cases.len(), 11);
    let mut checked = 0;
    for c in &cases {
        let mut s = sampler(c);
        let forward = c.lines.iter();
        let backward = c.lines.iter().rev();
        for (pass, lines) in [
            Box::new(forward) as Box<dyn Iterator<Item = _>>,
            Box::new(backward),
        ]
        .into_iter()
        .enumerate()
        {
            for (p, i, want) in lines {
                let got = values(&mut s, c, *p, *i);
                assert_eq!(
                    &got, want,
                    "{} spp {} pixel {p} sample {i} (pass {pass})",
                    c.name, c.spp
                );
                checked += got.len();
            }
        }
        for (p, i, want) in c.lines.iter().step_by(7) {
            assert_eq!(&values(&mut sampler(c), c, *p, *i), want);
        }
    }
    assert!(checked > 10_000, "{checked} values");
}

/// The generator matrices made from Joe and Kuo's direction numbers are
/// upper triangular with a unit diagonal (every dimension a (0,1)-sequence),
/// and the first two are the van der Corput and Pascal matrices.
#[test]
fn sobol_matrices_structure() {
    let m = &sobol_matrices().m32;
    assert_eq!(m.len(), 1024 * SOBOL_MATRIX_SIZE);
    for d in 0..1024 {
        for j in 0..32 {
            let c = m[d * SOBOL_MATRIX_SIZE + j];
            // Rows 0..=j (bit 31 is row 0): row j set, none below.
            assert_eq!((c >> (31 - j)) & 1, 1, "dim {d} column {j}: diagonal");
            assert_eq!(c & ((1u64 << (31 - j)) - 1) as u32, 0, "dim {d} column {j}");
        }
    }
    for j in 0..32usize {
        assert_eq!(m[j], 1 << (31 - j));
        // Pascal: row r of column j is C(j, r) mod 2 = (r & j == r).
        let want = (0..32usize)
            .filter(|&r| r & j == r)
            .fold(0u32, |a, r| a | 1 << (31 - r));
        assert_eq!(m[SOBOL_MATRIX_SIZE + j], want, "column {j}");
    }
}

fn start(s: &mut Sampler, pixel: IVec2, i: u32) {
    s.start_pixel_sample(pixel, i);
}

/// A (0,m,2)-net in base 2: every elementary interval of area 2^-m (all
/// `2^a × 2^(m-a)` grids) holds exactly one point.
fn assert_02_net(points: &[Vec2], what: &str) {
    let n = points.len();
    let m = n.trailing_zeros();
    assert!(n.is_power_of_two());
    for a in 0..=m {
        let (nx, ny) = (1usize << a, 1usize << (m - a));
        let mut seen = vec![false; n];
        for p in points {
            let cell = (p.y * ny as f32) as usize * nx + (p.x * nx as f32) as usize;
            assert!(
                !seen[cell],
                "{what}: two points in cell {cell} of {nx}×{ny}"
            );
            seen[cell] = true;
        }
    }
}

/// The 2D dimensions and 2D arrays of `02sequence` are (0,2)-nets over a
/// pixel's samples (scrambling and shuffling keep the property); 1D
/// dimensions and arrays have one value in each interval of width 1/n.
#[test]
fn zero_two_sequence_nets_and_strata() {
    for spp in [1u32, 2, 4, 16, 64] {
        let desc = SamplerDesc {
            kind: SamplerKind::ZeroTwoSequence { dimensions: 3 },
            pixel_samples: spp,
            sample_pixel_center: false,
        };
        let mut s = Sampler::new(&desc, Bounds2i::new(IVec2::ZERO, IVec2::new(40, 24)), 0);
        s.request_1d_array(4);
        s.request_2d_array(8);
        for pixel in [IVec2::new(0, 0), IVec2::new(17, 3), IVec2::new(39, 23)] {
            let mut dims2 = vec![Vec::new(); 3];
            let mut dims1 = vec![Vec::new(); 3];
            let (mut arr1, mut arr2) = (Vec::new(), Vec::new());
            for i in 0..spp {
                start(&mut s, pixel, i);
                for d in 0..3 {
                    dims1[d].push(s.get_1d());
                    let p = s.get_2d();
                    // pixel offsets: within [0,1)
                    assert!(p.x >= 0.0 && p.x < 1.0 && p.y >= 0.0 && p.y < 1.0);
                    dims2[d].push(p);
                }
                let a = s.get_1d_array(4).unwrap().to_vec();
                assert_strata(&a, "one sample's 1D array");
                arr1.extend(a);
                let b = s.get_2d_array(8).unwrap().to_vec();
                assert_02_net(&b, "one sample's 2D array");
                arr2.extend(b);
            }
            for d in 0..3 {
                assert_02_net(&dims2[d], &format!("spp {spp} 2D dimension {d}"));
                assert_strata(&dims1[d], &format!("spp {spp} 1D dimension {d}"));
            }
            assert_02_net(&arr2, "a pixel's 2D array values");
            assert_strata(&arr1, "a pixel's 1D array values");
        }
    }
}

fn assert_strata(v: &[f32], what: &str) {
    let n = v.len();
    let mut seen = vec![false; n];
    for &x in v {
        let k = (x * n as f32) as usize;
        assert!(!seen[k], "{what}: two values in stratum {k} of {n}");
        seen[k] = true;
    }
}

/// maxmindist: the first 2D dimension has one sample in each column
/// `[i/n, (i+1)/n)` and, for the matrices of 4 or more samples, is a
/// (0,m,2)-net; the later dimensions are 02sequence's.
#[test]
fn max_min_dist_strata() {
    for spp in [4u32, 8, 16, 32, 64, 256] {
        let desc = SamplerDesc {
            kind: SamplerKind::MaxMinDist { dimensions: 2 },
            pixel_samples: spp,
            sample_pixel_center: false,
        };
        let mut s = Sampler::new(&desc, Bounds2i::new(IVec2::ZERO, IVec2::new(20, 20)), 0);
        let (mut first, mut second) = (Vec::new(), Vec::new());
        for i in 0..spp {
            start(&mut s, IVec2::new(5, 18), i);
            first.push(s.get_2d());
            second.push(s.get_2d());
        }
        let xs: Vec<f32> = first.iter().map(|p| p.x).collect();
        assert_strata(&xs, "maxmindist x");
        assert_02_net(&first, &format!("maxmindist spp {spp}"));
        assert_02_net(&second, "maxmindist second 2D dimension");
    }
}

/// Sobol': over the `spp` samples of a pixel, the pixel offsets form a
/// (0,2)-net (the sequence's first two dimensions restricted to an
/// elementary interval); over all samples of an image of `2^m × 2^m`
/// pixels (the first `4^m · spp` points of the sequence) every later
/// dimension is stratified into as many intervals.
#[test]
fn sobol_pixel_samples_are_stratified() {
    for spp in [1u32, 4, 16] {
        let desc = SamplerDesc {
            kind: SamplerKind::Sobol,
            pixel_samples: spp,
            sample_pixel_center: false,
        };
        let b = Bounds2i::new(IVec2::new(-3, 2), IVec2::new(13, 18));
        let mut s = Sampler::new(&desc, b, 0);
        let mut later = vec![Vec::new(); 10];
        for pixel in b.iter() {
            let mut film = Vec::new();
            for i in 0..spp {
                start(&mut s, pixel, i);
                film.push(s.get_2d());
                for d in later.iter_mut() {
                    d.push(s.get_1d());
                }
            }
            assert_02_net(&film, "sobol pixel offsets");
        }
        for (k, d) in later.iter().enumerate() {
            assert_strata(d, &format!("sobol spp {spp} dimension {}", k + 2));
        }
    }
}

/// Sample counts and array sizes: powers of two, rounded up.
#[test]
fn counts_round_to_powers_of_two() {
    for (kind, want) in [
        (SamplerKind::Sobol, 16),
        (SamplerKind::ZeroTwoSequence { dimensions: 4 }, 16),
        (SamplerKind::MaxMinDist { dimensions: 4 }, 16),
    ] {
        let desc = SamplerDesc {
            kind,
            pixel_samples: 10,
            sample_pixel_center: false,
        };
        let s = Sampler::new(&desc, Bounds2i::new(IVec2::ZERO, IVec2::new(4, 4)), 0);
        assert_eq!(s.samples_per_pixel(), want, "{kind:?}");
    }
    let desc = SamplerDesc {
        kind: SamplerKind::ZeroTwoSequence { dimensions: 4 },
        pixel_samples: 4,
        sample_pixel_center: false,
    };
    let s = Sampler::new(&desc, Bounds2i::new(IVec2::ZERO, IVec2::new(4, 4)), 0);
    assert_eq!(s.round_count(5), 8);
    assert_eq!(s.round_count(8), 8);
}

/// Bad parameters: located errors or warnings with pbrt-v3's wording, no
/// panic; the scene still loads (with the default) where pbrt-v3 renders.
#[test]
fn bad_parameters_are_located() {
    let load = |sampler: &str| {
        let text = format!(
            "Film \"image\" \"integer xresolution\" 4 \"integer yresolution\" 4\n{sampler}\nWorldBegin\nWorldEnd\n"
        );
        pbrs::loader::load_scene_str(&text, std::path::Path::new("bad.pbrt"))
    };
    let warned = |sampler: &str, needle: &str| {
        let l = load(sampler).unwrap_or_else(|f| panic!("{sampler}: {f:?}"));
        let all = l
            .warnings
            .iter()
            .map(|w| w.to_string())
            .collect::<Vec<_>>()
            .join("\n");
        assert!(all.contains(needle), "{sampler}: {all}");
        assert!(all.contains("bad.pbrt:2"), "{sampler}: not located: {all}");
        l.scene.sampler
    };
    let d = warned(
        "Sampler \"sobol\" \"integer pixelsamples\" 10",
        "Non power-of-two sample count rounded up to 16 for SobolSampler.",
    );
    assert_eq!(d.pixel_samples, 16);
    let d = warned(
        "Sampler \"lowdiscrepancy\" \"integer pixelsamples\" 5",
        "Pixel samples being rounded up to power of 2 (from 5 to 8).",
    );
    assert_eq!(d.pixel_samples, 8);
    let d = warned(
        "Sampler \"maxmindist\" \"integer pixelsamples\" 3",
        "Non power-of-two sample count rounded up to 4 for MaxMinDistSampler.",
    );
    assert_eq!(d.pixel_samples, 4);
    let d = warned(
        "Sampler \"maxmindist\" \"integer pixelsamples\" 100000",
        "No more than 65536 samples per pixel are supported with MaxMinDistSampler.",
    );
    assert_eq!(d.pixel_samples, 65536);
    for bad in [
        "Sampler \"sobol\" \"integer pixelsamples\" 0",
        "Sampler \"sobol\" \"integer pixelsamples\" -3",
        "Sampler \"02sequence\" \"integer pixelsamples\" 999999999",
        "Sampler \"02sequence\" \"integer dimensions\" -1",
        "Sampler \"02sequence\" \"integer dimensions\" 100000",
        "Sampler \"maxmindist\" \"integer dimensions\" 0",
        "Sampler \"02sequence\" \"integer pixelsamples\" 1048576 \"integer dimensions\" 1000",
        "Sampler \"maxmindist\" \"float pixelsamples\" 4",
    ] {
        let r = std::panic::catch_unwind(|| load(bad));
        let r = r.unwrap_or_else(|_| panic!("{bad}: panicked"));
        let msg = match r {
            Ok(l) => l
                .warnings
                .iter()
                .map(|w| w.to_string())
                .collect::<Vec<_>>()
                .join("\n"),
            Err(f) => format!("{f:?}"),
        };
        assert!(msg.contains("bad.pbrt:2"), "{bad}: not located: {msg}");
    }
}
