//! Ray-traversal micro-benchmark: closest-hit and occlusion queries on a
//! scene's geometry, with rays like a path tracer's (origins on surfaces,
//! random directions; shadow rays towards random points near the ceiling).
//!
//! cargo run --release --example trace_bench -- [SCENE] [N]
//!
//! Prints ns per closest-hit ray (one at a time, and 16 side by side), ns
//! per shadow ray (one at a time, and 16 side by side) and per surface
//! lookup, single-threaded. Compare two builds by running both in turn.

use glam::Vec3;
use pbrs::accel::{Aggregate, Hit};
use pbrs::geometry::{spawn_ray, spawn_ray_to_point, Ray};
use pbrs::integrators::RenderScene;
use pbrs::loader::load_scene;
use pbrs::sampling::rng::Pcg32;
use std::path::Path;
use std::time::Instant;

/// Rays traced side by side (`Aggregate::intersect_stream`), as a batch of
/// `path` traces its bounces.
const SIDE_BY_SIDE: usize = 16;

fn main() {
    let mut args = std::env::args().skip(1);
    let scene = args
        .next()
        .unwrap_or_else(|| "scenes/cornell-path.pbrt".into());
    let n: usize = args
        .next()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1_000_000);
    let loaded = match load_scene(Path::new(&scene)) {
        Ok(l) => l,
        Err(_) => {
            eprintln!("trace_bench: cannot load {scene}");
            std::process::exit(1);
        }
    };
    let rs = RenderScene::new(&loaded.scene);
    let g = &rs.aggregate;
    let b = g.bounds;
    let mut rng = Pcg32::with_sequence(1);
    let mut rnd = || rng.uniform_f32();
    let dir = |rnd: &mut dyn FnMut() -> f32| {
        let z = 2.0 * rnd() - 1.0;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = std::f32::consts::TAU * rnd();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    };
    // Surface points: hits of rays from the scene's centre.
    let centre = b.min.lerp(b.max, 0.5);
    let mut points = Vec::new();
    while points.len() < 4096 {
        if let Some(h) = g.intersect(&Ray::new(centre, dir(&mut rnd))) {
            points.push(g.surface(&h).point);
        }
    }
    let rays: Vec<Ray> = (0..n)
        .map(|i| {
            let s = points[i % points.len()];
            let mut d = dir(&mut rnd);
            if d.dot(s.n) < 0.0 {
                d = -d;
            }
            spawn_ray(s.p, s.p_error, s.n, d)
        })
        .collect();
    let top = Vec3::new(centre.x, b.max.y - 0.01 * (b.max.y - b.min.y), centre.z);
    let shadow: Vec<Ray> = (0..n)
        .map(|i| {
            let s = points[i % points.len()];
            let q = top + (Vec3::new(rnd(), 0.0, rnd()) - 0.5) * 0.25 * (b.max - b.min);
            spawn_ray_to_point(s.p, s.p_error, s.n, q)
        })
        .collect();
    let rounds = if std::env::var_os("TRACE_BENCH_ONCE").is_some() {
        1
    } else {
        3
    };
    for round in 0..rounds {
        let t = Instant::now();
        let hits = closest_all(g, &rays);
        let closest = t.elapsed().as_secs_f64() * 1e9 / n as f64;
        let t = Instant::now();
        let n_stream = closest_stream(g, &rays);
        let stream = t.elapsed().as_secs_f64() * 1e9 / n as f64;
        assert_eq!(n_stream, hits.len());
        let t = Instant::now();
        let blocked = shadow_all(g, &shadow);
        let occl = t.elapsed().as_secs_f64() * 1e9 / n as f64;
        let t = Instant::now();
        let blocked_stream = shadow_stream(g, &shadow);
        let occl_stream = t.elapsed().as_secs_f64() * 1e9 / n as f64;
        assert_eq!(blocked_stream, blocked);
        let t = Instant::now();
        let acc = surface_all(g, &hits);
        let surf = t.elapsed().as_secs_f64() * 1e9 / hits.len().max(1) as f64;
        println!(
            "round {round}: closest {closest:.1} ns/ray ({} hits), {SIDE_BY_SIDE} side by side {stream:.1} ns/ray, shadow {occl:.1} ns/ray ({blocked} blocked), {SIDE_BY_SIDE} side by side {occl_stream:.1} ns/ray, surface {surf:.1} ns ({acc:.0})",
            hits.len()
        );
    }
}

// Separate, never-inlined loops so that profilers (callgrind, perf) can
// attribute each query's cost.

#[inline(never)]
fn closest_all(g: &Aggregate, rays: &[Ray]) -> Vec<Hit> {
    let mut hits = Vec::with_capacity(rays.len());
    for r in rays {
        if let Some(h) = g.intersect(r) {
            hits.push(h);
        }
    }
    hits
}

#[inline(never)]
fn closest_stream(g: &Aggregate, rays: &[Ray]) -> usize {
    let times = [0.0f32; SIDE_BY_SIDE];
    let mut out = [None; SIDE_BY_SIDE];
    let mut hits = 0;
    for c in rays.chunks(SIDE_BY_SIDE) {
        g.intersect_stream(c, &times[..c.len()], &mut out[..c.len()]);
        hits += out[..c.len()].iter().filter(|h| h.is_some()).count();
    }
    hits
}

#[inline(never)]
fn shadow_all(g: &Aggregate, rays: &[Ray]) -> usize {
    rays.iter().filter(|r| g.occluded(r)).count()
}

#[inline(never)]
fn shadow_stream(g: &Aggregate, rays: &[Ray]) -> usize {
    let times = [0.0f32; SIDE_BY_SIDE];
    let mut out = [false; SIDE_BY_SIDE];
    let mut blocked = 0;
    for c in rays.chunks(SIDE_BY_SIDE) {
        g.occluded_stream(c, &times[..c.len()], &mut out[..c.len()]);
        blocked += out[..c.len()].iter().filter(|&&b| b).count();
    }
    blocked
}

#[inline(never)]
fn surface_all(g: &Aggregate, hits: &[Hit]) -> f32 {
    hits.iter().map(|h| g.surface(h).point.p.x).sum()
}
