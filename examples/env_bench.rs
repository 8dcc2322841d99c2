//! Environment-map micro-benchmark: ns per `sample` (one at a time, and
//! three at once through `EnvMap::sample_each`, as bdpt takes them), `le`
//! and `pdf` of an infinite light's map (an image file, scaled by 3),
//! single-threaded, on uniformly random sample values and directions,
//! three rounds. With
//! `ALIAS` set in the environment the map is sampled by its alias tables
//! (`"string sampling" "alias"`) instead of pbrt-v3's CDF search.
//!
//! cargo run --release --example env_bench -- MAP [N]

use glam::{DMat4, Vec2, Vec3};
use pbrs::lights::infinite::{EnvMap, EnvSampling};
use pbrs::sampling::rng::Pcg32;
use std::path::Path;
use std::time::Instant;

fn main() {
    let mut args = std::env::args().skip(1);
    let path = args.next().expect("env_bench MAP [N]");
    let n: usize = args
        .next()
        .and_then(|s| s.parse().ok())
        .unwrap_or(2_000_000);
    let bytes = std::fs::read(&path).expect("read");
    let img = pbrs::loader::image::decode_image(&bytes, Path::new(&path)).expect("decode");
    let map = EnvMap::new(
        Some(&img),
        Vec3::splat(3.0),
        DMat4::IDENTITY,
        if std::env::var_os("ALIAS").is_some() {
            EnvSampling::Alias
        } else {
            EnvSampling::Map
        },
    );
    let mut rng = Pcg32::with_sequence(1);
    let us: Vec<Vec2> = (0..n)
        .map(|_| Vec2::new(rng.uniform_f32(), rng.uniform_f32()))
        .collect();
    let ds: Vec<Vec3> = us
        .iter()
        .map(|u| {
            let z = 2.0 * u.x - 1.0;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = std::f32::consts::TAU * u.y;
            Vec3::new(r * phi.cos(), r * phi.sin(), z)
        })
        .collect();
    for round in 0..3 {
        let t = Instant::now();
        let a: f32 = us
            .iter()
            .map(|&u| map.sample(u).map_or(0.0, |s| s.2 + s.1.x))
            .sum();
        let ts = t.elapsed().as_secs_f64() * 1e9 / n as f64;
        // Three at a time, as bdpt's strategies draw them ahead.
        let t = Instant::now();
        let mut e = 0.0f32;
        for c in us.chunks_exact(3) {
            let mut batch = [(&map, c[0], None), (&map, c[1], None), (&map, c[2], None)];
            EnvMap::sample_each(&mut batch);
            e += batch
                .iter()
                .map(|b| b.2.map_or(0.0, |s| s.2 + s.1.x))
                .sum::<f32>();
        }
        let te = t.elapsed().as_secs_f64() * 1e9 / n as f64;
        let t = Instant::now();
        let b: f32 = ds.iter().map(|&d| map.le(d).x).sum();
        let tl = t.elapsed().as_secs_f64() * 1e9 / n as f64;
        let t = Instant::now();
        let c: f32 = ds.iter().map(|&d| map.pdf(d)).sum();
        let tp = t.elapsed().as_secs_f64() * 1e9 / n as f64;
        println!("round {round}: sample {ts:.1} ns, three at once {te:.1} ns, le {tl:.1} ns, pdf {tp:.1} ns ({a} {e} {b} {c})");
    }
}
