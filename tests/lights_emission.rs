//! Emitted rays (`LightModel::sample_le`, pbrt-v3's `Sample_Le`), one test
//! per light kind, each a scene loaded through the real loader and built by
//! `RenderScene::new`:
//!
//! - the densities are those of the rays drawn: the mean of
//!   Le·|cos θ|/(pdf_pos·pdf_dir) over many rays is the light's emitted
//!   power (computed independently: exactly for point, distant and area
//!   lights, by integrating the radiance over directions otherwise), and the
//!   mean of 1/pdf_dir over directions is the solid angle they cover;
//! - each ray's radiance is the light's own (its `sample_li` from a point on
//!   the ray, its `le` for an infinite light, its `emitted` for an area
//!   light), and its origin and direction lie where the light emits.

mod common;

use common::load_text;
use glam::{Vec2, Vec3};
use pbrs::geometry::luminance;
use pbrs::integrators::RenderScene;
use pbrs::lights::{EmittedRay, Light};
use pbrs::sampling::{uniform_sample_sphere, Pcg32};
use pbrs::shapes::SurfacePoint;

/// A scene with `light` (in the world block) and a unit sphere at the
/// origin, so that lights at infinity have a scene to cover.
fn scene(light: &str) -> RenderScene {
    let text = format!(
        "Camera \"perspective\"\nWorldBegin\n{light}\nAttributeBegin\nMaterial \"matte\"\nShape \"sphere\" \"float radius\" 1\nAttributeEnd\nWorldEnd\n"
    );
    RenderScene::new(&load_text(&text).scene)
}

/// The scene's only emitting light (the sphere is not one unless the
/// world says so).
fn light(sc: &RenderScene) -> &Light {
    assert_eq!(sc.lights.len(), 1, "one light");
    &sc.lights[0]
}

/// `n` emitted rays of the scene's light, from a fixed random stream.
fn rays(sc: &RenderScene, n: usize) -> Vec<EmittedRay> {
    let mut rng = Pcg32::with_sequence(7);
    let mut u = || Vec2::new(rng.uniform_f32(), rng.uniform_f32());
    (0..n)
        .filter_map(|_| {
            let (u1, u2) = (u(), u());
            light(sc).sample_le(u1, u2, &sc.aggregate)
        })
        .collect()
}

/// Mean of luminance(Le)·|n·d|/(pdf_pos·pdf_dir) over `n` draws (rays not
/// drawn count as zero): an estimate of the emitted power.
fn power_estimate(sc: &RenderScene, n: usize) -> f64 {
    let l = light(sc);
    let mut rng = Pcg32::with_sequence(11);
    let mut sum = 0.0f64;
    for _ in 0..n {
        let u1 = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
        let u2 = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
        if let Some(e) = l.sample_le(u1, u2, &sc.aggregate) {
            assert!(e.pdf_pos > 0.0 && e.pdf_dir > 0.0);
            assert!((e.ray.d.length() - 1.0).abs() < 1e-4, "unit direction");
            sum += (luminance(e.le) * e.n.dot(e.ray.d).abs() / (e.pdf_pos * e.pdf_dir)) as f64;
        }
    }
    sum / n as f64
}

fn mean_inverse_pdf_dir(rs: &[EmittedRay], n: usize) -> f64 {
    rs.iter().map(|e| 1.0 / e.pdf_dir as f64).sum::<f64>() / n as f64
}

fn at(p: Vec3) -> SurfacePoint {
    SurfacePoint {
        p,
        p_error: Vec3::ZERO,
        n: Vec3::ZERO,
        ns: Vec3::ZERO,
    }
}

fn close(a: f64, b: f64, rel: f64, what: &str) {
    assert!((a - b).abs() <= rel * b.abs(), "{what}: {a} vs {b}");
}

/// Point-like lights: Le along each ray is the intensity `sample_li` sees
/// from the point at distance 1 along it.
fn check_point_like(sc: &RenderScene, rs: &[EmittedRay]) {
    for e in rs {
        let s = light(sc)
            .sample_li(&at(e.ray.o + e.ray.d), Vec2::new(0.5, 0.5), &sc.aggregate)
            .expect("sample");
        assert!((s.li - e.le).abs().max_element() <= 1e-4 * e.le.max_element().max(1.0));
        assert_eq!(e.pdf_pos, 1.0);
        assert_eq!(e.n, e.ray.d);
    }
}

/// The emitted power by integrating Le over uniformly drawn directions.
fn power_by_directions(sc: &RenderScene, n: usize) -> f64 {
    let l = light(sc);
    let o = match l {
        Light::Spot(s) => s.p,
        Light::Goniometric(g) => g.p,
        Light::Projection(p) => p.p,
        _ => unreachable!(),
    };
    let mut rng = Pcg32::with_sequence(3);
    let mut sum = 0.0f64;
    for _ in 0..n {
        let d = uniform_sample_sphere(Vec2::new(rng.uniform_f32(), rng.uniform_f32()));
        if let Some(s) = l.sample_li(&at(o + d), Vec2::ZERO, &sc.aggregate) {
            sum += luminance(s.li) as f64;
        }
    }
    sum / n as f64 * 4.0 * std::f64::consts::PI
}

const N: usize = 200_000;

#[test]
fn point() {
    let sc = scene("LightSource \"point\" \"point from\" [0 3 0] \"rgb I\" [1 2 3]");
    let rs = rays(&sc, 1000);
    assert_eq!(rs.len(), 1000);
    check_point_like(&sc, &rs);
    close(
        mean_inverse_pdf_dir(&rs, 1000),
        4.0 * std::f64::consts::PI,
        1e-5,
        "solid angle",
    );
    close(
        power_estimate(&sc, 1000),
        light(&sc).power() as f64,
        1e-5,
        "power",
    );
}

#[test]
fn spot() {
    let sc = scene("LightSource \"spot\" \"point from\" [0 3 0] \"point to\" [1 0 0] \"float coneangle\" 25 \"float conedeltaangle\" 10 \"rgb I\" [4 4 4]");
    let Light::Spot(s) = light(&sc) else { panic!() };
    let rs = rays(&sc, N);
    check_point_like(&sc, &rs[..1000]);
    for e in &rs {
        assert!(
            s.frame.to_local(e.ray.d).z >= s.cos_total - 1e-5,
            "in the cone"
        );
    }
    let cone = 2.0 * std::f64::consts::PI * (1.0 - s.cos_total as f64);
    close(mean_inverse_pdf_dir(&rs, N), cone, 1e-4, "solid angle");
    close(
        power_estimate(&sc, N),
        power_by_directions(&sc, 4 * N),
        0.02,
        "power",
    );
}

#[test]
fn goniometric() {
    let sc = scene("LightSource \"goniometric\" \"string mapname\" \"scenes/textures-env/pattern.png\" \"rgb I\" [2 2 2]");
    let rs = rays(&sc, N);
    check_point_like(&sc, &rs[..1000]);
    close(
        mean_inverse_pdf_dir(&rs, N),
        4.0 * std::f64::consts::PI,
        1e-5,
        "solid angle",
    );
    close(
        power_estimate(&sc, N),
        power_by_directions(&sc, N),
        0.02,
        "power",
    );
}

#[test]
fn projection() {
    let sc = scene("Translate 0 3 0\nRotate 90 1 0 0\nLightSource \"projection\" \"string mapname\" \"scenes/textures-env/pattern.png\" \"float fov\" 40 \"rgb I\" [2 2 2]");
    let Light::Projection(p) = light(&sc) else {
        panic!()
    };
    let rs = rays(&sc, N);
    check_point_like(&sc, &rs[..1000]);
    // The cone around the frustum: its half-diagonal's tangent.
    let tan_diag = (p.screen[1].hypot(p.screen[3]) / p.inv_tan) as f64;
    let cos_max = 1.0 / (1.0 + tan_diag * tan_diag).sqrt();
    for e in &rs {
        assert!(e.ray.d.dot(p.axis) as f64 >= cos_max - 1e-5, "in the cone");
    }
    let cone = 2.0 * std::f64::consts::PI * (1.0 - cos_max);
    close(mean_inverse_pdf_dir(&rs, N), cone, 1e-4, "solid angle");
    close(
        power_estimate(&sc, N),
        power_by_directions(&sc, 4 * N),
        0.02,
        "power",
    );
}

#[test]
fn distant() {
    let sc = scene(
        "LightSource \"distant\" \"point from\" [1 2 3] \"point to\" [0 0 0] \"rgb L\" [2 2 2]",
    );
    let Light::Distant(d) = light(&sc) else {
        panic!()
    };
    let (c, r) = sc.aggregate.bounds.bounding_sphere();
    let rs = rays(&sc, 1000);
    assert_eq!(rs.len(), 1000);
    for e in &rs {
        assert!((e.ray.d + d.w).length() < 1e-6, "along the light");
        let o = e.ray.o - c;
        assert!((o.dot(d.w) - r).abs() < 1e-4 * r, "on the disk's plane");
        assert!(
            (o - o.dot(d.w) * d.w).length() <= r * (1.0 + 1e-5),
            "on the disk"
        );
        assert_eq!(e.le, d.l);
        assert_eq!(e.pdf_dir, 1.0);
    }
    close(
        power_estimate(&sc, 1000),
        light(&sc).power() as f64,
        1e-4,
        "power",
    );
}

#[test]
fn infinite() {
    let sc = scene("LightSource \"infinite\" \"string mapname\" \"scenes/textures-env/sky.exr\"");
    let l = light(&sc);
    let (c, r) = sc.aggregate.bounds.bounding_sphere();
    let rs = rays(&sc, N);
    for e in &rs[..1000] {
        // The map's texel at the sampled (u, v) and at the direction made of
        // it: equal but for rounding in the direction's round trip.
        assert!((e.le - l.le(-e.ray.d)).abs().max_element() <= 1e-3 * e.le.max_element().max(1.0));
        let o = e.ray.o - c;
        assert!(
            (o.dot(-e.ray.d) - r).abs() < 1e-3 * r,
            "on the disk's plane"
        );
        close(
            e.pdf_pos as f64,
            1.0 / (std::f64::consts::PI * (r * r) as f64),
            1e-5,
            "pdf_pos",
        );
    }
    // Mean of Le/pdf_dir against ∫Le dω by uniform directions.
    let by_sampling = rs
        .iter()
        .map(|e| luminance(e.le) as f64 / e.pdf_dir as f64)
        .sum::<f64>()
        / N as f64;
    let mut rng = Pcg32::with_sequence(5);
    let uniform = (0..4 * N)
        .map(|_| {
            let d = uniform_sample_sphere(Vec2::new(rng.uniform_f32(), rng.uniform_f32()));
            luminance(l.le(d)) as f64
        })
        .sum::<f64>()
        / (4 * N) as f64
        * 4.0
        * std::f64::consts::PI;
    close(by_sampling, uniform, 0.02, "radiance over directions");
}

/// Area lights: Le is the light's emission at the origin's normal, the
/// origins lie on the shape, and the power estimate is L·area·π (twice for
/// two-sided lights), which is also the light's `power()`.
fn check_area(sc: &RenderScene, on_shape: impl Fn(Vec3) -> bool, two_sided: bool) {
    let l = light(sc);
    let rs = rays(sc, N);
    assert_eq!(rs.len(), N);
    let mut below = 0;
    for e in &rs {
        assert!(on_shape(e.ray.o), "origin {} on the shape", e.ray.o);
        assert_eq!(e.le, l.emitted(e.n, e.ray.d));
        if e.n.dot(e.ray.d) < 0.0 {
            below += 1;
        }
    }
    if two_sided {
        close(below as f64, N as f64 / 2.0, 0.02, "both sides");
    } else {
        assert_eq!(below, 0, "one side");
    }
    close(power_estimate(sc, N), l.power() as f64, 0.01, "power");
}

#[test]
fn diffuse_triangle() {
    let sc = RenderScene::new(
        &load_text(
            "Camera \"perspective\"\nWorldBegin\nAttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [1 2 3]\n\
             Shape \"trianglemesh\" \"integer indices\" [0 1 2] \"point P\" [0 0 0  2 0 0  0 0 3]\nAttributeEnd\nWorldEnd\n",
        )
        .scene,
    );
    check_area(
        &sc,
        |p| p.y.abs() < 1e-5 && p.x >= -1e-5 && p.z >= -1e-5 && p.x / 2.0 + p.z / 3.0 <= 1.0 + 1e-5,
        false,
    );
}

#[test]
fn diffuse_sphere_two_sided() {
    let sc = RenderScene::new(
        &load_text(
            "Camera \"perspective\"\nWorldBegin\nAttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [1 1 1] \"bool twosided\" \"true\"\n\
             Translate 1 2 3\nShape \"sphere\" \"float radius\" 0.5\nAttributeEnd\nWorldEnd\n",
        )
        .scene,
    );
    check_area(
        &sc,
        |p| ((p - Vec3::new(1.0, 2.0, 3.0)).length() - 0.5).abs() < 1e-4,
        true,
    );
}

#[test]
fn diffuse_disk() {
    let sc = RenderScene::new(
        &load_text(
            "Camera \"perspective\"\nWorldBegin\nAttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [2 2 2]\n\
             Rotate 90 1 0 0\nShape \"disk\" \"float radius\" 2\nAttributeEnd\nWorldEnd\n",
        )
        .scene,
    );
    check_area(&sc, |p| p.y.abs() < 1e-4 && p.length() <= 2.0 + 1e-4, false);
}
