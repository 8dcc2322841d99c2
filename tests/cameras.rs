//! The cameras' geometry against pbrt-v3's conventions: orthographic rays
//! and thin-lens focus, the environment camera's directions, the realistic
//! camera's focus, exit pupil, focal lengths and weights, and bad camera
//! input as located diagnostics. (Renders against pbrt-v3 are golden
//! entries: `scenes/cameras/`.)

mod common;

use common::repo;
use glam::{Vec2, Vec3};
use pbrs::cameras::realistic::LensRay;
use pbrs::cameras::{Camera, Projection, RealisticCamera};
use pbrs::geometry::Ray;
use pbrs::lang::parser::FileLoader;
use pbrs::loader::{load_scene_str, load_scene_with, LoadFailure, LoadedScene};
use pbrs::samplers::CameraSample;
use pbrs::scene::SceneDescription;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

fn load(text: &str) -> SceneDescription {
    load_scene_str(text, Path::new("mem.pbrt"))
        .unwrap_or_else(|f| panic!("{f:?}"))
        .scene
}

fn camera_of(s: &SceneDescription) -> Camera {
    Camera::new(&s.camera, &s.film)
}

fn sample(x: f32, y: f32, u: f32, v: f32) -> CameraSample {
    CameraSample {
        p_film: Vec2::new(x, y),
        p_lens: Vec2::new(u, v),
        time: 0.5,
    }
}

/// World → camera space of the scene's camera.
fn to_camera(s: &SceneDescription, p: Vec3) -> Vec3 {
    s.camera
        .camera_to_world
        .inverse()
        .transform_point3(p.as_dvec3())
        .as_vec3()
}

fn to_camera_dir(s: &SceneDescription, d: Vec3) -> Vec3 {
    s.camera
        .camera_to_world
        .inverse()
        .transform_vector3(d.as_dvec3())
        .as_vec3()
}

fn close(a: Vec3, b: Vec3, tol: f32) -> bool {
    (a - b).length() <= tol
}

/// A small deterministic sequence in [0, 1).
fn lcg(state: &mut u64) -> f32 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    ((*state >> 40) as f32) / (1u64 << 24) as f32
}

// ------------------------------------------------------------ orthographic

const ORTHO: &str = "LookAt 1 2 3  0 0 0  0 1 0\nCamera \"orthographic\" \"float screenwindow\" [-2 3 -1 1.5]\nFilm \"image\" \"integer xresolution\" 50 \"integer yresolution\" 20\nWorldBegin\nWorldEnd";

#[test]
fn orthographic_rays_are_parallel_and_start_on_the_screen_window() {
    let s = load(ORTHO);
    assert!(matches!(s.camera.projection, Projection::Orthographic(_)));
    let cam = camera_of(&s);
    assert!(!cam.uses_lens());
    let forward = (Vec3::ZERO - Vec3::new(1.0, 2.0, 3.0)).normalize();
    for (x, y) in [
        (0.0, 0.0),
        (50.0, 20.0),
        (25.0, 10.0),
        (12.3, 17.9),
        (49.0, 0.5),
    ] {
        let (ray, w) = cam.generate_ray(&sample(x, y, 0.3, 0.7));
        assert_eq!(w, 1.0);
        assert!(close(ray.d, forward, 1e-6), "{:?}", ray.d);
        // Raster (0, 0) is the window's top-left (xmin, ymax); y runs down.
        let want = Vec3::new(-2.0 + x / 50.0 * 5.0, 1.5 - y / 20.0 * 2.5, 0.0);
        let o = to_camera(&s, ray.o);
        assert!(close(o, want, 1e-5), "({x}, {y}): {o} != {want}");
    }
}

#[test]
fn orthographic_differentials_are_pbrt_v3s() {
    let s = load(ORTHO);
    let cam = camera_of(&s);
    let cs = sample(10.25, 5.5, 0.1, 0.9);
    let (ray, d, w) = cam.generate_ray_differential(&cs, 1.0);
    let (plain, _) = cam.generate_ray(&cs);
    assert_eq!((ray.o, ray.d, w), (plain.o, plain.d, 1.0));
    // Pinhole: origins of the next pixel over, the same direction.
    let (rx, _) = cam.generate_ray(&sample(11.25, 5.5, 0.1, 0.9));
    let (ry, _) = cam.generate_ray(&sample(10.25, 6.5, 0.1, 0.9));
    assert!(close(d.rx_o, rx.o, 1e-5) && close(d.ry_o, ry.o, 1e-5));
    assert_eq!((d.rx_d, d.ry_d), (ray.d, ray.d));
    let (_, quarter, _) = cam.generate_ray_differential(&cs, 0.25);
    assert!(close(quarter.rx_o, ray.o + (rx.o - ray.o) * 0.25, 1e-6));
}

/// Rays from different lens points through one raster position meet on the
/// plane of focus, at the pinhole ray's point there (orthographic and
/// perspective thin lenses).
#[test]
fn thin_lens_rays_meet_on_the_focal_plane() {
    for camera in [
        "\"orthographic\" \"float lensradius\" 0.4 \"float focaldistance\" 7",
        "\"perspective\" \"float fov\" 50 \"float lensradius\" 0.4 \"float focaldistance\" 7",
    ] {
        let text = format!("LookAt 0 1 -4  0 1 0  0 1 0\nCamera {camera}\nFilm \"image\" \"integer xresolution\" 40 \"integer yresolution\" 30\nWorldBegin\nWorldEnd");
        let s = load(&text);
        let cam = camera_of(&s);
        assert!(cam.uses_lens());
        for (x, y) in [(20.0, 15.0), (3.5, 27.25), (39.0, 1.0)] {
            let mut meet = Vec::new();
            for (u, v) in [
                (0.5, 0.5),
                (0.05, 0.9),
                (0.95, 0.2),
                (0.3, 0.01),
                (0.99, 0.99),
            ] {
                let (ray, _) = cam.generate_ray(&sample(x, y, u, v));
                let (o, d) = (to_camera(&s, ray.o), to_camera_dir(&s, ray.d));
                assert!(o.z.abs() < 1e-4, "rays start on the lens plane");
                meet.push(o + d * ((7.0 - o.z) / d.z));
            }
            // The centre of the lens is the pinhole ray.
            for p in &meet[1..] {
                assert!(
                    close(*p, meet[0], 2e-4),
                    "{camera} ({x}, {y}): {p} vs {}",
                    meet[0]
                );
            }
            // And lens points differ: away from the focal plane they do not meet.
            let (a, _) = cam.generate_ray(&sample(x, y, 0.05, 0.9));
            let (b, _) = cam.generate_ray(&sample(x, y, 0.95, 0.2));
            let at = |r: Ray, z: f32| {
                let (o, d) = (to_camera(&s, r.o), to_camera_dir(&s, r.d));
                o + d * ((z - o.z) / d.z)
            };
            assert!((at(a, 3.0) - at(b, 3.0)).length() > 0.1);
        }
    }
}

// ------------------------------------------------------------ environment

#[test]
fn environment_camera_maps_raster_positions_as_pbrt_v3() {
    let s = load("Camera \"environment\"\nFilm \"image\" \"integer xresolution\" 64 \"integer yresolution\" 32\nWorldBegin\nWorldEnd");
    let cam = camera_of(&s);
    assert!(!cam.uses_lens());
    let dir = |x: f32, y: f32| {
        let (r, w) = cam.generate_ray(&sample(x, y, 0.5, 0.5));
        assert_eq!((r.o, w), (Vec3::ZERO, 1.0));
        r.d
    };
    // θ from +y (top row) to −y (bottom row); φ from +x around through +z.
    assert!(
        close(dir(32.0, 16.0), -Vec3::X, 1e-6),
        "centre: {}",
        dir(32.0, 16.0)
    );
    assert!(close(dir(0.0, 16.0), Vec3::X, 1e-6));
    assert!(close(dir(16.0, 16.0), Vec3::Z, 1e-6));
    assert!(close(dir(48.0, 16.0), -Vec3::Z, 1e-6));
    assert!(close(dir(64.0, 16.0), Vec3::X, 1e-5));
    assert!(close(dir(20.0, 0.0), Vec3::Y, 1e-6));
    assert!(close(dir(20.0, 32.0), -Vec3::Y, 1e-6));
    // 45° up, a quarter around: between +y and +z.
    let d = dir(16.0, 8.0);
    assert!(close(d, Vec3::new(0.0, 1.0, 1.0).normalize(), 1e-6), "{d}");
    // Finite-difference differentials: one pixel is 2π/64 of longitude at
    // the equator.
    let (ray, diff, _) = cam.generate_ray_differential(&sample(16.0, 16.0, 0.5, 0.5), 1.0);
    let step = (diff.rx_d - ray.d).length();
    assert!((step - std::f32::consts::TAU / 64.0).abs() < 1e-3, "{step}");
    assert!(((diff.ry_d - ray.d).length() - std::f32::consts::PI / 32.0).abs() < 1e-3);
    assert_eq!((diff.rx_o, diff.ry_o), (ray.o, ray.o));
}

// ------------------------------------------------------------ realistic

fn realistic_scene(camera_params: &str, film: &str) -> String {
    format!("LookAt 0 0 0  0 0 1  0 1 0\nCamera \"realistic\" {camera_params}\nFilm \"image\" {film}\nWorldBegin\nWorldEnd")
}

fn load_lens_scene(text: &str) -> SceneDescription {
    let path = repo().join("scenes/cameras/mem.pbrt");
    load_scene_str(text, &path)
        .unwrap_or_else(|f| panic!("{f:?}"))
        .scene
}

fn realistic_of(s: &SceneDescription) -> RealisticCamera {
    match camera_of(s).projection {
        Projection::Realistic(c) => c,
        other => panic!("not realistic: {other:?}"),
    }
}

const DGAUSS: &str = "\"string lensfile\" \"lenses/dgauss.50mm.dat\" \"float aperturediameter\" 12 \"float focusdistance\" 3";
const FILM: &str = "\"integer xresolution\" 48 \"integer yresolution\" 32";

/// The double Gauss lens focused at 3 (one construction shared by the
/// tests: the exit pupil costs 64 × 2²⁰ traced rays, as in pbrt-v3).
fn dgauss() -> &'static (SceneDescription, RealisticCamera) {
    static CAM: OnceLock<(SceneDescription, RealisticCamera)> = OnceLock::new();
    CAM.get_or_init(|| {
        let s = load_lens_scene(&realistic_scene(DGAUSS, FILM));
        let c = realistic_of(&s);
        (s, c)
    })
}

#[test]
fn paraxial_focal_lengths_match_the_lens_files() {
    for (file, nominal) in [
        ("dgauss.50mm.dat", 0.050),
        ("telephoto.250mm.dat", 0.250),
        ("fisheye.10mm.dat", 0.010),
    ] {
        let s = load_lens_scene(&realistic_scene(
            &format!("\"string lensfile\" \"lenses/{file}\" \"float focusdistance\" 1e4"),
            FILM,
        ));
        let Projection::Realistic(r) = &s.camera.projection else {
            panic!("{file}: not realistic")
        };
        let f = r.focal_length;
        assert!(((f - nominal) / nominal).abs() < 0.02, "{file}: {f} m");
        // Focused far away, the film sits about one focal length behind the
        // rear principal plane: the rear distance is positive and below f
        // plus the lens length.
        let rear = r.lens.interfaces.last().unwrap().thickness;
        let length: f32 = r.lens.interfaces.iter().map(|e| e.thickness).sum();
        assert!(rear > 0.0 && rear < f + length, "{file}: rear {rear}");
    }
}

/// Rays from the film centre through different points of the exit pupil
/// cross the axis at the focus distance (paraxial rays: the thick-lens
/// approximation is exact in the limit), and a point on the focal plane is
/// imaged back to one film point.
#[test]
fn realistic_lens_focuses_at_focusdistance() {
    let (_, cam) = dgauss();
    let lens = &cam.lens;
    let rear = lens.rear_z();
    let mut hits = 0;
    for h in [0.2e-3f32, 0.4e-3, -0.3e-3, 0.5e-3] {
        let r = LensRay {
            o: Vec3::ZERO,
            d: Vec3::new(h, 0.0, rear),
        };
        let out = lens
            .trace_from_film(r)
            .expect("a paraxial ray gets through");
        let t = -out.o.x / out.d.x;
        let z = out.o.z + out.d.z * t;
        assert!((z - 3.0).abs() < 0.03, "h {h}: crosses the axis at {z}");
        hits += 1;
    }
    assert_eq!(hits, 4);
    // From the scene side: a point 5 mm off axis on the plane of focus.
    let p = Vec3::new(0.005, 0.0, 3.0);
    let front = lens.front_z();
    let mut on_film = Vec::new();
    for (a, b) in [(0.0, 0.0), (0.5e-3, 0.0), (0.0, 0.5e-3), (-0.4e-3, 0.3e-3)] {
        let target = Vec3::new(a, b, front);
        let out = lens
            .trace_from_scene(LensRay {
                o: p,
                d: target - p,
            })
            .expect("gets through");
        let t = -out.o.z / out.d.z;
        on_film.push(out.o + out.d * t);
    }
    for q in &on_film[1..] {
        assert!((*q - on_film[0]).length() < 2e-6, "{q} vs {}", on_film[0]);
    }
    // The image is inverted: the point at +x lands at −x on the film.
    assert!(on_film[0].x < 0.0);
    // Defocused (a point at 1.5 instead of 3), the same rays spread.
    let p = Vec3::new(0.0025, 0.0, 1.5);
    let spread: Vec<Vec3> = [(0.0, 0.0), (2e-3, 0.0)]
        .iter()
        .map(|&(a, b)| {
            let out = lens
                .trace_from_scene(LensRay {
                    o: p,
                    d: Vec3::new(a, b, front) - p,
                })
                .expect("gets through");
            out.o + out.d * (-out.o.z / out.d.z)
        })
        .collect();
    assert!((spread[1] - spread[0]).length() > 2e-5);
}

/// pbrt-v3's `TestExitPupilBounds`, for every radius: rays from film points
/// to points of the rear element that get through the lens hit the rear
/// plane inside the bounds used for that film point (rotated to its angle).
#[test]
fn exit_pupil_bounds_contain_every_ray_that_gets_through() {
    let (_, cam) = dgauss();
    let lens = &cam.lens;
    let (rear_z, rear_r) = (lens.rear_z(), lens.rear_radius());
    let mut rng = 7u64;
    let (mut through, mut blocked) = (0, 0);
    for _ in 0..400 {
        let raster = Vec2::new(lcg(&mut rng) * 48.0, lcg(&mut rng) * 32.0);
        let pf = cam.film_point(raster);
        let bounds = cam.pupil_bounds(pf.truncate());
        let r = pf.truncate().length();
        let (sin, cos) = if r > 0.0 {
            (pf.y / r, pf.x / r)
        } else {
            (0.0, 1.0)
        };
        for _ in 0..100 {
            let (a, b) = (lcg(&mut rng) * 2.0 - 1.0, lcg(&mut rng) * 2.0 - 1.0);
            if a * a + b * b > 1.0 {
                continue;
            }
            let rear = Vec2::new(a, b) * rear_r;
            let ray = LensRay {
                o: pf,
                d: Vec3::new(rear.x, rear.y, rear_z) - pf,
            };
            if lens.trace_from_film(ray).is_none() {
                blocked += 1;
                continue;
            }
            through += 1;
            // Into the frame where the film point lies on +x.
            let local = Vec2::new(cos * rear.x + sin * rear.y, -sin * rear.x + cos * rear.y);
            assert!(
                bounds.contains(local),
                "film {pf}: {local} outside {bounds:?}"
            );
        }
    }
    assert!(through > 1000 && blocked > 1000, "{through} {blocked}");
    // The bounds are tight, not the whole rear element: the centre bound
    // is a fraction of the 3r × 3r square pbrt-v3 falls back to.
    assert!(cam.exit_pupil[0].area() < 0.5 * (3.0 * rear_r).powi(2));
}

/// No NaN anywhere: every sample over the film, the film's edges and
/// extreme lens samples gives a zero weight or a finite unit ray with finite
/// differentials and a positive finite weight; the fisheye
/// blocks some samples (zero weight, as pbrt-v3).
#[test]
fn realistic_samples_are_finite_or_zero_weight() {
    let fisheye = load_lens_scene(&realistic_scene(
        "\"string lensfile\" \"lenses/fisheye.10mm.dat\" \"float aperturediameter\" 6.08 \"float focusdistance\" 1",
        FILM,
    ));
    let cams = [
        (
            Camera::still(Projection::Realistic(dgauss().1.clone())),
            "dgauss",
        ),
        (camera_of(&fisheye), "fisheye"),
    ];
    for (cam, name) in &cams {
        let mut rng = 11u64;
        let (mut zero, mut live) = (0, 0);
        let edges = [0.0, 1e-6, 0.5, 0.999_999];
        for i in 0..6000 {
            let (x, y, u, v) = if i < 256 {
                (
                    edges[i % 4] * 48.0,
                    edges[(i / 4) % 4] * 32.0,
                    edges[(i / 16) % 4],
                    edges[(i / 64) % 4],
                )
            } else {
                (
                    lcg(&mut rng) * 48.0,
                    lcg(&mut rng) * 32.0,
                    lcg(&mut rng),
                    lcg(&mut rng),
                )
            };
            let (ray, d, w) = cam.generate_ray_differential(&sample(x, y, u, v), 0.25);
            let (plain, w2) = cam.generate_ray(&sample(x, y, u, v));
            assert_eq!(w, w2);
            assert!(w.is_finite() && w >= 0.0, "{name}: weight {w}");
            if w == 0.0 {
                zero += 1;
                continue;
            }
            live += 1;
            assert_eq!((ray.o, ray.d), (plain.o, plain.d));
            assert!(ray.o.is_finite() && (ray.d.length() - 1.0).abs() < 1e-5);
            assert!(ray.d.z > 0.0, "{name}: looks forward (+z)");
            for v in [d.rx_o, d.rx_d, d.ry_o, d.ry_d] {
                assert!(v.is_finite(), "{name}: differential {v}");
            }
        }
        assert!(live > 1000, "{name}: {live}");
        if *name == "fisheye" {
            assert!(zero > 100, "the fisheye vignettes: {zero}");
        }
    }
}

// ------------------------------------------------------------ bad input

/// Lens files in memory (by file name) for the loader.
struct Files(HashMap<PathBuf, Vec<u8>>);

impl FileLoader for Files {
    fn load(&self, path: &Path) -> Result<Vec<u8>, String> {
        self.0
            .get(path)
            .cloned()
            .ok_or_else(|| "No such file or directory".to_string())
    }
}

fn with_lens(file: &str, params: &str) -> Result<LoadedScene, LoadFailure> {
    let files = Files(HashMap::from([(
        PathBuf::from("lens.dat"),
        file.as_bytes().to_vec(),
    )]));
    load_scene_with(
        &realistic_scene(&format!("\"string lensfile\" \"lens.dat\" {params}"), FILM),
        Path::new("mem.pbrt"),
        Box::new(files),
    )
}

fn errors_of(r: Result<LoadedScene, LoadFailure>) -> String {
    match r {
        Ok(_) => panic!("loaded"),
        Err(f) => f
            .errors
            .iter()
            .map(|e| e.to_string())
            .collect::<Vec<_>>()
            .join("\n"),
    }
}

fn warnings_of(s: &LoadedScene) -> String {
    s.warnings
        .iter()
        .map(|w| w.to_string())
        .collect::<Vec<_>>()
        .join("\n")
}

const SINGLET: &str = "# a biconvex singlet (f about 51 mm), then the stop\n\n  50 5 1.5 20 # front\n-50 2 1 20\n0 40 0 10\n";

#[test]
fn bad_lens_files_are_located_errors() {
    // The valid file loads (comments, blank lines, trailing comments).
    let ok = with_lens(
        SINGLET,
        "\"float aperturediameter\" 8 \"float focusdistance\" 5",
    )
    .unwrap_or_else(|f| panic!("{f:?}"));
    let Projection::Realistic(r) = &ok.scene.camera.projection else {
        panic!()
    };
    assert_eq!(r.lens.interfaces.len(), 3);
    assert!((r.lens.interfaces[2].aperture_radius - 0.004).abs() < 1e-8);
    assert!(
        (r.focal_length - 0.0508).abs() < 0.001,
        "{}",
        r.focal_length
    );
    for (file, want) in [
        ("", "no lens interface"),
        ("# only a comment\n\n", "no lens interface"),
        ("50 5 1.5 20\n0 2 0\n-1e9 40 1 20\n", "line 2: 3 values"),
        ("50 5 1.5 20 7\n", "line 1: 5 values"),
        (
            "50 5 1.5 twenty\n",
            "line 1: \"twenty\" is not a finite number",
        ),
        ("50 5 nan 20\n", "is not a finite number"),
        ("50 -5 1.5 20\n", "thickness -5 is negative"),
        ("50 5 1.5 0\n", "aperture diameter 0"),
        ("50 5 0 20\n", "index of refraction 0 of a lens interface"),
    ] {
        let e = errors_of(with_lens(file, ""));
        assert!(e.contains(want), "{file:?}: {e}");
        assert!(e.contains("mem.pbrt:2:"), "located at the Camera: {e}");
    }
    let e = errors_of(load_scene_with(
        &realistic_scene("\"string lensfile\" \"missing.dat\"", FILM),
        Path::new("mem.pbrt"),
        Box::new(Files(HashMap::new())),
    ));
    assert!(e.contains("cannot read lens file \"missing.dat\""), "{e}");
    let e = errors_of(load_scene_with(
        &realistic_scene("\"float focusdistance\" 3", FILM),
        Path::new("mem.pbrt"),
        Box::new(Files(HashMap::new())),
    ));
    assert!(e.contains("needs a \"string lensfile\""), "{e}");
}

#[test]
fn lenses_that_block_every_ray_or_cannot_focus_are_errors() {
    for (params, want) in [
        ("\"float aperturediameter\" 0", "must be > 0"),
        ("\"float aperturediameter\" -3", "must be > 0"),
        // A stop far smaller than the thick-lens ray's height (35 µm).
        (
            "\"float aperturediameter\" 0.00001",
            "no ray parallel to the axis",
        ),
        ("\"float focusdistance\" 0.02", "cannot focus"),
        (
            "\"float focusdistance\" -1",
            "\"focusdistance\" -1 must be > 0",
        ),
    ] {
        let e = errors_of(with_lens(SINGLET, params));
        assert!(e.contains(want), "{params}: {e}");
    }
    // An aperture larger than the stop is clamped with a warning.
    let s = with_lens(SINGLET, "\"float aperturediameter\" 30").unwrap_or_else(|f| panic!("{f:?}"));
    assert!(warnings_of(&s).contains("clamped"), "{}", warnings_of(&s));
    let Projection::Realistic(r) = &s.scene.camera.projection else {
        panic!()
    };
    assert!((r.lens.interfaces[2].aperture_radius - 0.005).abs() < 1e-8);
}

#[test]
fn bad_thin_lens_parameters() {
    let text = |cam: &str| format!("Camera {cam}\nWorldBegin\nWorldEnd");
    let s = load_scene_str(
        &text("\"orthographic\" \"float lensradius\" -1"),
        Path::new("mem.pbrt"),
    )
    .unwrap_or_else(|f| panic!("{f:?}"));
    assert!(warnings_of(&s).contains("a pinhole camera is used"));
    assert!(!camera_of(&s.scene).uses_lens());
    for cam in [
        "\"orthographic\" \"float lensradius\" 0.1 \"float focaldistance\" 0",
        "\"perspective\" \"float lensradius\" 0.1 \"float focaldistance\" -2",
    ] {
        let e = errors_of(load_scene_str(&text(cam), Path::new("mem.pbrt")));
        assert!(
            e.contains("\"focaldistance\"") && e.contains("must be > 0"),
            "{e}"
        );
        assert!(e.contains("mem.pbrt:1:"), "{e}");
    }
    let e = errors_of(load_scene_str(
        &text("\"orthographic\" \"float frameaspectratio\" 0"),
        Path::new("mem.pbrt"),
    ));
    assert!(e.contains("\"frameaspectratio\" 0 must be > 0"), "{e}");
    // The environment camera reads and ignores the projective parameters
    // (no unused-parameter warning, as pbrt-v3); others are reported.
    let s = load_scene_str(
        &text("\"environment\" \"float lensradius\" 1 \"float fov\" 30"),
        Path::new("mem.pbrt"),
    )
    .unwrap_or_else(|f| panic!("{f:?}"));
    let w = warnings_of(&s);
    assert!(
        w.contains("\"float fov\" not used") && !w.contains("lensradius"),
        "{w}"
    );
}

/// Every kind of `cameras::CAMERAS`, loaded from a statement: the
/// centre of the film looks where pbrt-v3's camera of that kind looks (the
/// projective and realistic cameras along +z, the environment camera along
/// −x), with a positive weight, and `--check` names the kind. A kind of the
/// table without a case here fails.
#[test]
fn every_camera_kind_loads_and_looks_where_pbrt_v3s_does() {
    use pbrs::cameras::CAMERAS;
    let cases: &[(&str, &str, Vec3)] = &[
        ("perspective", "\"float fov\" 30", Vec3::Z),
        ("orthographic", "", Vec3::Z),
        ("environment", "", -Vec3::X),
        (
            "realistic",
            "\"string lensfile\" \"lenses/dgauss.50mm.dat\" \"float aperturediameter\" 2 \"float focusdistance\" 3",
            Vec3::Z,
        ),
    ];
    for k in CAMERAS {
        assert!(
            cases.iter().any(|c| c.0 == k.name),
            "camera \"{}\" has no test case",
            k.name
        );
    }
    for (name, params, forward) in cases {
        let text =
            format!("Camera \"{name}\" {params}\nFilm \"image\" {FILM}\nWorldBegin\nWorldEnd");
        let s = load_lens_scene(&text);
        assert!(s.camera.projection.describe().starts_with(name));
        let cam = camera_of(&s);
        let (ray, w) = cam.generate_ray(&sample(24.0, 16.0, 0.5, 0.5));
        assert!(w > 0.0, "{name}: weight {w}");
        assert!(
            close(ray.d.normalize(), *forward, 0.05),
            "{name}: the film's centre looks along {}",
            ray.d
        );
    }
}
