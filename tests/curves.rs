//! pbrt-v3's `curve` shape: hits against the known centre line of straight
//! curves (t, point, u, v across the width), each type's normal convention
//! (flat: along the ray; cylinder: swept about dp/du across v; ribbon: the
//! slerped end normals `N`), b-spline input converted to the Bézier span
//! pbrt-v3 gives it, no NaN on grazing rays, and located errors for bad input.

mod common;
use common::*;
use glam::Vec3;
use pbrs::geometry::Ray;
use pbrs::integrators::RenderScene;
use pbrs::loader::load_scene_str;
use pbrs::sampling::Pcg32;
use pbrs::shapes::{DiffGeom, SurfacePoint};

fn load_text(text: &str) -> Result<pbrs::loader::LoadedScene, pbrs::loader::LoadFailure> {
    load_scene_str(text, &repo().join("scenes/curve-test.pbrt"))
}

fn scene(shape: &str) -> RenderScene {
    let s = load_text(&format!("WorldBegin\n{shape}\nWorldEnd\n"))
        .unwrap_or_else(|f| panic!("{shape}: {f:?}"));
    assert!(s.warnings.is_empty(), "{shape}: {:?}", s.warnings);
    RenderScene::new(&s.scene)
}

struct Found {
    t: f32,
    point: SurfacePoint,
    geom: DiffGeom,
}

fn trace(sc: &RenderScene, o: Vec3, d: Vec3) -> Option<Found> {
    let ray = Ray {
        o,
        d,
        t_max: f32::INFINITY,
    };
    let hit = sc.aggregate.intersect(&ray)?;
    let s = sc.aggregate.surface(&hit);
    let geom = sc.aggregate.diff_geom(&hit, &s);
    Some(Found {
        t: hit.t,
        point: s.point,
        geom,
    })
}

/// A straight curve along x from -1 to 1 with evenly spaced control points
/// (so u = (x + 1) / 2), width 0.2.
const LINE: &str = "\"point P\" [-1 0 0  -0.3333333 0 0  0.3333333 0 0  1 0 0] \"float width\" 0.2";

#[test]
fn flat_curve_hits_on_its_centre_line_within_half_its_width() {
    let sc = scene(&format!("Shape \"curve\" {LINE}"));
    for (x, y) in [(0.3f32, 0.05f32), (-0.6, -0.02), (0.0, 0.0), (0.8, 0.095)] {
        let f = trace(&sc, Vec3::new(x, y, 5.0), -Vec3::Z).expect("hit");
        assert!((f.t - 5.0).abs() < 1e-4, "t {}", f.t);
        assert!(
            (f.point.p - Vec3::new(x, y, 0.0)).length() < 1e-4,
            "{:?}",
            f.point.p
        );
        assert!(
            (f.geom.uv.x - (x + 1.0) / 2.0).abs() < 2e-3,
            "u {}",
            f.geom.uv.x
        );
        // v is 0.5 on the centre line and moves by the offset over the width.
        let dv = (f.geom.uv.y - 0.5).abs();
        assert!(
            (dv - y.abs() / 0.2).abs() < 2e-3,
            "v {} at y {y}",
            f.geom.uv.y
        );
        // pbrt-v3's flat normal: dp/du × dp/dv with dp/dv = d̂ × dp/du, so it
        // points along the ray.
        assert!(f.point.n.dot(-Vec3::Z) > 0.999, "n {:?}", f.point.n);
        assert!(f.geom.dpdu.normalize().dot(Vec3::X) > 0.999);
        assert!(
            (f.geom.dpdv.length() - 0.2).abs() < 1e-4,
            "|dp/dv| is the width"
        );
        // The error bound is 2·width per axis (and more from the transform).
        assert!(f.point.p_error.min_element() >= 0.4);
    }
    // v is mirrored across the centre line.
    let a = trace(&sc, Vec3::new(0.2, 0.05, 5.0), -Vec3::Z).unwrap();
    let b = trace(&sc, Vec3::new(0.2, -0.05, 5.0), -Vec3::Z).unwrap();
    assert!((a.geom.uv.y + b.geom.uv.y - 1.0).abs() < 1e-3);
    // Past half the width, past the ends, or behind the origin: no hit.
    for o in [
        Vec3::new(0.3, 0.105, 5.0),
        Vec3::new(0.3, -0.12, 5.0),
        Vec3::new(1.05, 0.0, 5.0),
        Vec3::new(-1.05, 0.0, 5.0),
    ] {
        assert!(trace(&sc, o, -Vec3::Z).is_none(), "{o}");
    }
    assert!(trace(&sc, Vec3::new(0.3, 0.0, -1.0), -Vec3::Z).is_none());
}

#[test]
fn width_varies_from_width0_to_width1() {
    let sc = scene(
        "Shape \"curve\" \"point P\" [-1 0 0  -0.3333333 0 0  0.3333333 0 0  1 0 0] \"float width0\" 0.4 \"float width1\" 0.1",
    );
    // At x = -0.5 (u = 0.25) the width is 0.325; at x = 0.5 it is 0.175.
    assert!(trace(&sc, Vec3::new(-0.5, 0.15, 5.0), -Vec3::Z).is_some());
    assert!(trace(&sc, Vec3::new(-0.5, 0.17, 5.0), -Vec3::Z).is_none());
    assert!(trace(&sc, Vec3::new(0.5, 0.08, 5.0), -Vec3::Z).is_some());
    assert!(trace(&sc, Vec3::new(0.5, 0.095, 5.0), -Vec3::Z).is_none());
}

#[test]
fn cylinder_curve_normal_sweeps_across_the_tube() {
    let sc = scene(&format!(
        "Shape \"curve\" \"string type\" \"cylinder\" {LINE}"
    ));
    for y in [0.0f32, 0.03, -0.05, 0.07, -0.09, 0.098] {
        let f = trace(&sc, Vec3::new(0.1, y, 5.0), -Vec3::Z).expect("hit");
        let n = f.point.n;
        assert!(n.dot(f.geom.dpdu.normalize()).abs() < 1e-3, "n ⟂ dp/du");
        // θ from -90° to 90° across v, as pbrt-v3 rotates dp/dv.
        let theta = (f.geom.uv.y - 0.5) * std::f32::consts::PI;
        assert!(
            (n.y.abs() - theta.sin().abs()).abs() < 2e-3,
            "y {y}: n {n}, v {}",
            f.geom.uv.y
        );
        assert!((n.z.abs() - theta.cos()).abs() < 2e-3, "y {y}: n {n}");
        // Towards the edges the normal points out of the tube, towards the
        // side of the centre line the ray passed on.
        if y.abs() > 0.02 {
            assert!(n.y * y > 0.0, "y {y}: n {n}");
        }
        // On the centre line it is the flat curve's: along the ray (pbrt-v3's
        // orientation; its BSDFs are two-sided).
        if y == 0.0 {
            assert!(n.dot(-Vec3::Z) > 0.999, "n {n}");
        }
    }
}

#[test]
fn ribbon_normal_follows_n() {
    // Parallel end normals: a strip in the z = 0 plane.
    let sc = scene(&format!(
        "Shape \"curve\" \"string type\" \"ribbon\" {LINE} \"normal N\" [0 0 1  0 0 1]"
    ));
    let f = trace(&sc, Vec3::new(0.4, 0.05, 3.0), -Vec3::Z).expect("hit");
    assert!(f.point.n.cross(Vec3::Z).length() < 1e-4, "n {}", f.point.n);
    // Seen at 60° from its normal it looks half as wide, so rays through
    // its plane hit exactly within the strip, |y| < 0.1; a flat curve, which
    // always faces the ray, is hit farther out.
    let d = Vec3::new(0.0, 60f32.to_radians().sin(), -60f32.to_radians().cos());
    let at = |y: f32| Vec3::new(0.4, y, 0.0) - 3.0 * d;
    assert!(trace(&sc, at(0.09), d).is_some());
    assert!(trace(&sc, at(-0.09), d).is_some());
    assert!(trace(&sc, at(0.11), d).is_none());
    let flat = scene(&format!("Shape \"curve\" {LINE}"));
    assert!(trace(&flat, at(0.11), d).is_some());

    // A strip in the y = 0 plane, seen edge-on from above: nothing to hit.
    let edge = scene(&format!(
        "Shape \"curve\" \"string type\" \"ribbon\" {LINE} \"normal N\" [0 1 0  0 1 0]"
    ));
    assert!(trace(&edge, Vec3::new(0.4, 0.0, 3.0), -Vec3::Z).is_none());

    // Twisting from z at u = 0 to y at u = 1: (0, 1, 1)/√2 half way.
    let tw = scene(&format!(
        "Shape \"curve\" \"string type\" \"ribbon\" {LINE} \"normal N\" [0 0 1  0 1 0]"
    ));
    let n_mid = Vec3::new(0.0, 1.0, 1.0).normalize();
    let f = trace(&tw, Vec3::new(0.0, 0.0, 0.0) + 3.0 * n_mid, -n_mid).expect("hit");
    assert!(f.point.n.cross(n_mid).length() < 2e-3, "n {}", f.point.n);
    assert!((f.geom.uv.x - 0.5).abs() < 2e-3);
    assert!(
        f.geom.dpdv.dot(n_mid).abs() < 1e-3,
        "dp/dv lies in the ribbon"
    );
}

#[test]
fn bspline_and_degree_2_spans_are_pbrt_v3s() {
    // A uniform cubic b-spline over x = 0, 1, 2, 3 spans x in [1, 2].
    let sc = scene(
        "Shape \"curve\" \"string basis\" \"bspline\" \"point P\" [0 0 0  1 0 0  2 0 0  3 0 0] \"float width\" 0.1",
    );
    for (x, hit) in [(0.95f32, false), (1.05, true), (1.95, true), (2.05, false)] {
        let f = trace(&sc, Vec3::new(x, 0.0, 2.0), -Vec3::Z);
        assert_eq!(f.is_some(), hit, "x {x}");
    }
    // A quadratic one over 0, 1, 2 spans [0.5, 1.5].
    let q = scene(
        "Shape \"curve\" \"string basis\" \"bspline\" \"integer degree\" 2 \"point P\" [0 0 0  1 0 0  2 0 0] \"float width\" 0.1",
    );
    for (x, hit) in [(0.45f32, false), (0.55, true), (1.45, true), (1.55, false)] {
        assert_eq!(
            trace(&q, Vec3::new(x, 0.0, 2.0), -Vec3::Z).is_some(),
            hit,
            "x {x}"
        );
    }
    // Two quadratic Bézier segments share their middle point: x in [0, 4],
    // and a bend at (2, 1) the curve passes under (it touches y = 0.5 at
    // x = 1 and 3).
    let b = scene(
        "Shape \"curve\" \"integer degree\" 2 \"point P\" [0 0 0  1 1 0  2 0 0  3 -1 0  4 0 0] \"float width\" 0.1",
    );
    assert!(trace(&b, Vec3::new(1.0, 0.5, 2.0), -Vec3::Z).is_some());
    assert!(trace(&b, Vec3::new(3.0, -0.5, 2.0), -Vec3::Z).is_some());
    assert!(trace(&b, Vec3::new(1.0, 0.0, 2.0), -Vec3::Z).is_none());
}

fn finite(f: &Found) -> bool {
    let g = &f.geom;
    f.t.is_finite()
        && f.point.p.is_finite()
        && f.point.p_error.is_finite()
        && f.point.n.is_finite()
        && (f.point.n.length() - 1.0).abs() < 1e-3
        && g.uv.is_finite()
        && g.dpdu.is_finite()
        && g.dpdv.is_finite()
}

#[test]
fn grazing_and_tangent_rays_give_no_nan() {
    let curved = "\"point P\" [-1 0 0  -0.3 1 0.5  0.3 -1 -0.5  1 0 0] \"float width0\" 0.2 \"float width1\" 0.02";
    for ty in ["flat", "cylinder", "ribbon"] {
        let n = if ty == "ribbon" {
            "\"normal N\" [0 0 1  0 1 0]"
        } else {
            ""
        };
        let sc = scene(&format!(
            "Shape \"curve\" \"string type\" \"{ty}\" {curved} {n}"
        ));
        let mut rng = Pcg32::with_sequence(7);
        let mut hits = 0;
        for i in 0..4000 {
            // Rays through points near the curve, from every direction, and
            // along its chord and end tangents.
            let target = Vec3::new(
                2.2 * rng.uniform_f32() - 1.1,
                2.0 * rng.uniform_f32() - 1.0,
                rng.uniform_f32() - 0.5,
            ) * Vec3::new(1.0, 0.3, 0.3);
            let d = match i % 4 {
                0 => Vec3::X,
                1 => Vec3::new(0.7, 1.0, 0.5).normalize(),
                _ => {
                    let z = 2.0 * rng.uniform_f32() - 1.0;
                    let phi = std::f32::consts::TAU * rng.uniform_f32();
                    let r = (1.0 - z * z).max(0.0).sqrt();
                    Vec3::new(r * phi.cos(), r * phi.sin(), z)
                }
            };
            if let Some(f) = trace(&sc, target - 4.0 * d, d) {
                hits += 1;
                assert!(finite(&f), "{ty}: ray {i}: {:?} {:?}", f.point, f.geom);
            }
        }
        assert!(hits > 100, "{ty}: only {hits} hits");
    }
}

/// The error messages of a scene that must not load.
fn errors(shape: &str) -> String {
    world_errors(&repo().join("scenes/curve-test.pbrt"), shape)
}

#[test]
fn bad_curves_give_located_errors() {
    let p4 = "\"point P\" [0 0 0 1 0 0 2 0 0 3 0 0]";
    for (shape, want) in [
        (
            format!("Shape \"curve\" {p4} \"integer degree\" 4"),
            "degree 4",
        ),
        (
            format!("Shape \"curve\" {p4} \"string basis\" \"nurbs\""),
            "basis \"nurbs\"",
        ),
        (
            "Shape \"curve\" \"point P\" [0 0 0 1 0 0 2 0 0 3 0 0 4 0 0]".to_string(),
            "5 control points",
        ),
        (
            "Shape \"curve\" \"point P\" [0 0 0 1 0 0]".to_string(),
            "2 control points",
        ),
        (
            "Shape \"curve\" \"string basis\" \"bspline\" \"point P\" [0 0 0 1 0 0 2 0 0]"
                .to_string(),
            "at least 4",
        ),
        (
            "Shape \"curve\" \"float width\" 1".to_string(),
            "needs control points",
        ),
        (
            format!("Shape \"curve\" {p4} \"float width\" 0"),
            "must be positive",
        ),
        (
            format!("Shape \"curve\" {p4} \"float width1\" -1"),
            "must be positive",
        ),
        (
            format!("Shape \"curve\" {p4} \"string type\" \"ribbon\""),
            "needs normals",
        ),
        (
            format!("Shape \"curve\" {p4} \"string type\" \"ribbon\" \"normal N\" [0 0 1]"),
            "1 normals",
        ),
        (
            format!("Shape \"curve\" {p4} \"string type\" \"ribbon\" \"normal N\" [0 0 1 0 0 0]"),
            "zero",
        ),
    ] {
        let e = errors(&shape);
        assert!(e.contains(want), "{shape}: {e}");
        assert!(
            e.contains("curve-test.pbrt:2:"),
            "{shape}: not located: {e}"
        );
    }
}

#[test]
fn curve_warnings_keep_the_curve() {
    let p4 = "\"point P\" [0 0 0 1 0 0 2 0 0 3 0 0]";
    for (shape, want) in [
        (
            format!("Shape \"curve\" {p4} \"string type\" \"tube\""),
            "unknown curve type \"tube\"",
        ),
        (
            format!("Shape \"curve\" {p4} \"normal N\" [0 0 1 0 0 1]"),
            "only used by \"ribbon\"",
        ),
        (
            format!(
                "AttributeBegin\nAreaLightSource \"diffuse\"\nShape \"curve\" {p4}\nAttributeEnd"
            ),
            "does not emit",
        ),
    ] {
        let s = load_text(&format!("WorldBegin\n{shape}\nWorldEnd\n"))
            .unwrap_or_else(|f| panic!("{f:?}"));
        assert_eq!(s.scene.shapes.len(), 1, "{shape}");
        let w: Vec<String> = s.warnings.iter().map(|w| format!("{w}")).collect();
        assert!(w.iter().any(|w| w.contains(want)), "{shape}: {w:?}");
        assert!(s.scene.shapes[0].area_light.is_none());
    }
}
