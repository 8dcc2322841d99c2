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
