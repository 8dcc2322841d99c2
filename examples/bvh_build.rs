//! BVH build time for n coincident triangles (one triangle indexed n times)
//! and n random triangles, n = 10^4 … 10^6: time, time / (n log2 n), the
//! counted work per n log2 n, and which builder ran.
//!
//! cargo run --release --example bvh_build [-- N...]

use glam::Vec3;
use pbrs::accel::Aggregate;
use pbrs::shapes::TriangleMesh;
use std::time::Instant;

fn coincident(n: usize) -> TriangleMesh {
    let p = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
    TriangleMesh::plain(p, [0, 1, 2].repeat(n))
}

fn random(n: usize) -> TriangleMesh {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut rnd = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    let mut p = Vec::with_capacity(3 * n);
    for _ in 0..n {
        let c = Vec3::new(rnd(), rnd(), rnd()) * 10.0;
        for _ in 0..3 {
            p.push(c + Vec3::new(rnd(), rnd(), rnd()) * 0.05);
        }
    }
    TriangleMesh::plain(p, (0..3 * n as u32).collect())
}

fn main() {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let ns = if args.is_empty() {
        vec![10_000, 100_000, 1_000_000]
    } else {
        args
    };
    println!(
        "{:>11} {:>9} {:>9} {:>14} {:>12} {:>8}",
        "input", "n", "build s", "ns/(n log2 n)", "work/(nlogn)", "builder"
    );
    for kind in ["coincident", "random"] {
        for &n in &ns {
            let m = if kind == "coincident" {
                coincident(n)
            } else {
                random(n)
            };
            let t = Instant::now();
            let g = Aggregate::new(vec![m], Vec::new());
            let s = t.elapsed().as_secs_f64();
            let nlogn = n as f64 * (n as f64).log2();
            println!(
                "{:>11} {:>9} {:>9.3} {:>14.2} {:>12.2} {:>8}",
                kind,
                n,
                s,
                s * 1e9 / nlogn,
                g.build_work.work as f64 / nlogn,
                if g.build_work.bounded {
                    "bounded"
                } else {
                    "PLOC"
                }
            );
        }
    }
}
