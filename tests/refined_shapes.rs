//! The refined shapes `loopsubdiv`, `nurbs` and `heightfield` as pbrt-v3
//! refines them: Loop subdivision's face/vertex counts, its limit masks
//! (interior ½ / ¹⁄₁₂ at valence 6, levels that leave an original vertex's
//! limit point where it was, pbrt-v3's boundary curve rule), NURBS that
//! reproduce a plane and a rational circle exactly, sub-ranges, heightfield
//! vertices, uv and triangles; every kind of bad input gives a located error
//! and never a panic; refinement happens once per object, not per instance;
//! small renders are finite with the expected mean.

mod common;
use common::*;
use glam::{DVec3, Vec3};
use pbrs::image::compare::mean_rgb;
use pbrs::loader::load_scene_str;
use pbrs::scene::{MeshData, Surface};
use std::sync::Arc;

fn load_text(text: &str) -> Result<pbrs::loader::LoadedScene, pbrs::loader::LoadFailure> {
    load_scene_str(text, &repo().join("scenes/refined-test.pbrt"))
}

/// The mesh of the one shape `shape` (a Shape statement) and the warnings.
fn mesh_w(shape: &str) -> (Arc<MeshData>, Vec<String>) {
    let s = load_text(&format!("WorldBegin\n{shape}\nWorldEnd\n"))
        .unwrap_or_else(|f| panic!("{shape}: {f:?}"));
    assert_eq!(s.scene.shapes.len(), 1, "{shape}");
    let warnings = s.warnings.iter().map(|w| format!("{w}")).collect();
    match &s.scene.shapes[0].surface {
        Surface::TriangleMesh(m) => (m.clone(), warnings),
        g => panic!("not a mesh: {g:?}"),
    }
}

fn mesh(shape: &str) -> Arc<MeshData> {
    let (m, w) = mesh_w(shape);
    assert!(w.is_empty(), "{shape}: {w:?}");
    m
}

/// The error messages of a scene that must not load.
fn errors(shape: &str) -> String {
    world_errors(&repo().join("scenes/refined-test.pbrt"), shape)
}

fn nums<T: std::fmt::Display>(v: &[T]) -> String {
    v.iter()
        .map(|x| x.to_string())
        .collect::<Vec<_>>()
        .join(" ")
}

fn loop_shape(levels: i32, p: &[DVec3], idx: &[u32]) -> String {
    let ps: Vec<f64> = p.iter().flat_map(|v| [v.x, v.y, v.z]).collect();
    format!(
        "Shape \"loopsubdiv\" \"integer levels\" [ {levels} ] \"integer indices\" [ {} ] \"point P\" [ {} ]",
        nums(idx),
        nums(&ps)
    )
}

fn tetrahedron() -> (Vec<DVec3>, Vec<u32>) {
    (
        vec![
            DVec3::new(1.0, 1.0, 1.0),
            DVec3::new(-1.0, -1.0, 1.0),
            DVec3::new(-1.0, 1.0, -1.0),
            DVec3::new(1.0, -1.0, -1.0),
        ],
        // Outward, consistently oriented.
        vec![0, 1, 3, 0, 2, 1, 0, 3, 2, 1, 2, 3],
    )
}

fn octahedron() -> (Vec<DVec3>, Vec<u32>) {
    (
        vec![
            DVec3::X,
            DVec3::NEG_X,
            DVec3::Y,
            DVec3::NEG_Y,
            DVec3::Z,
            DVec3::NEG_Z,
        ],
        vec![
            0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5,
        ],
    )
}

/// An n × n torus grid, each quad split in two: every vertex has valence 6.
fn torus(n: u32) -> (Vec<DVec3>, Vec<u32>) {
    let mut p = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let (a, b) = (
                std::f64::consts::TAU * i as f64 / n as f64,
                std::f64::consts::TAU * j as f64 / n as f64,
            );
            let r = 2.0 + 0.7 * b.cos() + 0.1 * (3.0 * a).sin();
            p.push(DVec3::new(r * a.cos(), r * a.sin(), 0.7 * b.sin()));
        }
    }
    let at = |i: u32, j: u32| (j % n) * n + (i % n);
    let mut idx = Vec::new();
    for j in 0..n {
        for i in 0..n {
            idx.extend([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            idx.extend([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    (p, idx)
}

fn close(a: Vec3, b: DVec3, tol: f64) -> bool {
    (a.as_dvec3() - b).length() <= tol * (1.0 + b.length())
}

// ---------------------------------------------------------------- loopsubdiv

#[test]
fn loop_counts_per_level_on_closed_meshes() {
    for (name, (p, idx)) in [("tetrahedron", tetrahedron()), ("octahedron", octahedron())] {
        let f0 = idx.len() / 3;
        for levels in 0..4 {
            let m = mesh(&loop_shape(levels, &p, &idx));
            let f = f0 * 4usize.pow(levels as u32);
            assert_eq!(m.triangle_count(), f, "{name} level {levels}");
            // Closed genus 0: V − E + F = 2 with E = 3F/2.
            assert_eq!(m.positions.len(), 2 + f / 2, "{name} level {levels}");
            assert!(m.indices.iter().all(|&i| (i as usize) < m.positions.len()));
            let n = m.normals.as_ref().expect("limit normals");
            assert_eq!(n.len(), m.positions.len());
        }
    }
    // Default: 3 levels.
    let (p, idx) = tetrahedron();
    let text = loop_shape(0, &p, &idx).replace("\"integer levels\" [ 0 ]", "");
    assert_eq!(mesh(&text).triangle_count(), 4 * 64);
    // "nlevels" is read when "levels" is not given.
    let text = loop_shape(0, &p, &idx).replace("levels", "nlevels");
    assert_eq!(mesh(&text).triangle_count(), 4);
}

#[test]
fn loop_regular_limit_mask_and_level_invariance() {
    // Level 0: every vertex goes straight to its limit point. On the torus
    // every vertex is regular: ½ p + ¹⁄₁₂ of each of its six neighbours.
    let (p, idx) = torus(6);
    let m = mesh(&loop_shape(0, &p, &idx));
    let mut ring: Vec<Vec<usize>> = vec![Vec::new(); p.len()];
    for t in idx.chunks_exact(3) {
        for k in 0..3 {
            let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
            if !ring[a].contains(&b) {
                ring[a].push(b);
            }
            if !ring[b].contains(&a) {
                ring[b].push(a);
            }
        }
    }
    for (i, r) in ring.iter().enumerate() {
        assert_eq!(r.len(), 6);
        let want = 0.5 * p[i] + r.iter().map(|&j| p[j]).sum::<DVec3>() / 12.0;
        assert!(
            close(m.positions[i], want, 1e-6),
            "vertex {i}: {} vs {want}",
            m.positions[i]
        );
    }
    // An original vertex keeps its index, and its limit point is the same
    // whatever the number of levels (the limit masks are those of pbrt-v3's
    // interior rules, regular and not).
    for (name, (p, idx)) in [
        ("torus", torus(6)),
        ("tetrahedron", tetrahedron()),
        ("octahedron", octahedron()),
    ] {
        let base = mesh(&loop_shape(0, &p, &idx));
        for levels in 1..4 {
            let m = mesh(&loop_shape(levels, &p, &idx));
            for i in 0..p.len() {
                assert!(
                    close(m.positions[i], base.positions[i].as_dvec3(), 1e-5),
                    "{name} level {levels} vertex {i}: {} vs {}",
                    m.positions[i],
                    base.positions[i]
                );
            }
        }
    }
}

#[test]
fn loop_limit_normals_point_outward_on_a_closed_mesh() {
    let (p, idx) = octahedron();
    let m = mesh(&loop_shape(3, &p, &idx));
    let n = m.normals.as_ref().unwrap();
    // pbrt-v3's S × T runs against the faces' winding (its one ring goes
    // clockwise seen from the side the counter-clockwise faces face): the
    // normals of an outward-wound mesh point in, all of them.
    for (v, n) in m.positions.iter().zip(n) {
        let c = n.normalize().dot(v.normalize());
        assert!(c < -0.95, "normal {n} at {v}: cos {c}");
    }
    for t in m.indices.chunks_exact(3) {
        let [a, b, c] = [0, 1, 2].map(|k| m.positions[t[k] as usize]);
        let g = (b - a).cross(c - a);
        assert!(g.dot(n[t[0] as usize]) < 0.0);
    }
}

/// pbrt-v3's boundary curve rules on a closed polygon `b`: `levels` times
/// even = ¾ p + ⅛ (neighbours), odd = midpoint; then the limit ⅗ p + ⅕
/// (neighbours).
fn boundary_curve(mut b: Vec<DVec3>, levels: u32) -> Vec<DVec3> {
    for _ in 0..levels {
        let n = b.len();
        let mut out = Vec::with_capacity(2 * n);
        for i in 0..n {
            let (pr, p, nx) = (b[(i + n - 1) % n], b[i], b[(i + 1) % n]);
            out.push(0.75 * p + 0.125 * (pr + nx));
            out.push(0.5 * (p + nx));
        }
        b = out;
    }
    let n = b.len();
    (0..n)
        .map(|i| 0.6 * b[i] + 0.2 * (b[(i + n - 1) % n] + b[(i + 1) % n]))
        .collect()
}

#[test]
fn loop_boundary_follows_the_boundary_curve_rule() {
    // A 3 × 3 grid of quads in z = 0 with its four inner vertices raised
    // (differently in the two meshes): the boundary of the refined surface
    // depends on the boundary polygon alone and stays in z = 0.
    let grid = |lift: f64| {
        let mut p = Vec::new();
        for j in 0..4 {
            for i in 0..4 {
                let inner = (1..3).contains(&i) && (1..3).contains(&j);
                let z = if inner {
                    lift * (1.0 + i as f64 * 0.3)
                } else {
                    0.0
                };
                p.push(DVec3::new(i as f64 + 0.1 * j as f64, j as f64, z));
            }
        }
        let at = |i: u32, j: u32| j * 4 + i;
        let mut idx = Vec::new();
        for j in 0..3 {
            for i in 0..3 {
                idx.extend([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                idx.extend([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
        (p, idx)
    };
    let ring: Vec<usize> = vec![0, 1, 2, 3, 7, 11, 15, 14, 13, 12, 8, 4];
    for levels in 0..3u32 {
        let (p, idx) = grid(0.7);
        let m = mesh(&loop_shape(levels as i32, &p, &idx));
        let (p2, idx2) = grid(-1.3);
        let m2 = mesh(&loop_shape(levels as i32, &p2, &idx2));
        let want = boundary_curve(ring.iter().map(|&i| p[i]).collect(), levels);
        for w in &want {
            let found = m.positions.iter().position(|q| close(*q, *w, 1e-6));
            let Some(k) = found else {
                panic!("level {levels}: boundary point {w} not in the mesh");
            };
            assert!(m.positions[k].z.abs() < 1e-6);
            assert!(
                close(m2.positions[k], *w, 1e-6),
                "level {levels}: boundary depends on the inside"
            );
        }
        // Vertex and face counts of an open mesh: V + E per level.
        let f = 18 * 4usize.pow(levels);
        assert_eq!(m.triangle_count(), f);
        // On a flat mesh every limit normal, inside and on the boundary, is
        // along z, on the same side.
        let (p0, idx0) = grid(0.0);
        let flat = mesh(&loop_shape(levels as i32, &p0, &idx0));
        for (q, n) in flat.positions.iter().zip(flat.normals.as_ref().unwrap()) {
            assert!(
                n.normalize().z < -0.9999,
                "level {levels}: normal {n} at {q}"
            );
        }
    }
}

#[test]
fn loop_bad_input_is_an_error() {
    let (p, idx) = tetrahedron();
    let cases: Vec<(String, &str)> = vec![
        (
            "Shape \"loopsubdiv\" \"point P\" [ 0 0 0 1 0 0 0 1 0 ]".into(),
            "indices",
        ),
        (
            "Shape \"loopsubdiv\" \"integer indices\" [ 0 1 2 ]".into(),
            "point P",
        ),
        (
            "Shape \"loopsubdiv\" \"integer indices\" [ 0 1 2 0 ] \"point P\" [ 0 0 0 1 0 0 0 1 0 ]".into(),
            "multiple of 3",
        ),
        (
            "Shape \"loopsubdiv\" \"integer indices\" [ 0 1 3 ] \"point P\" [ 0 0 0 1 0 0 0 1 0 ]".into(),
            "out of range",
        ),
        (
            "Shape \"loopsubdiv\" \"integer indices\" [ 0 1 -1 ] \"point P\" [ 0 0 0 1 0 0 0 1 0 ]".into(),
            "out of range",
        ),
        (
            "Shape \"loopsubdiv\" \"integer indices\" [ 0 1 1 ] \"point P\" [ 0 0 0 1 0 0 0 1 0 ]".into(),
            "repeats a vertex",
        ),
        (
            // Two faces running the same way along edge 0–1.
            "Shape \"loopsubdiv\" \"integer indices\" [ 0 1 2 0 1 3 ] \"point P\" [ 0 0 0 1 0 0 0 1 0 0 -1 0 ]".into(),
            "consistently oriented",
        ),
        (
            "Shape \"loopsubdiv\" \"integer indices\" [ 0 1 2 ] \"point P\" [ 0 0 0 1e39 0 0 0 1 0 ]".into(),
            "finite",
        ),
        // 4 faces × 4^11 is beyond the budget.
        (loop_shape(11, &p, &idx), "more than pbrs refines"),
        // Capped (with a warning), still beyond the budget.
        (loop_shape(1000, &p, &idx), "more than pbrs refines"),
    ];
    for (shape, want) in cases {
        let e = errors(&shape);
        assert!(e.contains(want), "{shape}\n wanted \"{want}\" in: {e}");
        assert!(e.contains("loopsubdiv"), "{e}");
        assert!(e.contains("refined-test.pbrt:2:"), "not located: {e}");
    }
}

#[test]
fn loop_unused_vertices_are_left_out_with_a_warning() {
    let (m, w) = mesh_w(
        "Shape \"loopsubdiv\" \"integer levels\" [ 1 ] \"integer indices\" [ 0 2 3 ] \"point P\" [ 0 0 0 9 9 9 1 0 0 0 1 0 ]",
    );
    assert_eq!(m.triangle_count(), 4);
    assert_eq!(m.positions.len(), 6);
    assert!(m.positions.iter().all(|p| p.x < 2.0));
    assert!(w.iter().any(|w| w.contains("in no face")), "{w:?}");
}

// ---------------------------------------------------------------- nurbs

/// One direction of a patch: control points, order, knots.
type Dir<'a> = (usize, usize, &'a [f64]);

fn nurbs(u: Dir, v: Dir, points: &str, extra: &str) -> String {
    format!(
        "Shape \"nurbs\" \"integer nu\" [ {} ] \"integer uorder\" [ {} ] \"float uknots\" [ {} ] \"integer nv\" [ {} ] \"integer vorder\" [ {} ] \"float vknots\" [ {} ] {points} {extra}",
        u.0,
        u.1,
        nums(u.2),
        v.0,
        v.1,
        nums(v.2)
    )
}

/// A bilinear patch of four coplanar corners on z = 0.3x − 0.2y + 1.
fn plane_patch(extra: &str) -> String {
    nurbs(
        (2, 2, &[0.0, 0.0, 1.0, 1.0]),
        (2, 2, &[0.0, 0.0, 1.0, 1.0]),
        "\"point P\" [ 0 0 1   2 0.5 1.5   -0.5 1 0.65   1.5 2.5 0.95 ]",
        extra,
    )
}

#[test]
fn nurbs_bilinear_patch_reproduces_the_plane() {
    let m = mesh(&plane_patch(""));
    assert_eq!(m.positions.len(), 900);
    assert_eq!(m.triangle_count(), 2 * 29 * 29);
    let c = [
        DVec3::new(0.0, 0.0, 1.0),
        DVec3::new(2.0, 0.5, 1.5),
        DVec3::new(-0.5, 1.0, 0.65),
        DVec3::new(1.5, 2.5, 0.95),
    ];
    let plane_n = DVec3::new(-0.3, 0.2, 1.0).normalize();
    let uv = m.uvs.as_ref().expect("uv");
    let n = m.normals.as_ref().expect("normals");
    for (k, p) in m.positions.iter().enumerate() {
        let (i, j) = (k % 30, k / 30);
        let (u, v) = (i as f64 / 29.0, j as f64 / 29.0);
        assert!((uv[k].x as f64 - u).abs() < 1e-6 && (uv[k].y as f64 - v).abs() < 1e-6);
        let want = (1.0 - v) * ((1.0 - u) * c[0] + u * c[1]) + v * ((1.0 - u) * c[2] + u * c[3]);
        assert!(close(*p, want, 1e-6), "{p} vs {want}");
        let pd = p.as_dvec3();
        assert!((pd.z - (0.3 * pd.x - 0.2 * pd.y + 1.0)).abs() < 1e-5);
        // ∂p/∂u × ∂p/∂v: the plane's upward normal here.
        assert!(
            (n[k].as_dvec3().dot(plane_n) - 1.0).abs() < 1e-5,
            "{}",
            n[k]
        );
    }
    // pbrt-v3's split of cell (0, 0).
    assert_eq!(&m.indices[..6], &[0, 1, 31, 0, 31, 30]);
}

#[test]
fn nurbs_sub_range() {
    let m = mesh(&plane_patch(
        "\"float u0\" [ 0.25 ] \"float u1\" [ 0.75 ] \"float v0\" [ 0.5 ] \"float v1\" [ 1 ]",
    ));
    let uv = m.uvs.as_ref().unwrap();
    assert!((uv[0].x - 0.25).abs() < 1e-7 && (uv[0].y - 0.5).abs() < 1e-7);
    assert!((uv[899].x - 0.75).abs() < 1e-7 && (uv[899].y - 1.0).abs() < 1e-7);
    // The first vertex is the patch at (0.25, 0.5).
    let c = [
        DVec3::new(0.0, 0.0, 1.0),
        DVec3::new(2.0, 0.5, 1.5),
        DVec3::new(-0.5, 1.0, 0.65),
        DVec3::new(1.5, 2.5, 0.95),
    ];
    let at = |u: f64, v: f64| {
        (1.0 - v) * ((1.0 - u) * c[0] + u * c[1]) + v * ((1.0 - u) * c[2] + u * c[3])
    };
    assert!(close(m.positions[0], at(0.25, 0.5), 1e-6));
    assert!(close(m.positions[899], at(0.75, 1.0), 1e-6));
    assert!(close(m.positions[29], at(0.75, 0.5), 1e-6));
}

/// A quarter cylinder of radius 1: the rational quadratic quarter circle in
/// u (weights 1, 1/√2, 1), extruded linearly along z in v.
fn quarter_cylinder(extra: &str) -> String {
    let w = std::f64::consts::FRAC_1_SQRT_2;
    let row = |z: f64| format!("1 0 {z} 1   {w} {w} {} {w}   0 1 {z} 1", z * w);
    nurbs(
        (3, 3, &[0.0, 0.0, 0.0, 1.0, 1.0, 1.0]),
        (2, 2, &[0.0, 0.0, 1.0, 1.0]),
        &format!("\"float Pw\" [ {}   {} ]", row(0.0), row(2.0)),
        extra,
    )
}

#[test]
fn nurbs_rational_quarter_circle_lies_on_the_circle() {
    let m = mesh(&quarter_cylinder(""));
    let n = m.normals.as_ref().unwrap();
    let mut max_angle: f32 = 0.0;
    for (p, n) in m.positions.iter().zip(n) {
        let r = (p.x * p.x + p.y * p.y).sqrt();
        assert!((r - 1.0).abs() < 1e-6, "{p}: radius {r}");
        assert!(p.x >= -1e-7 && p.y >= -1e-7 && (0.0..=2.0 + 1e-6).contains(&p.z));
        // Normal: radial (∂p/∂u runs counter-clockwise, ∂p/∂v up: outward).
        let radial = Vec3::new(p.x, p.y, 0.0).normalize();
        assert!(n.dot(radial) > 1.0 - 1e-5, "{n} at {p}");
        max_angle = max_angle.max(p.y.atan2(p.x));
    }
    assert!((max_angle - std::f32::consts::FRAC_PI_2).abs() < 1e-5);
    // By symmetry u = ½ is at 45°.
    let m = mesh(&quarter_cylinder("\"float u1\" [ 0.5 ]"));
    let last = m.positions[29];
    assert!(
        (last.y.atan2(last.x) - std::f32::consts::FRAC_PI_4).abs() < 1e-5,
        "{last}"
    );
    // u0 > u1 dices backwards (a warning, as pbrt-v3 accepts it).
    let (m, w) = mesh_w(&quarter_cylinder("\"float u0\" [ 1 ] \"float u1\" [ 0 ]"));
    assert!(close(m.positions[0], DVec3::new(0.0, 1.0, 0.0), 1e-6));
    assert!(w.iter().any(|w| w.contains("u0")), "{w:?}");
}

#[test]
fn nurbs_cubic_bezier_patch_matches_bernstein() {
    // Order 4 with a single span is the bicubic Bézier patch.
    let mut pts = Vec::new();
    let h = |i: usize, j: usize| ((i * 7 + j * 3) % 5) as f64 * 0.25;
    for j in 0..4 {
        for i in 0..4 {
            pts.extend([i as f64, j as f64, h(i, j)]);
        }
    }
    let k = [0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0];
    let m = mesh(&nurbs(
        (4, 4, &k),
        (4, 4, &k),
        &format!("\"point P\" [ {} ]", nums(&pts)),
        "",
    ));
    let b = |t: f64| {
        let s = 1.0 - t;
        [s * s * s, 3.0 * s * s * t, 3.0 * s * t * t, t * t * t]
    };
    for (k, p) in m.positions.iter().enumerate() {
        let uv = m.uvs.as_ref().unwrap()[k].as_dvec2();
        let (bu, bv) = (b(uv.x), b(uv.y));
        let mut want = DVec3::ZERO;
        for (j, bj) in bv.iter().enumerate() {
            for (i, bi) in bu.iter().enumerate() {
                want += bi * bj * DVec3::new(i as f64, j as f64, h(i, j));
            }
        }
        assert!(close(*p, want, 1e-6), "{p} vs {want}");
    }
}

#[test]
fn nurbs_bad_input_is_an_error() {
    let k2 = [0.0, 0.0, 1.0, 1.0];
    let p4 = "\"point P\" [ 0 0 0 1 0 0 0 1 0 1 1 0 ]";
    let cases: Vec<(String, &str)> = vec![
        (
            nurbs((2, 2, &[0.0, 0.0, 1.0]), (2, 2, &k2), p4, ""),
            "knots",
        ),
        (nurbs((2, 2, &k2), (2, 2, &k2), "\"point P\" [ 0 0 0 1 0 0 0 1 0 ]", ""), "nu × nv"),
        (nurbs((2, 2, &k2), (2, 2, &k2), "\"float Pw\" [ 0 0 0 1 1 0 0 1 0 1 0 1 1 1 0 ]", ""), "multiple of 4"),
        (nurbs((2, 2, &k2), (2, 2, &k2), "\"float Pw\" [ 0 0 0 1 1 0 0 1 0 1 0 1 ]", ""), "nu × nv"),
        (nurbs((2, 2, &k2), (2, 2, &k2), "\"float Pw\" [ 0 0 0 1 1 0 0 1 0 1 0 0 1 1 0 1 ]", ""), "positive"),
        (nurbs((2, 1, &[0.0, 0.0, 1.0]), (2, 2, &k2), p4, ""), "orders 2 to"),
        (nurbs((2, 3, &[0.0, 0.0, 0.0, 1.0, 1.0]), (2, 2, &k2), p4, ""), "fewer control points"),
        (nurbs((2, 2, &[0.0, 1.0, 0.5, 1.0]), (2, 2, &k2), p4, ""), "decreases"),
        (nurbs((2, 2, &[0.0, 0.5, 0.5, 1.0]), (2, 2, &k2), p4, ""), "empty"),
        (nurbs((2, 2, &k2), (2, 2, &k2), p4, "\"float u0\" [ 0.5 ] \"float u1\" [ 0.5 ]"), "empty"),
        (nurbs((2, 2, &k2), (2, 2, &k2), p4, "\"float u1\" [ 1.5 ]"), "outside"),
        (nurbs((2, 2, &k2), (2, 2, &k2), p4, "\"float v0\" [ -0.1 ]"), "outside"),
        (nurbs((2, 2, &[0.0, 0.0, 1.0, 1e39]), (2, 2, &k2), p4, ""), "finite"),
        (nurbs((2, 2, &k2), (2, 2, &k2), "\"point P\" [ 0 0 0 1 0 0 0 1 0 1 1 1e39 ]", ""), "finite"),
        (nurbs((2, 2, &k2), (2, 2, &k2), "", ""), "\"point P\" or \"float Pw\""),
        (nurbs((100, 100, &(0..200).map(|i| i as f64).collect::<Vec<_>>()), (2, 2, &k2), p4, ""), "orders 2 to"),
        (
            "Shape \"nurbs\" \"integer nu\" [ 2 ] \"integer uorder\" [ 2 ] \"float uknots\" [ 0 0 1 1 ]".into(),
            "\"integer nv\"",
        ),
        (
            format!("Shape \"nurbs\" \"integer nu\" [ 2000000000 ] \"integer uorder\" [ 2 ] \"float uknots\" [ 0 0 1 1 ] \"integer nv\" [ 2000000000 ] \"integer vorder\" [ 2 ] \"float vknots\" [ 0 0 1 1 ] {p4}"),
            "knots",
        ),
    ];
    for (shape, want) in cases {
        let e = errors(&shape);
        assert!(e.contains(want), "{shape}\n wanted \"{want}\" in: {e}");
        assert!(e.contains("nurbs"), "{e}");
        assert!(e.contains("refined-test.pbrt:2:"), "not located: {e}");
    }
}

#[test]
fn nurbs_degenerate_edge_gives_zero_normals_not_nan() {
    // All four v = 0 control points at one spot: ∂p/∂u vanishes along that edge.
    let m = mesh(&nurbs(
        (2, 2, &[0.0, 0.0, 1.0, 1.0]),
        (2, 2, &[0.0, 0.0, 1.0, 1.0]),
        "\"point P\" [ 0 0 1  0 0 1  -1 1 0  1 1 0 ]",
        "",
    ));
    let n = m.normals.as_ref().unwrap();
    assert!(n.iter().all(|n| n.is_finite()));
    assert!(n[..30].iter().all(|n| *n == Vec3::ZERO));
    assert!(n[30..].iter().all(|n| (n.length() - 1.0).abs() < 1e-5));
}

// ---------------------------------------------------------------- heightfield

#[test]
fn heightfield_vertices_uv_and_triangles() {
    let m = mesh("Shape \"heightfield\" \"integer nu\" [ 3 ] \"integer nv\" [ 2 ] \"float Pz\" [ 0 1 2 3 4 5 ]");
    assert_eq!(m.positions.len(), 6);
    assert_eq!(m.triangle_count(), 4);
    let uv = m.uvs.as_ref().unwrap();
    for (k, p) in m.positions.iter().enumerate() {
        let (i, j) = (k % 3, k / 3);
        let want = Vec3::new(i as f32 / 2.0, j as f32, k as f32);
        assert_eq!(*p, want);
        assert_eq!(uv[k], want.truncate());
    }
    assert_eq!(*m.indices, vec![0, 1, 4, 0, 4, 3, 1, 2, 5, 1, 5, 4]);
    assert!(m.normals.is_none());
}

#[test]
fn heightfield_bad_input_is_an_error() {
    let cases = [
        (
            "\"integer nu\" [ 3 ] \"integer nv\" [ 2 ] \"float Pz\" [ 0 1 2 3 4 ]",
            "\"Pz\" has 5",
        ),
        (
            "\"integer nu\" [ 1 ] \"integer nv\" [ 2 ] \"float Pz\" [ 0 1 ]",
            "at least 2",
        ),
        (
            "\"integer nu\" [ 2 ] \"integer nv\" [ -2 ] \"float Pz\" [ 0 1 ]",
            "at least 2",
        ),
        (
            "\"integer nv\" [ 2 ] \"float Pz\" [ 0 1 ]",
            "\"integer nu\"",
        ),
        ("\"integer nu\" [ 2 ] \"integer nv\" [ 1 ]", "\"float Pz\""),
        (
            "\"integer nu\" [ 2 ] \"integer nv\" [ 2 ] \"float Pz\" [ 0 1 2 1e39 ]",
            "finite",
        ),
        (
            "\"integer nu\" [ 2000000000 ] \"integer nv\" [ 2000000000 ] \"float Pz\" [ 0 1 2 3 ]",
            "\"Pz\" has 4",
        ),
    ];
    for (params, want) in cases {
        let e = errors(&format!("Shape \"heightfield\" {params}"));
        assert!(e.contains(want), "{params}\n wanted \"{want}\" in: {e}");
        assert!(e.contains("refined-test.pbrt:2:"), "not located: {e}");
    }
}

// ---------------------------------------------------------------- scene

#[test]
fn refined_once_per_object_and_no_alpha() {
    let (p, idx) = octahedron();
    let text = format!(
        "WorldBegin\nObjectBegin \"blob\"\n{} \"float alpha\" [ 0 ]\nObjectEnd\nObjectInstance \"blob\"\nTranslate 3 0 0\nObjectInstance \"blob\"\nObjectInstance \"blob\"\nWorldEnd\n",
        loop_shape(2, &p, &idx)
    );
    let s = load_text(&text).unwrap_or_else(|f| panic!("{f:?}"));
    assert_eq!(s.scene.objects.len(), 1);
    assert_eq!(s.scene.objects[0].shapes.len(), 1);
    assert_eq!(s.scene.instances.len(), 3);
    let sh = &s.scene.objects[0].shapes[0];
    assert!(matches!(&sh.surface, Surface::TriangleMesh(m) if m.triangle_count() == 8 * 16));
    // pbrt-v3 gives refined meshes no alpha: the parameter is unused.
    assert!(sh.alpha.is_none());
    let w: Vec<String> = s.warnings.iter().map(|w| format!("{w}")).collect();
    assert!(
        w.iter()
            .any(|w| w.contains("alpha") && w.contains("not used")),
        "{w:?}"
    );
    // And the unsupported-shape count does not include them.
    assert!(!w.iter().any(|w| w.contains("unsupported")), "{w:?}");
}

#[test]
fn refined_shapes_render_finite_with_the_expected_mean() {
    // Diffuse (Kd 0.5) surfaces under a uniform environment (L 1): a flat
    // heightfield filling the view and a convex subdivided octahedron reflect
    // 0.5 wherever they are seen; the background is 1.
    let scene = |shape: &str| {
        format!(
            "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" [ 30 ]\nSampler \"halton\"\nIntegrator \"path\" \"integer maxdepth\" [ 3 ]\nWorldBegin\nLightSource \"infinite\" \"rgb L\" [ 1 1 1 ]\nMaterial \"matte\" \"rgb Kd\" [ 0.5 0.5 0.5 ]\n{shape}\nWorldEnd\n"
        )
    };
    let pz: Vec<String> = (0..16).map(|_| "0".to_string()).collect();
    let hf = format!(
        "Translate -5 -5 0\nScale 10 10 1\nShape \"heightfield\" \"integer nu\" [ 4 ] \"integer nv\" [ 4 ] \"float Pz\" [ {} ]",
        pz.join(" ")
    );
    let (p, idx) = octahedron();
    let blob = loop_shape(3, &p, &idx);
    for (name, shape, lo, hi) in [
        ("heightfield", hf, 0.48, 0.52),
        ("loopsubdiv", blob, 0.85, 0.99),
    ] {
        let s = load_text(&scene(&shape))
            .unwrap_or_else(|f| panic!("{f:?}"))
            .scene;
        let (img, stats) = render_at(s, 32, 16, None);
        assert_eq!(stats.dropped_samples(), 0, "{name}");
        assert!(img.data.iter().all(|v| v.is_finite()), "{name}: NaN or inf");
        let m = mean_rgb(&img)[1];
        assert!((lo..hi).contains(&m), "{name}: mean {m}");
        // Every pixel is the surface (about 0.5) or the background (1).
        assert!(
            img.data.iter().all(|&v| (0.2..=1.0 + 1e-3).contains(&v)),
            "{name}"
        );
    }
}

#[test]
fn nurbs_empty_first_knot_span_is_evaluated_at_its_right() {
    // Knots 0 0 0 1 1 (order 2, three points): the first span of the domain
    // is empty (pbrt-v3 divides by zero there); the curve runs from the
    // second control point to the third.
    let m = mesh(&nurbs(
        (3, 2, &[0.0, 0.0, 0.0, 1.0, 1.0]),
        (2, 2, &[0.0, 0.0, 1.0, 1.0]),
        "\"point P\" [ 5 5 5  0 0 0  1 0 0   5 5 6  0 1 0  1 1 0 ]",
        "",
    ));
    assert!(m.positions.iter().all(|p| p.is_finite()));
    assert!(
        close(m.positions[0], DVec3::ZERO, 1e-6),
        "{}",
        m.positions[0]
    );
    assert!(
        close(m.positions[29], DVec3::X, 1e-6),
        "{}",
        m.positions[29]
    );
    assert!(close(m.positions[899], DVec3::new(1.0, 1.0, 0.0), 1e-6));
}
