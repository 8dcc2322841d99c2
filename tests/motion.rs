//! Motion blur: pbrt-v3's `AnimatedTransform` (decomposition, interpolation,
//! motion bounds) and the loader's `TransformTimes` / `ActiveTransform`
//! semantics.

use glam::{DMat4, DQuat, DVec3};
use pbrs::loader::load_scene_str;
use pbrs::scene::motion::{decompose, slerp};
use pbrs::scene::AnimatedTransform;
use std::path::Path;

fn close(a: DMat4, b: DMat4, tol: f64) -> bool {
    a.to_cols_array()
        .iter()
        .zip(b.to_cols_array())
        .all(|(x, y)| (x - y).abs() <= tol)
}

#[test]
fn decomposition_reproduces_trs() {
    let t = DVec3::new(1.0, -2.0, 3.5);
    let r = DQuat::from_axis_angle(DVec3::new(1.0, 2.0, -0.5).normalize(), 1.1);
    let s = DVec3::new(2.0, 0.5, 3.0);
    let m = DMat4::from_scale_rotation_translation(s, r, t);
    let d = decompose(&m);
    assert!((d.t - t).length() < 1e-12);
    // q and -q are the same rotation.
    assert!(d.r.dot(r).abs() > 1.0 - 1e-9, "{:?} vs {r:?}", d.r);
    let back = DMat4::from_translation(d.t) * DMat4::from_quat(d.r) * DMat4::from_mat3(d.s);
    assert!(close(back, m, 1e-9));
    // A mirror keeps M = T R S with a proper rotation.
    let mirror = m * DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0));
    let d = decompose(&mirror);
    let back = DMat4::from_translation(d.t) * DMat4::from_quat(d.r) * DMat4::from_mat3(d.s);
    assert!(close(back, mirror, 1e-9));
    assert!(d.r.is_normalized());
}

#[test]
fn halfway_rotation_is_the_slerp() {
    let axis = DVec3::new(0.0, 0.0, 1.0);
    let a = DMat4::from_axis_angle(axis, 0.0);
    let b = DMat4::from_axis_angle(axis, 2.0);
    let at = AnimatedTransform::new(a, 0.0, b, 1.0).expect("animated");
    let half = at.interpolate(0.5);
    assert!(
        close(half, DMat4::from_axis_angle(axis, 1.0), 1e-9),
        "{half:?}"
    );
    let q = at.interpolate(0.25);
    assert!(close(q, DMat4::from_axis_angle(axis, 0.5), 1e-9));
    // Through the shorter way round: 350 degrees from 0 is -10.
    let b = DMat4::from_axis_angle(axis, 350f64.to_radians());
    let at = AnimatedTransform::new(a, 0.0, b, 1.0).unwrap();
    let half = at.interpolate(0.5);
    assert!(close(
        half,
        DMat4::from_axis_angle(axis, -5f64.to_radians()),
        1e-9
    ));
    // The linear branch of slerp for nearly equal rotations stays unit.
    let q0 = DQuat::from_rotation_z(0.0);
    let q1 = DQuat::from_rotation_z(0.01);
    let qh = slerp(0.5, q0, q1);
    assert!(qh.is_normalized());
    assert!(qh.dot(DQuat::from_rotation_z(0.005)) > 1.0 - 1e-9);
}

#[test]
fn translation_and_scale_lerp_between_the_times() {
    let a = DMat4::from_translation(DVec3::new(0.0, 0.0, 0.0));
    let b = DMat4::from_scale_rotation_translation(
        DVec3::splat(3.0),
        DQuat::IDENTITY,
        DVec3::new(4.0, 0.0, 0.0),
    );
    let at = AnimatedTransform::new(a, 2.0, b, 4.0).unwrap();
    let m = at.interpolate(3.0);
    let want = DMat4::from_scale_rotation_translation(
        DVec3::splat(2.0),
        DQuat::IDENTITY,
        DVec3::new(2.0, 0.0, 0.0),
    );
    assert!(close(m, want, 1e-12));
    // Clamped outside, exact at the keyframes.
    assert_eq!(at.interpolate(-10.0), a);
    assert_eq!(at.interpolate(2.0), a);
    assert_eq!(at.interpolate(4.0), b);
    assert_eq!(at.interpolate(9.0), b);
    assert_eq!(at.interpolate(f64::NAN), a);
    assert!(AnimatedTransform::new(a, 0.0, a, 1.0).is_none());
}

/// Deterministic pseudo-random numbers in [0, 1).
fn lcg(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*state >> 11) as f64 / (1u64 << 53) as f64
}

/// `inverse_at` (built from the interpolated parts, with the fixed part of
/// a translation or a turn precomputed) inverts `interpolate` at every time,
/// for each kind of motion: translation, turn and translation, scale change.
#[test]
fn inverse_at_inverts_the_interpolated_transform() {
    let a = DMat4::from_scale_rotation_translation(
        DVec3::new(1.0, 2.0, 0.5),
        DQuat::from_rotation_x(0.3),
        DVec3::new(1.0, 1.0, 1.0),
    );
    let cases = [
        (a, DMat4::from_translation(DVec3::new(0.0, 3.0, -1.0)) * a),
        (a, a * DMat4::from_rotation_y(2.0)),
        (
            a,
            DMat4::from_scale_rotation_translation(
                DVec3::new(0.2, 1.0, 3.0),
                DQuat::from_axis_angle(DVec3::new(1.0, 1.0, 0.0).normalize(), 3.0),
                DVec3::new(-2.0, 4.0, 0.0),
            ),
        ),
        (a, a * DMat4::from_rotation_z(0.01)),
    ];
    for (k, (a, b)) in cases.into_iter().enumerate() {
        let at = AnimatedTransform::new(a, 0.5, b, 2.0).unwrap();
        for time in [-1.0, 0.5, 0.6, 1.0, 1.25, 1.9, 2.0, 3.0] {
            let p = at.inverse_at(time) * at.interpolate(time);
            assert!(
                close(p, DMat4::IDENTITY, 1e-12),
                "case {k} at {time}: {p:?}"
            );
        }
    }
}

#[test]
fn motion_bounds_contain_the_box_at_every_time() {
    let mut rng = 7u64;
    let cases = [
        // A big rotation about an axis far from the box: the arc bulges out
        // of the union of the two end boxes.
        (
            DMat4::from_translation(DVec3::new(5.0, 0.0, 0.0)),
            DMat4::from_rotation_z(2.5) * DMat4::from_translation(DVec3::new(5.0, 0.0, 0.0)),
        ),
        (
            DMat4::from_scale_rotation_translation(
                DVec3::new(1.0, 2.0, 0.5),
                DQuat::from_rotation_x(0.3),
                DVec3::new(1.0, 1.0, 1.0),
            ),
            DMat4::from_scale_rotation_translation(
                DVec3::new(0.2, 1.0, 3.0),
                DQuat::from_axis_angle(DVec3::new(1.0, 1.0, 0.0).normalize(), 3.0),
                DVec3::new(-2.0, 4.0, 0.0),
            ),
        ),
        // Translation only.
        (
            DMat4::IDENTITY,
            DMat4::from_translation(DVec3::new(0.0, 10.0, 0.0)),
        ),
        // Nearly equal rotations (the linear slerp branch).
        (
            DMat4::from_translation(DVec3::new(100.0, 0.0, 0.0)),
            DMat4::from_rotation_z(0.02) * DMat4::from_translation(DVec3::new(100.0, 0.0, 0.0)),
        ),
    ];
    let lo = DVec3::new(-1.0, -0.5, -2.0);
    let hi = DVec3::new(1.0, 0.5, 0.0);
    for (a, b) in cases {
        let at = AnimatedTransform::new(a, 0.0, b, 1.0).unwrap();
        let (bmin, bmax) = at.motion_bounds(lo, hi);
        let mut grew = false;
        for _ in 0..20000 {
            let t = lcg(&mut rng);
            let p = lo + (hi - lo) * DVec3::new(lcg(&mut rng), lcg(&mut rng), lcg(&mut rng));
            let w = at.interpolate(t).transform_point3(p);
            assert!(
                w.cmpge(bmin).all() && w.cmple(bmax).all(),
                "{w:?} at t={t} outside {bmin:?}..{bmax:?}"
            );
            let e0 = a.transform_point3(p);
            let e1 = b.transform_point3(p);
            grew |= w.cmplt(e0.min(e1)).any() || w.cmpgt(e0.max(e1)).any();
        }
        let _ = grew;
        // Not wildly loose: within the box of the sweep's sampled extent
        // padded by 5% of the diagonal.
        let mut smin = DVec3::splat(f64::INFINITY);
        let mut smax = DVec3::splat(f64::NEG_INFINITY);
        for i in 0..=2000 {
            let m = at.interpolate(i as f64 / 2000.0);
            for c in 0..8 {
                let p = DVec3::new(
                    if c & 1 == 0 { lo.x } else { hi.x },
                    if c & 2 == 0 { lo.y } else { hi.y },
                    if c & 4 == 0 { lo.z } else { hi.z },
                );
                let w = m.transform_point3(p);
                smin = smin.min(w);
                smax = smax.max(w);
            }
        }
        let slack = 0.05 * (smax - smin).length();
        assert!(
            (smin - bmin).max_element() <= slack && (bmax - smax).max_element() <= slack,
            "bounds {bmin:?}..{bmax:?} much larger than the sweep {smin:?}..{smax:?}"
        );
    }
}

const SCENE_HEAD: &str = r#"
LookAt 0 0 5  0 0 0  0 1 0
Camera "perspective"
Film "image" "integer xresolution" 8 "integer yresolution" 8
"#;

fn load(text: &str) -> pbrs::loader::LoadedScene {
    load_scene_str(text, Path::new("motion-test.pbrt")).unwrap_or_else(|f| {
        panic!(
            "{:?}",
            f.errors.iter().map(|e| e.to_string()).collect::<Vec<_>>()
        )
    })
}

#[test]
fn active_transform_edits_only_the_selected_ctm() {
    let text = format!(
        "TransformTimes 0.25 0.75\n{SCENE_HEAD}WorldBegin
ActiveTransform StartTime
Translate 1 0 0
ActiveTransform EndTime
Translate 0 2 0
ActiveTransform All
Scale 2 2 2
Shape \"sphere\"
AttributeBegin
  ActiveTransform EndTime
AttributeEnd
Translate 0 0 1
Shape \"sphere\"
ActiveTransform StartTime
Translate -0.5 1 0
ActiveTransform All
Shape \"sphere\"
WorldEnd
"
    );
    let s = load(&text).scene;
    assert_eq!(s.shapes.len(), 3);
    let start =
        DMat4::from_translation(DVec3::new(1.0, 0.0, 0.0)) * DMat4::from_scale(DVec3::splat(2.0));
    let end =
        DMat4::from_translation(DVec3::new(0.0, 2.0, 0.0)) * DMat4::from_scale(DVec3::splat(2.0));
    let m = s.shapes[0].motion.as_ref().expect("animated");
    assert_eq!(s.shapes[0].object_to_world, start);
    assert_eq!(m.start, start);
    assert_eq!(m.end, end);
    assert_eq!((m.start_time, m.end_time), (0.25, 0.75));
    // AttributeEnd restored "All": the translate moved both.
    let m1 = s.shapes[1].motion.as_ref().expect("animated");
    let tz = DMat4::from_translation(DVec3::new(0.0, 0.0, 1.0));
    assert_eq!(m1.start, start * tz);
    assert_eq!(m1.end, end * tz);
    // The start caught up with the end (exactly, in binary): the CTMs
    // agree again, a static shape.
    let last = &s.shapes[2];
    assert!(
        last.motion.is_none(),
        "equal transforms must give a static shape: {:?}",
        last.motion
    );
}

#[test]
fn static_scene_has_no_motion() {
    let text = format!(
        "{SCENE_HEAD}WorldBegin
ObjectBegin \"o\"
Shape \"sphere\"
ObjectEnd
Translate 0 1 0
ObjectInstance \"o\"
Shape \"sphere\"
WorldEnd
"
    );
    let s = load(&text).scene;
    assert!(s.camera.motion.is_none());
    assert!(s.shapes.iter().all(|x| x.motion.is_none()));
    assert!(s.instances.iter().all(|x| x.motion.is_none()));
    assert!(s
        .objects
        .iter()
        .flat_map(|o| &o.shapes)
        .all(|x| x.motion.is_none()));
}

#[test]
fn camera_and_instances_record_both_transforms() {
    let text = r#"
ActiveTransform EndTime
Translate 0 0 1
ActiveTransform All
Camera "perspective" "float shutteropen" 0 "float shutterclose" 1
Film "image" "integer xresolution" 8 "integer yresolution" 8
WorldBegin
ObjectBegin "o"
Shape "sphere"
ObjectEnd
ActiveTransform EndTime
Rotate 90 0 0 1
ObjectInstance "o"
AttributeBegin
AreaLightSource "diffuse"
Shape "sphere"
AttributeEnd
WorldEnd
"#;
    let loaded = load(text);
    let s = loaded.scene;
    let cam = s.camera.motion.as_ref().expect("animated camera");
    assert_eq!(cam.start, DMat4::IDENTITY);
    assert!(close(
        cam.end,
        DMat4::from_translation(DVec3::new(0.0, 0.0, -1.0)),
        1e-12
    ));
    let inst = s.instances[0].motion.as_ref().expect("animated instance");
    assert_eq!(inst.start, DMat4::IDENTITY);
    assert!(close(
        inst.end,
        DMat4::from_rotation_z(90f64.to_radians()),
        1e-12
    ));
    // pbrt-v3 drops the area light of an animated shape, with a warning.
    assert!(s.shapes[0].motion.is_some());
    assert!(s.shapes[0].area_light.is_none());
    assert!(loaded.warnings.iter().any(|w| w
        .to_string()
        .contains("area light is ignored for an animated shape")));
}

// ---------------------------------------------------------------------------
// Interpolation against hand-computed matrices.

#[test]
fn interpolation_at_keyframes_and_midpoint_is_the_hand_computed_matrix() {
    // Start: translate (1, 0, 0). End: translate (3, 2, 0), turn 90° about z,
    // scale 2. Halfway: translate (2, 1, 0), turn 45°, scale 1.5.
    let start = DMat4::from_translation(DVec3::new(1.0, 0.0, 0.0));
    let end = DMat4::from_translation(DVec3::new(3.0, 2.0, 0.0))
        * DMat4::from_rotation_z(90f64.to_radians())
        * DMat4::from_scale(DVec3::splat(2.0));
    let at = AnimatedTransform::new(start, 0.0, end, 1.0).unwrap();
    assert_eq!(at.interpolate(0.0), start);
    assert_eq!(at.interpolate(1.0), end);
    let c = 1.5 * std::f64::consts::FRAC_1_SQRT_2;
    // Columns: x axis, y axis, z axis, translation.
    let want = DMat4::from_cols_array(&[
        c, c, 0.0, 0.0, //
        -c, c, 0.0, 0.0, //
        0.0, 0.0, 1.5, 0.0, //
        2.0, 1.0, 0.0, 1.0,
    ]);
    let mid = at.interpolate(0.5);
    assert!(close(mid, want, 1e-12), "{mid:?}");
    // A quarter of the way: 22.5°, scale 1.25, translate (1.5, 0.5, 0).
    let (s, co) = 22.5f64.to_radians().sin_cos();
    let want = DMat4::from_cols_array(&[
        1.25 * co,
        1.25 * s,
        0.0,
        0.0,
        -1.25 * s,
        1.25 * co,
        0.0,
        0.0,
        0.0,
        0.0,
        1.25,
        0.0,
        1.5,
        0.5,
        0.0,
        1.0,
    ]);
    assert!(close(at.interpolate(0.25), want, 1e-12));
    // The times are TransformTimes': halfway between 2 and 6 is 4.
    let at = AnimatedTransform::new(start, 2.0, end, 6.0).unwrap();
    assert!(close(at.interpolate(4.0), mid, 1e-12));
}

#[test]
fn motion_bounds_hold_rotations_up_to_half_a_turn() {
    let mut rng = 3u64;
    let (lo, hi) = (DVec3::new(-0.5, -1.0, -0.3), DVec3::new(0.7, 0.4, 0.6));
    for deg in [10.0f64, 45.0, 90.0, 135.0, 170.0, 179.0, 180.0] {
        for axis in [DVec3::Z, DVec3::new(1.0, 1.0, 0.3).normalize()] {
            let start = DMat4::from_translation(DVec3::new(2.0, 0.0, 0.0));
            let end = DMat4::from_axis_angle(axis, deg.to_radians())
                * DMat4::from_translation(DVec3::new(2.0, 0.5, 0.0));
            let at = AnimatedTransform::new(start, 0.0, end, 1.0).unwrap();
            let (bmin, bmax) = at.motion_bounds(lo, hi);
            for i in 0..4000 {
                let t = if i < 101 {
                    i as f64 / 100.0
                } else {
                    lcg(&mut rng)
                };
                let m = at.interpolate(t);
                for c in 0..8 {
                    let p = DVec3::new(
                        if c & 1 == 0 { lo.x } else { hi.x },
                        if c & 2 == 0 { lo.y } else { hi.y },
                        if c & 4 == 0 { lo.z } else { hi.z },
                    );
                    let w = m.transform_point3(p);
                    assert!(
                        w.cmpge(bmin).all() && w.cmple(bmax).all(),
                        "{deg}° about {axis}: corner {c} at t {t} is {w}, bounds {bmin} {bmax}"
                    );
                }
            }
        }
    }
}

// ---------------------------------------------------------------------------
// The renderer: rays at a time see the geometry where the interpolated
// transform puts it.

use glam::{Vec2, Vec3};
use pbrs::geometry::Ray;
use pbrs::integrators::RenderScene;
use pbrs::samplers::CameraSample;

fn render_scene(text: &str) -> RenderScene {
    RenderScene::new(&load(text).scene)
}

fn down(x: f32, y: f32) -> Ray {
    Ray::new(Vec3::new(x, y, 10.0), Vec3::new(0.0, 0.0, -1.0))
}

/// A sphere of radius 0.5 moving from x = 0 to x = 2 between times 0 and 1,
/// and a triangle turning 90° about z (it starts along +x, ends along +y).
const MOVING: &str = r#"
Camera "perspective"
Film "image" "integer xresolution" 8 "integer yresolution" 8
WorldBegin
AttributeBegin
  ActiveTransform EndTime
  Translate 2 0 0
  ActiveTransform All
  Shape "sphere" "float radius" 0.5
AttributeEnd
AttributeBegin
  Translate 0 0 -3
  ActiveTransform EndTime
  Rotate 90 0 0 1
  ActiveTransform All
  Shape "trianglemesh" "integer indices" [0 1 2]
    "point P" [1 -0.2 0  4 -0.2 0  4 0.2 0]
AttributeEnd
WorldEnd
"#;

#[test]
fn rays_hit_a_moving_sphere_where_its_transform_puts_it() {
    let sc = render_scene(MOVING);
    let g = &sc.aggregate;
    assert_eq!(g.moving_count(), 2);
    for (x, time, hit) in [
        (0.0, 0.0, true),
        (2.0, 0.0, false),
        (2.0, 1.0, true),
        (0.0, 1.0, false),
        (1.0, 0.5, true),
        (0.0, 0.5, false),
        (1.7, 0.85, true),
    ] {
        let r = down(x, 0.0);
        let h = g.intersect_at(&r, time);
        assert_eq!(h.is_some(), hit, "x {x} at time {time}");
        assert_eq!(g.occluded_at(&Ray { t_max: 100.0, ..r }, time), hit);
        if let Some(h) = h {
            // The top of the sphere: z = 0.5, normal +z, in world space.
            let s = g.surface_at(&h, time);
            assert!((h.t - 9.5).abs() < 1e-4, "{}", h.t);
            assert!((s.point.p - Vec3::new(x, 0.0, 0.5)).length() < 1e-4);
            assert!((s.point.n - Vec3::Z).length() < 1e-4, "{:?}", s.point.n);
            assert_eq!(s.time, time);
        }
    }
}

#[test]
fn rays_hit_a_turning_triangle_where_its_transform_puts_it() {
    let sc = render_scene(MOVING);
    let g = &sc.aggregate;
    // At time 0 the triangle lies along +x (at z = -3), at time 1 along +y,
    // halfway along the diagonal.
    let on = |x: f32, y: f32, t: f32| {
        g.intersect_at(&down(x, y), t)
            .map(|h| (h.t - 13.0).abs() < 1e-4)
            .unwrap_or(false)
    };
    assert!(on(3.0, 0.0, 0.0));
    assert!(!on(0.0, 3.0, 0.0));
    assert!(on(0.0, 3.0, 1.0));
    assert!(!on(3.0, 0.0, 1.0));
    let d = 3.0 * std::f32::consts::FRAC_1_SQRT_2;
    assert!(on(d, d, 0.5));
    assert!(!on(3.0, 0.0, 0.5) && !on(0.0, 3.0, 0.5));
    // Before the start time and after the end time the keyframes hold.
    assert!(on(3.0, 0.0, -1.0));
    assert!(on(0.0, 3.0, 2.0));
}

#[test]
fn animated_instances_move_and_still_ones_do_not() {
    let text = r#"
Camera "perspective"
Film "image" "integer xresolution" 8 "integer yresolution" 8
WorldBegin
ObjectBegin "ball"
  Shape "sphere" "float radius" 0.5
ObjectEnd
AttributeBegin
  Translate -3 0 0
  ObjectInstance "ball"
AttributeEnd
AttributeBegin
  ActiveTransform EndTime
  Translate 0 2 0
  ActiveTransform All
  ObjectInstance "ball"
AttributeEnd
WorldEnd
"#;
    let sc = render_scene(text);
    let g = &sc.aggregate;
    assert_eq!((g.instance_count(), g.moving_count()), (1, 1));
    for t in [0.0, 0.3, 1.0] {
        assert!(g.intersect_at(&down(-3.0, 0.0), t).is_some());
    }
    assert!(g.intersect_at(&down(0.0, 0.0), 0.0).is_some());
    assert!(g.intersect_at(&down(0.0, 0.0), 1.0).is_none());
    let h = g.intersect_at(&down(0.0, 1.0), 0.5).expect("halfway");
    let s = g.surface_at(&h, 0.5);
    assert!((s.point.p - Vec3::new(0.0, 1.0, 0.5)).length() < 1e-4);
}

#[test]
fn a_moving_camera_moves_its_rays_within_the_shutter() {
    let text = r#"
ActiveTransform EndTime
Translate -4 0 0
ActiveTransform All
Camera "perspective" "float shutteropen" 0.25 "float shutterclose" 0.75
Film "image" "integer xresolution" 8 "integer yresolution" 8
WorldBegin
WorldEnd
"#;
    let sc = render_scene(text);
    let cam = &sc.camera;
    assert!(cam.is_moving());
    let cs = |time: f32| CameraSample {
        p_film: Vec2::new(4.0, 4.0),
        p_lens: Vec2::new(0.5, 0.5),
        time,
    };
    // The world-to-camera end transform translates by -4: the camera
    // itself goes to +4. Sample time 0 is the shutter's opening (0.25, a
    // quarter of the way), 1 its closing, 0.5 the middle.
    for (u, time, x) in [(0.0, 0.25, 1.0), (0.5, 0.5, 2.0), (1.0, 0.75, 3.0)] {
        let (r, w) = cam.generate_ray(&cs(u));
        assert_eq!(w, 1.0);
        assert_eq!(cam.time(&cs(u)), time);
        assert!((r.o - Vec3::new(x, 0.0, 0.0)).length() < 1e-5, "{:?}", r.o);
        assert!((r.d - Vec3::Z).length() < 1e-5);
        let (rd, diff, _) = cam.generate_ray_differential(&cs(u), 1.0);
        assert_eq!((rd.o, rd.d), (r.o, r.d));
        assert!((diff.rx_o - r.o).length() < 1e-5);
        assert!(diff.rx_d.x > r.d.x, "one pixel right looks further right");
    }
    // A still camera gives the time too and does not move.
    let sc = render_scene(
        r#"Camera "perspective" "float shutteropen" 2 "float shutterclose" 4
Film "image" "integer xresolution" 8 "integer yresolution" 8
WorldBegin
WorldEnd
"#,
    );
    assert!(!sc.camera.is_moving());
    let (r, _) = sc.camera.generate_ray(&cs(0.25));
    assert_eq!(sc.camera.time(&cs(0.25)), 2.5);
    assert_eq!(r.o, Vec3::ZERO);
}

// ---------------------------------------------------------------------------
// Static scenes: no motion structures and the same image.

use pbrs::render::driver::{render, RenderOptions};

fn image(text: &str) -> Vec<f32> {
    let desc = load(text).scene;
    render(&desc, &RenderOptions::default(), &|_, _| {})
        .expect("render")
        .0
        .data
}

const STILL_WORLD: &str = r#"
Integrator "path" "integer maxdepth" [3]
Sampler "halton" "integer pixelsamples" 4
Film "image" "integer xresolution" 16 "integer yresolution" 16
WorldBegin
LightSource "point" "point from" [0 3 3] "rgb I" [10 10 10]
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [2 2 2]
  Translate 0 2 0
  Shape "sphere" "float radius" 0.3
AttributeEnd
Material "matte" "rgb Kd" [0.6 0.5 0.4]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
  "point P" [-3 -1 -3  3 -1 -3  3 -1 3  -3 -1 3]
ObjectBegin "ball"
  Shape "sphere" "float radius" 0.5
ObjectEnd
AttributeBegin
  Translate 0.8 -0.5 0
  ObjectInstance "ball"
AttributeEnd
Shape "sphere" "float radius" 0.4
WorldEnd
"#;

#[test]
fn a_static_scene_ignores_transform_times_and_the_shutter() {
    let head = "LookAt 0 0.5 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 40\n";
    let plain = image(&format!("{head}{STILL_WORLD}"));
    let timed = image(&format!(
        "TransformTimes 0.3 0.9\nLookAt 0 0.5 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 40 \"float shutteropen\" 0.1 \"float shutterclose\" 0.6\n{STILL_WORLD}"
    ));
    assert!(plain.iter().any(|&v| v > 0.0));
    assert_eq!(plain, timed, "time must not reach a static scene's image");
    // An "animation" whose two transforms agree is static.
    let same = image(&format!(
        "{head}{}",
        STILL_WORLD.replace(
            "Shape \"sphere\" \"float radius\" 0.4",
            "ActiveTransform EndTime\nTranslate 0 0 0\nActiveTransform All\nShape \"sphere\" \"float radius\" 0.4"
        )
    ));
    assert_eq!(plain, same);
    let sc = render_scene(&format!("{head}{STILL_WORLD}"));
    assert_eq!(sc.aggregate.moving_count(), 0);
    assert!(!sc.camera.is_moving());
    assert!(sc
        .notes
        .iter()
        .any(|n| n.contains("motion: none (no motion structures built)")));
}

#[test]
fn a_moving_scene_renders_blur_between_its_keyframes() {
    // The sphere at 0.4 moves; its image is a blend of the two keyframe
    // images, different from both (and finite).
    let head = "LookAt 0 0.5 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 40\n";
    let moved = |what: &str| {
        image(&format!(
            "{head}{}",
            STILL_WORLD.replace(
                "Shape \"sphere\" \"float radius\" 0.4",
                &format!("{what}\nShape \"sphere\" \"float radius\" 0.4")
            )
        ))
    };
    let start = moved("");
    let end = moved("Translate -1 0 0");
    let blur = moved("ActiveTransform EndTime\nTranslate -1 0 0\nActiveTransform All");
    assert!(blur.iter().all(|v| v.is_finite()));
    assert_ne!(blur, start);
    assert_ne!(blur, end);
}

// ---------------------------------------------------------------------------
// Bad input: located diagnostics, never a panic.

fn warnings_of(text: &str) -> Vec<String> {
    load(text).warnings.iter().map(|w| w.to_string()).collect()
}

#[test]
fn bad_transform_times_are_located_diagnostics() {
    let world = "Camera \"perspective\"\nFilm \"image\" \"integer xresolution\" 4 \"integer yresolution\" 4\nWorldBegin\nActiveTransform EndTime\nTranslate 1 0 0\nActiveTransform All\nShape \"sphere\"\nWorldEnd\n";
    // End before start: a warning, pbrt-v3's clamping (no motion between).
    let text = format!("TransformTimes 1 0\n{world}");
    let w = warnings_of(&text);
    assert!(
        w.iter()
            .any(|w| w.contains("end time 0 is before the start time 1")),
        "{w:?}"
    );
    let located = load(&text)
        .warnings
        .iter()
        .map(|w| format!("{w:?}"))
        .collect::<Vec<_>>();
    assert!(
        located.iter().any(|w| w.contains("motion-test.pbrt:1:1")),
        "{located:?}"
    );
    let img = image(&text);
    assert!(img.iter().all(|v| v.is_finite()));
    // Non-finite times: an error at the statement.
    let err = load_scene_str(
        &format!("TransformTimes 0 1e999\n{world}"),
        Path::new("motion-test.pbrt"),
    )
    .err()
    .expect("an error");
    let e: Vec<String> = err.errors.iter().map(|e| format!("{e:?}")).collect();
    assert!(
        e.iter()
            .any(|e| e.contains("finite") && e.contains("motion-test.pbrt:1:1")),
        "{e:?}"
    );
}

#[test]
fn singular_and_mirrored_animated_transforms_warn_and_never_panic() {
    let scene = |edit: &str| {
        format!(
            "Camera \"perspective\"\nFilm \"image\" \"integer xresolution\" 8 \"integer yresolution\" 8\nSampler \"halton\" \"integer pixelsamples\" 2\nWorldBegin\nLightSource \"point\" \"point from\" [0 0 -3] \"rgb I\" [5 5 5]\nAttributeBegin\nTranslate 0 0 4\nActiveTransform EndTime\n{edit}\nActiveTransform All\nShape \"sphere\"\nAttributeEnd\nWorldEnd\n"
        )
    };
    // A keyframe of scale 0: left out, with a warning.
    let text = scene("Scale 0 1 1");
    let w = warnings_of(&text);
    assert!(w.iter().any(|w| w.contains("singular")), "{w:?}");
    let sc = render_scene(&text);
    assert_eq!(sc.aggregate.moving_count(), 0);
    assert!(sc.notes.iter().any(|n| n.contains("singular start or end")));
    assert!(image(&text).iter().all(|v| v.is_finite()));
    // A mirror at the end: warned (pbrt-v3 interpolates it wrongly); the
    // scale passes through 0 halfway, where the sphere vanishes for those
    // rays only.
    let text = scene("Scale -1 1 1");
    let w = warnings_of(&text);
    assert!(w.iter().any(|w| w.contains("mirror")), "{w:?}");
    let sc = render_scene(&text);
    assert_eq!(sc.aggregate.moving_count(), 1);
    let ray = Ray::new(Vec3::new(0.0, 0.0, 0.0), Vec3::Z);
    assert!(sc.aggregate.intersect_at(&ray, 0.0).is_some());
    assert!(sc.aggregate.intersect_at(&ray, 1.0).is_some());
    assert!(!sc.aggregate.occluded_at(
        &Ray {
            t_max: 100.0,
            ..ray
        },
        0.5
    ));
    assert!(image(&text).iter().all(|v| v.is_finite()));
    // A projective keyframe: warned.
    let text = scene("ConcatTransform [1 0 0 0  0 1 0 0  0 0 1 0.5  0 0 0 1]");
    let w = warnings_of(&text);
    assert!(w.iter().any(|w| w.contains("projective")), "{w:?}");
    assert!(image(&text).iter().all(|v| v.is_finite()));
}

#[test]
fn animated_shapes_inside_objects_use_their_start_transform() {
    let text = r#"
Camera "perspective"
Film "image" "integer xresolution" 8 "integer yresolution" 8
WorldBegin
ObjectBegin "o"
  ActiveTransform EndTime
  Translate 5 0 0
  ActiveTransform All
  Shape "sphere"
ObjectEnd
ObjectInstance "o"
WorldEnd
"#;
    let w = warnings_of(text);
    assert!(
        w.iter().any(|w| w.contains("inside an object definition")),
        "{w:?}"
    );
    let sc = render_scene(text);
    assert_eq!(sc.aggregate.moving_count(), 0);
    assert!(sc.aggregate.intersect_at(&down(0.0, 0.0), 1.0).is_some());
}
