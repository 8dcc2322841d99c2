//! pbrt-v3's `disk` and `cylinder` against analytic answers (cones, paraboloids
//! and hyperboloids: tests/quadric_surfaces.rs).
//!
//! - intersection: rays through known points hit there (t, point, normal,
//!   uv); rays through the hole, the cut-out sector, past the rim, parallel
//!   to the plane or away from it miss;
//! - scale invariance: rays spawned from sampled points (either side) never
//!   re-hit the disk at scales 1e-4 .. 1e5, with no epsilon anywhere;
//! - the area light: each sample's density is `pdf_li`, and E[1/pdf] is the
//!   solid angle of a whole disk, and ∫ pdf_li dω = 1 for a partial one (whose samples, as in
//!   pbrt-v3, cover the whole disk);
//! - a render of a disk light over a matte plane against the analytic
//!   irradiance of a disk at each pixel's point.

mod common;
use common::*;
use glam::{DMat4, DVec3, Vec2, Vec3};
use pbrs::geometry::{offset_ray_origin, Frame};
use pbrs::integrators::RenderScene;
use pbrs::lights::{AreaShape, DiffuseLight, Light};
use pbrs::loader::load_scene_str;
use pbrs::sampling::Pcg32;
use pbrs::shapes::{Analytic, Cylinder, Disk, Placed, SurfacePoint};
use std::f64::consts::PI;
use std::path::Path;

/// Height 0.5, radius 2, inner radius 0.5, φmax 270°, moved by (1, 2, 3).
fn ring() -> Disk {
    Disk::new(Placed::new(
        (0.5, 2.0, 0.5, 270.0),
        DMat4::from_translation(DVec3::new(1.0, 2.0, 3.0)),
        false,
        0,
    ))
}

#[test]
fn disk_hits_where_the_plane_and_the_annulus_say() {
    let d = ring();
    let off = Vec3::new(1.0, 2.0, 3.0);
    // Straight down through (r, φ) = (1.2, 30°) from z = 5 (object space).
    let (x, y) = (
        1.2 * 30f32.to_radians().cos(),
        1.2 * 30f32.to_radians().sin(),
    );
    let o = off + Vec3::new(x, y, 5.0);
    let (t, p) = d.intersect(o, -Vec3::Z, f32::INFINITY).expect("hit");
    assert!((t - 4.5).abs() < 1e-5, "t {t}");
    assert_eq!(p.point_and_error().0.z, 0.5);
    let sp = d.surface_point(p);
    assert!((sp.p - (off + Vec3::new(x, y, 0.5))).length() < 1e-5);
    assert_eq!(sp.n, Vec3::Z);
    let g = d.diff_geom(p);
    assert!((g.uv.x - 30.0 / 270.0).abs() < 1e-5, "u {}", g.uv.x);
    assert!((g.uv.y - (2.0 - 1.2) / 1.5).abs() < 1e-5, "v {}", g.uv.y);
    assert!(g.dpdu.cross(g.dpdv).normalize().dot(sp.n) > 0.999);
    assert_eq!((g.dndu, g.dndv), (Vec3::ZERO, Vec3::ZERO));
    // An oblique ray from below hits too, at the same place.
    let dir = Vec3::new(0.3, -0.2, 1.0).normalize();
    let target = off + Vec3::new(x, y, 0.5);
    let (t2, _) = d
        .intersect(target - 3.0 * dir, dir, f32::INFINITY)
        .expect("hit from below");
    assert!((t2 - 3.0).abs() < 1e-5);
    // t_max before the plane: no hit.
    assert!(d.intersect(o, -Vec3::Z, 4.4).is_none());
    let down = |r: f32, phi_deg: f32| {
        let (s, c) = phi_deg.to_radians().sin_cos();
        d.intersect(off + Vec3::new(r * c, r * s, 5.0), -Vec3::Z, f32::INFINITY)
    };
    assert!(down(0.3, 45.0).is_none(), "through the hole");
    assert!(down(0.55, 45.0).is_some(), "just outside the hole");
    assert!(down(2.05, 45.0).is_none(), "past the rim");
    assert!(down(1.95, 45.0).is_some(), "inside the rim");
    assert!(down(1.0, 300.0).is_none(), "in the cut-out sector");
    assert!(down(1.0, 265.0).is_some(), "just inside φmax");
    // Parallel to the plane, and pointing away from it.
    assert!(d
        .intersect(off + Vec3::new(-3.0, 0.5, 0.5), Vec3::X, f32::INFINITY)
        .is_none());
    assert!(d.intersect(o, Vec3::Z, f32::INFINITY).is_none());
    // Area: φmax/2 · (r² − ri²).
    let want = 0.5 * 1.5 * PI * (4.0 - 0.25);
    assert!((d.area() as f64 - want).abs() < 1e-5 * want);
    // A rotated, scaled, mirrored disk: the area scales by the Jacobian, and
    // the normal follows pbrt-v3's rules (the handedness flip), which make it
    // the cross product of the world-space dp/du and dp/dv.
    let m = DMat4::from_rotation_x(0.7) * DMat4::from_scale(DVec3::new(-2.0, 3.0, 1.0));
    let d2 = Disk::new(Placed::new((0.0, 1.0, 0.0, 360.0), m, false, 0));
    assert!((d2.area() as f64 - 6.0 * PI).abs() < 1e-5 * 6.0 * PI);
    let (_, p) = d2
        .intersect(Vec3::new(0.1, 3.0, 0.1), -Vec3::Y, f32::INFINITY)
        .unwrap();
    let n_plane = m
        .transform_vector3(DVec3::X)
        .cross(m.transform_vector3(DVec3::Y));
    let n = d2.surface_point(p).n.as_dvec3();
    assert!(
        (n - n_plane.normalize()).length() < 1e-5,
        "{n} vs {n_plane}"
    );
    let g = d2.diff_geom(p);
    let n_uv = g.dpdu.cross(g.dpdv).normalize().as_dvec3();
    assert!((n - n_uv).length() < 1e-5, "{n} vs {n_uv}");
}

#[test]
fn rays_leaving_a_disk_do_not_rehit_it_at_any_scale() {
    let mut rng = Pcg32::with_sequence(7);
    for scale in [1e-4f64, 1e-2, 1.0, 1e3, 1e5] {
        let m = DMat4::from_translation(DVec3::new(0.3, -0.2, 0.7) * scale)
            * DMat4::from_rotation_y(0.4)
            * DMat4::from_rotation_x(-1.1)
            * DMat4::from_scale(DVec3::splat(scale));
        let d = Disk::new(Placed::new((0.25, 1.0, 0.1, 360.0), m, false, 0));
        for i in 0..4000 {
            let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
            let s = d.sample_area(u).expect("a sample").point;
            // A direction at a random grazing-to-normal angle on either side.
            let f = Frame::from_normal(s.n);
            let side = if i % 2 == 0 { 1.0 } else { -1.0 };
            let cos = 1e-3 + rng.uniform_f32() * 0.999;
            let sin = (1.0 - cos * cos).sqrt();
            let phi = rng.uniform_f32() * std::f32::consts::TAU;
            let w = f.from_local(Vec3::new(sin * phi.cos(), sin * phi.sin(), side * cos));
            let o = offset_ray_origin(s.p, s.p_error, s.n, w);
            assert!(
                d.intersect(o, w, f32::INFINITY).is_none(),
                "scale {scale}, sample {i}: re-hit"
            );
            // The true point lies inside its error box.
            assert!(s.p_error.is_finite() && s.p_error.max_element() > 0.0);
        }
    }
}

fn scene_text(disk: &str, floor: bool, integrator: &str) -> String {
    let floor = if floor {
        "Material \"matte\" \"rgb Kd\" [0.5 0.5 0.5]\nShape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] \"point P\" [-10 0 -10 10 0 -10 10 0 10 -10 0 10]\n"
    } else {
        ""
    };
    format!(
        "LookAt 0 0.6 0  0 0 0  0 0 1\nCamera \"perspective\" \"float fov\" [30]\n\
         Film \"image\" \"integer xresolution\" [32] \"integer yresolution\" [32]\n\
         Sampler \"halton\" \"integer pixelsamples\" [16]\n{integrator}\nWorldBegin\n\
         AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [2 2 2]\nMaterial \"matte\" \"rgb Kd\" [0 0 0]\n\
         Translate 0 1 0\nRotate 90 1 0 0\n{disk}\nAttributeEnd\n{floor}WorldEnd\n"
    )
}

fn disk_light_scene(disk: &str) -> RenderScene {
    let text = scene_text(disk, false, "Integrator \"directlighting\"");
    let l = load_scene_str(&text, Path::new("mem.pbrt")).unwrap_or_else(|f| panic!("{f:?}"));
    RenderScene::new(&l.scene)
}

fn at(p: Vec3) -> SurfacePoint {
    SurfacePoint {
        p,
        p_error: Vec3::ZERO,
        n: Vec3::ZERO,
        ns: Vec3::ZERO,
    }
}

fn the_light(sc: &RenderScene) -> &Light {
    let l = &sc.lights[0];
    assert!(matches!(
        l,
        Light::Diffuse(DiffuseLight {
            shape: AreaShape::Analytic(_),
            ..
        })
    ));
    l
}

/// Sampling against the density without a direction-space chi-square (its
/// adaptive quadrature of the pdf takes minutes on the disk's rim): the
/// density reported with each sample is `pdf_li` of its direction, and the
/// mean of 1/pdf over samples is the disk's solid angle, known in closed
/// form on its axis (and by that density's own estimate off it).
#[test]
fn disk_light_sampling_matches_its_density() {
    let radius = 0.4f64;
    let sc = disk_light_scene("Shape \"disk\" \"float radius\" [0.4]");
    let light = the_light(&sc);
    let h = 0.7f64;
    let r = at(Vec3::new(0.0, (1.0 - h) as f32, 0.0));
    let mut rng = Pcg32::with_sequence(11);
    let n = 400_000;
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
        let s = light.sample_li(&r, u, &sc.aggregate).expect("a sample");
        let pdf = light.pdf_li(&r, s.wi, &sc.aggregate);
        assert!(
            (pdf - s.pdf).abs() <= 1e-3 * s.pdf,
            "sampled density {} vs pdf_li {pdf}",
            s.pdf
        );
        let inv = 1.0 / s.pdf as f64;
        sum += inv;
        sum2 += inv * inv;
    }
    let mean = sum / n as f64;
    let se = ((sum2 / n as f64 - mean * mean) / n as f64).sqrt();
    let omega = 2.0 * PI * (1.0 - h / (h * h + radius * radius).sqrt());
    println!("E[1/pdf] = {mean} ± {se}, solid angle {omega}");
    assert!(
        (mean - omega).abs() < 4.0 * se + 1e-4 * omega,
        "{mean} vs {omega}"
    );
}

/// For a partial disk pbrt-v3 samples the whole disk, so sampling and
/// density differ; the density alone still integrates to one over the
/// directions that see the partial disk (Monte Carlo over the sphere).
#[test]
fn partial_disk_density_integrates_to_one() {
    let sc = disk_light_scene(
        "Shape \"disk\" \"float radius\" [0.4] \"float innerradius\" [0.15] \"float phimax\" [200]",
    );
    let light = the_light(&sc);
    let r = at(Vec3::new(0.1, 0.6, -0.05));
    let mut rng = Pcg32::with_sequence(3);
    let n = 2_000_000;
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let z = 1.0 - 2.0 * rng.uniform_f32();
        let phi = rng.uniform_f32() * std::f32::consts::TAU;
        let s = (1.0 - z * z).max(0.0).sqrt();
        let w = Vec3::new(s * phi.cos(), s * phi.sin(), z);
        let f = light.pdf_li(&r, w, &sc.aggregate) as f64 * 4.0 * PI;
        sum += f;
        sum2 += f * f;
    }
    let mean = sum / n as f64;
    let se = ((sum2 / n as f64 - mean * mean) / n as f64).sqrt();
    println!("∫ pdf dω = {mean} ± {se}");
    assert!((mean - 1.0).abs() < 4.0 * se + 1e-3, "{mean} ± {se}");
}

/// Irradiance at a point at distance `h` below the plane of a disk of radius
/// `r` and radiance `l`, `rho` off its axis (the plane facing the disk).
fn disk_irradiance(l: f64, r: f64, h: f64, rho: f64) -> f64 {
    let a = h * h + rho * rho;
    0.5 * PI * l * (1.0 - (a - r * r) / ((a + r * r).powi(2) - 4.0 * r * r * rho * rho).sqrt())
}

#[test]
fn disk_light_over_a_plane_gives_the_analytic_irradiance() {
    let radius = 0.5;
    let text = scene_text(
        &format!("Shape \"disk\" \"float radius\" [{radius}]"),
        true,
        "Integrator \"directlighting\" \"integer maxdepth\" [1]",
    );
    let l = load_scene_str(&text, Path::new("mem.pbrt")).unwrap_or_else(|f| panic!("{f:?}"));
    let (img, _) = render_seeded(l.scene, 32, 64, 5);
    // The camera at height 0.6 looks straight down; the pixel (i, j) centre
    // sees the floor at (x, z) = 0.6·tan(fov/2)·(screen coordinates).
    let half = 0.6 * (15f64).to_radians().tan();
    let (mut err2, mut want2) = (0.0, 0.0);
    let mut worst: f64 = 0.0;
    for j in 0..32 {
        for i in 0..32 {
            let sx = (i as f64 + 0.5) / 16.0 - 1.0;
            let sy = (j as f64 + 0.5) / 16.0 - 1.0;
            let rho = half * (sx * sx + sy * sy).sqrt();
            let want = 0.5 / PI * disk_irradiance(2.0, radius, 1.0, rho);
            let got = img.data[3 * (j * 32 + i)] as f64;
            err2 += (got - want).powi(2);
            want2 += want * want;
            worst = worst.max(((got - want) / want).abs());
        }
    }
    let rel = (err2 / want2).sqrt();
    println!("disk light over a plane: relative RMS error {rel:.5}, worst pixel {worst:.4}");
    assert!(rel < 0.01, "relative RMS error {rel}");
    assert!(worst < 0.04, "worst pixel {worst}");
}

/// Radius 0.5, z in [-1, 2], φmax 300°, moved by (1, 2, 3).
fn tube() -> Cylinder {
    Cylinder::new(Placed::new(
        (0.5, -1.0, 2.0, 300.0),
        DMat4::from_translation(DVec3::new(1.0, 2.0, 3.0)),
        false,
        0,
    ))
}

#[test]
fn cylinder_hits_where_the_tube_says() {
    let c = tube();
    let off = Vec3::new(1.0, 2.0, 3.0);
    // From outside along -x at z = 0.5, y = 0.3: hits x = sqrt(0.25 - 0.09) = 0.4.
    let (t, p) = c
        .intersect(off + Vec3::new(5.0, 0.3, 0.5), -Vec3::X, f32::INFINITY)
        .expect("hit");
    assert!((t - 4.6).abs() < 1e-5, "t {t}");
    let sp = c.surface_point(p);
    assert!(
        (sp.n - Vec3::new(0.8, 0.6, 0.0)).length() < 1e-5,
        "{}",
        sp.n
    );
    let g = c.diff_geom(p);
    let phi = 0.6f32.atan2(0.8);
    assert!((g.uv.x - phi / 300f32.to_radians()).abs() < 1e-5);
    assert!((g.uv.y - 0.5).abs() < 1e-5);
    assert!(g.dpdu.cross(g.dpdv).normalize().dot(sp.n) > 0.999);
    // dn/du = dp/du / radius (the normal turns with φ).
    assert!((g.dndu - g.dpdu / 0.5).length() < 1e-4);
    // From the axis (inside), the far side only.
    let (t, _) = c
        .intersect(off + Vec3::new(0.0, 0.0, 0.5), Vec3::X, f32::INFINITY)
        .expect("from inside");
    assert!((t - 0.5).abs() < 1e-6);
    // Above zmax, in the cut-out sector (φ = 330°), along the axis: misses.
    assert!(c
        .intersect(off + Vec3::new(5.0, 0.3, 2.1), -Vec3::X, f32::INFINITY)
        .is_none());
    let (s, co) = 330f32.to_radians().sin_cos();
    assert!(c
        .intersect(off + Vec3::new(co, s, 0.0), -Vec3::new(co, s, 0.0), 0.6)
        .is_none());
    assert!(c.intersect(off, Vec3::Z, f32::INFINITY).is_none());
    let want = 3.0 * 0.5 * 300f64.to_radians();
    assert!((c.area() as f64 - want).abs() < 1e-5 * want);
}

#[test]
fn rays_leaving_a_cylinder_do_not_rehit_it_at_any_scale() {
    let mut rng = Pcg32::with_sequence(8);
    for scale in [1e-4f64, 1e-2, 1.0, 1e3, 1e5] {
        let m = DMat4::from_translation(DVec3::new(0.3, -0.2, 0.7) * scale)
            * DMat4::from_rotation_y(0.4)
            * DMat4::from_rotation_x(-1.1)
            * DMat4::from_scale(DVec3::splat(scale));
        let c = Cylinder::new(Placed::new((1.0, -0.5, 0.5, 360.0), m, false, 0));
        for i in 0..4000 {
            let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
            let s = c.sample_area(u).expect("a sample").point;
            // Outwards (any angle) must miss; inwards must hit the far side,
            // never this side again (t well above the error bound).
            let f = Frame::from_normal(s.n);
            let cos = 1e-3 + rng.uniform_f32() * 0.999;
            let sin = (1.0 - cos * cos).sqrt();
            let phi = rng.uniform_f32() * std::f32::consts::TAU;
            let w = f.from_local(Vec3::new(sin * phi.cos(), sin * phi.sin(), cos));
            let o = offset_ray_origin(s.p, s.p_error, s.n, w);
            assert!(
                c.intersect(o, w, f32::INFINITY).is_none(),
                "scale {scale}, sample {i}: re-hit going out"
            );
            let w_in = -s.n;
            let o = offset_ray_origin(s.p, s.p_error, s.n, w_in);
            let (t, _) = c.intersect(o, w_in, f32::INFINITY).expect("far side");
            assert!(
                (t as f64 - 2.0 * scale).abs() < 1e-3 * scale,
                "scale {scale}: t {t}"
            );
        }
    }
}

#[test]
fn cylinder_light_sampling_matches_its_density() {
    let (r, zmin, zmax) = (0.4f64, -0.5f64, 0.3f64);
    let sc = disk_light_scene(&format!(
        "Shape \"cylinder\" \"float radius\" [{r}] \"float zmin\" [{zmin}] \"float zmax\" [{zmax}]"
    ));
    let light = the_light(&sc);
    // Object (0, 0, 0) on the axis is world (0, 1, 0).
    let p = at(Vec3::new(0.0, 1.0, 0.0));
    let mut rng = Pcg32::with_sequence(12);
    let n = 400_000;
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
        let s = light.sample_li(&p, u, &sc.aggregate).expect("a sample");
        let pdf = light.pdf_li(&p, s.wi, &sc.aggregate);
        assert!((pdf - s.pdf).abs() <= 1e-3 * s.pdf, "{} vs {pdf}", s.pdf);
        let inv = 1.0 / s.pdf as f64;
        sum += inv;
        sum2 += inv * inv;
    }
    let mean = sum / n as f64;
    let se = ((sum2 / n as f64 - mean * mean) / n as f64).sqrt();
    let omega =
        2.0 * PI * (zmax / (zmax * zmax + r * r).sqrt() - zmin / (zmin * zmin + r * r).sqrt());
    println!("cylinder: E[1/pdf] = {mean} ± {se}, solid angle {omega}");
    assert!(
        (mean - omega).abs() < 4.0 * se + 1e-4 * omega,
        "{mean} vs {omega}"
    );
}
