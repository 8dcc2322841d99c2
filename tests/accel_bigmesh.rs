//! Big levels (more than 262,144 primitives) are built by the parallel
//! binned-SAH builder: the same tree and the same hits for one thread and
//! two, and a BVH no larger than the loader's memory estimate (nor much
//! smaller: the estimate is what the memory check relies on).

use glam::Vec3;
use pbrs::accel::{bvh_memory_estimate, Aggregate};
use pbrs::geometry::Ray;
use pbrs::shapes::TriangleMesh;

/// A wavy grid of `2·n²` triangles over [-1, 1]² (z up to ±0.1).
fn grid(n: u32) -> TriangleMesh {
    let mut p = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (
                i as f32 / n as f32 * 2.0 - 1.0,
                j as f32 / n as f32 * 2.0 - 1.0,
            );
            p.push(Vec3::new(x, y, 0.1 * (9.0 * x).sin() * (7.0 * y).cos()));
        }
    }
    let mut indices = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let a = j * (n + 1) + i;
            indices.extend_from_slice(&[a, a + 1, a + n + 2, a, a + n + 2, a + n + 1]);
        }
    }
    TriangleMesh::plain(p, indices)
}

#[test]
fn big_level_is_deterministic_and_within_its_estimate() {
    let mesh = grid(400);
    let triangles = mesh.triangle_count() as u64;
    assert_eq!(triangles, 320_000);
    let build = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| Aggregate::new(vec![mesh.clone()], Vec::new()))
    };
    let (one, two) = (build(1), build(2));
    assert!(one.build_work.binned, "a big level uses the binned builder");
    assert_eq!(one.bvh_counts(), two.bvh_counts());
    assert_eq!(one.bvh_bytes(), two.bvh_bytes());
    // Rays from above onto the grid, and grazing ones: the same hits.
    let mut hits = 0;
    for k in 0..4000u32 {
        let (u, v) = ((k % 63) as f32 / 31.0 - 1.0, (k / 63) as f32 / 31.0 - 1.0);
        let ray = if k % 2 == 0 {
            Ray::new(Vec3::new(u, v, 2.0), Vec3::new(0.01 * v, 0.02, -1.0))
        } else {
            Ray::new(Vec3::new(-2.0, u, 0.05 * v), Vec3::new(1.0, 0.1 * v, -0.01))
        };
        let (a, b) = (one.intersect(&ray), two.intersect(&ray));
        assert_eq!(
            a.map(|h| (h.t, h.prim)),
            b.map(|h| (h.t, h.prim)),
            "ray {k}"
        );
        hits += a.is_some() as u32;
        assert_eq!(one.occluded(&ray), a.is_some());
    }
    assert!(hits > 2500, "{hits} of 4000 rays hit the grid");
    // The estimate covers the BVH and is not more than 1.5 times it.
    let (actual, estimate) = (one.bvh_bytes() as u64, bvh_memory_estimate(triangles));
    assert!(
        actual <= estimate && estimate <= actual * 3 / 2,
        "BVH {actual} bytes ({:.1} per triangle), estimate {estimate}",
        actual as f64 / triangles as f64
    );
}

/// A scene whose meshes cannot fit (one 300,000-triangle PLY placed 1,800
/// times: 540 million triangles, past the BVH's limit and, on most
/// machines, its memory estimate first) is refused while loading, with an
/// error at the `Shape` line, before anything is built.
#[test]
fn too_many_triangles_is_a_located_error() {
    let dir = std::env::temp_dir().join(format!("pbrs-accel-bigmesh-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mesh = grid(388);
    let mut ply = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
        mesh.p.len(),
        mesh.triangle_count()
    )
    .into_bytes();
    for v in mesh.p.iter() {
        for c in v.to_array() {
            ply.extend_from_slice(&c.to_le_bytes());
        }
    }
    for t in mesh.indices.chunks_exact(3) {
        ply.push(3);
        for &i in t {
            ply.extend_from_slice(&(i as i32).to_le_bytes());
        }
    }
    std::fs::write(dir.join("m.ply"), ply).unwrap();
    let shapes = "Shape \"plymesh\" \"string filename\" \"m.ply\"\n".repeat(1800);
    std::fs::write(
        dir.join("scene.pbrt"),
        format!(
            "LookAt 0 0 5 0 0 0 0 1 0\nCamera \"perspective\"\nFilm \"image\" \"integer xresolution\" 8 \"integer yresolution\" 8 \"string filename\" \"out.png\"\nWorldBegin\n{shapes}WorldEnd\n"
        ),
    )
    .unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_pbrs"))
        .arg("scene.pbrt")
        .current_dir(&dir)
        .env("NO_COLOR", "1")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert_eq!(stderr.matches("triangles so far").count(), 1, "{stderr}");
    assert!(stderr.contains("scene.pbrt:"), "{stderr}");
    assert!(!dir.join("out.png").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}
