//! Perlin-noise micro-benchmark: ns per call of pbrt-v3's `Noise` as the
//! textures call it (eight corners in SIMD lanes) and of the plain
//! corner-by-corner code it is tested against, on the same points,
//! single-threaded, three rounds.
//!
//! cargo run --release --example noise_bench

use pbrs::textures::noise::{noise, noise_plain};
use std::time::Instant;

fn main() {
    let n = 4_000_000;
    let points: Vec<[f32; 3]> = (0..n)
        .map(|i| {
            let f = i as f32 * 0.0137;
            [f * 1.3 + 0.1, (f * 0.7).sin() * 50.0, f * -0.37 + 3.3]
        })
        .collect();
    for round in 0..3 {
        let t = Instant::now();
        let a: f32 = points.iter().map(|p| noise_plain(p[0], p[1], p[2])).sum();
        let plain = t.elapsed().as_secs_f64() * 1e9 / n as f64;
        let t = Instant::now();
        let b: f32 = points.iter().map(|p| noise(p[0], p[1], p[2])).sum();
        let lanes = t.elapsed().as_secs_f64() * 1e9 / n as f64;
        assert_eq!(a.to_bits(), b.to_bits());
        println!("round {round}: plain {plain:.2} ns, lanes {lanes:.2} ns per call");
    }
}
