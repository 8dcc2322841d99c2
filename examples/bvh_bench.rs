//! BVH benchmark: build time and peak memory for a generated 1M-triangle mesh
//! (a bumpy 708×708 grid), and for 1,000 instances of a 100k-triangle object
//! (two-level BVH), with closest-hit throughput on random rays.
//!
//! cargo run --release --example bvh_bench [-- flat|instanced]
//!
//! Without an argument each case runs in its own process, so that the peak
//! memory (VmHWM) is per case.

use glam::{DMat4, DVec3, Vec3};
use pbrs::accel::{Aggregate, Instance, Object};
use pbrs::geometry::Ray;
use pbrs::render::driver::peak_memory_bytes;
use pbrs::shapes::TriangleMesh;
use std::process::Command;
use std::sync::Arc;
use std::time::Instant;

/// A bumpy n×n-vertex grid over [-1,1]², 2(n-1)² triangles.
fn grid(n: u32) -> TriangleMesh {
    let mut p = Vec::with_capacity((n * n) as usize);
    for j in 0..n {
        for i in 0..n {
            let u = i as f32 / (n - 1) as f32 * 2.0 - 1.0;
            let v = j as f32 / (n - 1) as f32 * 2.0 - 1.0;
            let h = 0.05 * ((u * 37.0).sin() * (v * 29.0).cos()) + 0.02 * ((u + v) * 91.0).sin();
            p.push(Vec3::new(u, h, v));
        }
    }
    let mut indices = Vec::with_capacity(6 * ((n - 1) * (n - 1)) as usize);
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let a = j * n + i;
            indices.extend_from_slice(&[a, a + 1, a + n + 1, a, a + n + 1, a + n]);
        }
    }
    TriangleMesh::plain(p, indices)
}

/// Random rays from a sphere of radius 4 towards points near the origin.
fn trace(g: &Aggregate, n: usize) -> (f64, usize) {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut rnd = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    let rays: Vec<Ray> = (0..n)
        .map(|_| {
            let o = Vec3::new(rnd() - 0.5, rnd() * 0.5 + 0.2, rnd() - 0.5).normalize() * 4.0;
            let t = Vec3::new(rnd() * 2.0 - 1.0, 0.0, rnd() * 2.0 - 1.0);
            Ray::new(o, (t - o).normalize())
        })
        .collect();
    let start = Instant::now();
    let hits = rays.iter().filter(|r| g.intersect(r).is_some()).count();
    (n as f64 / start.elapsed().as_secs_f64() / 1e6, hits)
}

/// Resident memory now (VmRSS), Linux only.
fn resident_bytes() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmRSS:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

fn mib(b: Option<u64>) -> String {
    b.map(|b| format!("{:.1} MiB", b as f64 / (1 << 20) as f64))
        .unwrap_or_else(|| "n/a".into())
}

fn flat() {
    let mesh = grid(708);
    let tris = mesh.triangle_count();
    let before = peak_memory_bytes();
    let start = Instant::now();
    let g = Aggregate::new(vec![mesh], Vec::new());
    let build = start.elapsed();
    let resident = resident_bytes();
    let (mrays, hits) = trace(&g, 1_000_000);
    println!(
        "flat: {tris} triangles, BVH build {:.0} ms, peak memory {} (mesh alone {}; resident after the build {}), {mrays:.2} Mrays/s single-threaded ({hits} hits of 1M)",
        build.as_secs_f64() * 1e3,
        mib(peak_memory_bytes()),
        mib(before),
        mib(resident),
    );
}

fn instanced() {
    // 224×224 vertices: 99,458 triangles per object, over [-1,1]² scaled to
    // 0.03, on a 40×25 grid of instances (1,000) with varied rotations.
    let mesh = grid(224);
    let tris = mesh.triangle_count() as u64;
    let start = Instant::now();
    let object = Arc::new(Object::new(vec![mesh], Vec::new()));
    let object_build = start.elapsed();
    let mut instances = Vec::new();
    for k in 0..1000 {
        let (i, j) = (k % 40, k / 40);
        let m = DMat4::from_translation(DVec3::new(
            -1.0 + 2.0 * (i as f64 + 0.5) / 40.0,
            0.0,
            -1.0 + 2.0 * (j as f64 + 0.5) / 25.0,
        )) * DMat4::from_rotation_y(k as f64 * 0.7)
            * DMat4::from_scale(DVec3::splat(0.024));
        instances.push(Instance::new(object.clone(), m).expect("invertible"));
    }
    let start = Instant::now();
    let g = Aggregate::with_instances(Vec::new(), Vec::new(), instances);
    let top_build = start.elapsed();
    let resident = resident_bytes();
    let (mrays, hits) = trace(&g, 1_000_000);
    println!(
        "instanced: 1000 instances of a {tris}-triangle object ({} triangles as seen), object BVH {:.0} ms, top BVH {:.1} ms, peak memory {} (resident after the build {}), {mrays:.2} Mrays/s single-threaded ({hits} hits of 1M)",
        tris * 1000,
        object_build.as_secs_f64() * 1e3,
        top_build.as_secs_f64() * 1e3,
        mib(peak_memory_bytes()),
        mib(resident),
    );
}

fn main() {
    match std::env::args().nth(1).as_deref() {
        Some("flat") => flat(),
        Some("instanced") => instanced(),
        _ => {
            let exe = std::env::current_exe().expect("own path");
            for case in ["flat", "instanced"] {
                let status = Command::new(&exe).arg(case).status().expect("run case");
                assert!(status.success());
            }
        }
    }
}
