//! The goniometric and projection lights against pbrt-v3's conventions,
//! evaluated independently here: which texel a direction reads (the
//! goniometric map's pole along light-space +y, φ = atan2(z, x); the
//! projection's screen window by aspect ratio, `fov` across the shorter
//! side, first row towards −y), under rotated light transforms; the
//! frustum's edges and the space behind the light; their power for light
//! selection; and renders: a map of ones gives the point light's image
//! byte for byte, inside the frustum too, and nothing outside it.

mod tex_common;

use glam::{Vec2, Vec3};
use pbrs::image::Image;
use pbrs::integrators::RenderScene;
use pbrs::lights::Light;
use pbrs::render::driver::{render, RenderOptions};
use pbrs::shapes::SurfacePoint;
use std::f32::consts::PI;
use tex_common::{load, pfm, MemFiles};

/// A map whose texel (i, j) (row j from the top) is (i + 1, j + 1, 1) / 8:
/// every texel different.
fn texel(i: usize, j: usize) -> Vec3 {
    Vec3::new(i as f32 + 1.0, j as f32 + 1.0, 1.0) / 8.0
}

fn map(w: usize, h: usize) -> MemFiles {
    let px: Vec<[f32; 3]> = (0..h)
        .flat_map(|j| (0..w).map(move |i| texel(i, j).to_array()))
        .collect();
    let mut f = MemFiles::default();
    f.0.insert(tex_common::dir().join("map.pfm"), pfm(w, h, &px));
    f
}

fn light_of(transform: &str, light: &str, files: &MemFiles) -> (Light, RenderScene) {
    let s = load(
        &format!("WorldBegin\nAttributeBegin\n{transform}\n{light}\nAttributeEnd\nShape \"sphere\" \"float radius\" 0.01\nWorldEnd\n"),
        files,
    );
    let sc = RenderScene::new(&s.scene);
    assert_eq!(sc.lights.len(), 1);
    (sc.lights[0].clone(), sc)
}

/// Li at a point `d` away from the light, in world direction `w` from it.
fn li_towards(l: &Light, sc: &RenderScene, light_p: Vec3, w: Vec3, d: f32) -> Vec3 {
    let r = SurfacePoint {
        p: light_p + w * d,
        p_error: Vec3::ZERO,
        n: Vec3::ZERO,
        ns: Vec3::ZERO,
    };
    let s = l
        .sample_li(&r, Vec2::new(0.5, 0.5), &sc.aggregate)
        .expect("a sample");
    assert_eq!(s.pdf, 1.0);
    s.li * d * d
}

fn close(a: Vec3, b: Vec3, tol: f32) -> bool {
    (a - b).abs().max_element() <= tol * b.abs().max_element().max(1e-3)
}

/// Rotations about x then y, as the scene writes them, applied to a vector.
fn rotate(v: Vec3) -> Vec3 {
    let m = glam::Mat3::from_rotation_x(30f32.to_radians())
        * glam::Mat3::from_rotation_y(-50f32.to_radians());
    m * v
}
const ROTATE: &str = "Translate 1 2 3\nRotate 30 1 0 0\nRotate -50 0 1 0";

#[test]
fn goniometric_reads_the_texel_of_each_direction() {
    let (w, h) = (16, 8);
    let files = map(w, h);
    let (l, sc) = light_of(
        ROTATE,
        "LightSource \"goniometric\" \"rgb I\" [2 3 4] \"string mapname\" \"map.pfm\"",
        &files,
    );
    let Light::Goniometric(g) = &l else {
        panic!("not a goniometric light")
    };
    let p = Vec3::new(1.0, 2.0, 3.0);
    assert!(close(g.p, p, 1e-6));
    let i_ = Vec3::new(2.0, 3.0, 4.0);
    for (i, j) in [(0, 0), (3, 1), (15, 7), (8, 4), (11, 6)] {
        // Texel centre (i + ½)/w, (j + ½)/h: φ and θ, and the light-space
        // direction with the map's pole along +y.
        let phi = 2.0 * PI * (i as f32 + 0.5) / w as f32;
        let theta = PI * (j as f32 + 0.5) / h as f32;
        let local = Vec3::new(
            theta.sin() * phi.cos(),
            theta.cos(),
            theta.sin() * phi.sin(),
        );
        let world = rotate(local);
        let got = li_towards(&l, &sc, p, world, 2.0);
        assert!(
            close(got, i_ * texel(i, j), 2e-4),
            "texel ({i}, {j}): {got} vs {}",
            i_ * texel(i, j)
        );
    }
    // At the poles (θ = 0 along light-space +y, θ = π along −y) the
    // bilinear lookup is half a texel outside the map, and pbrt-v3's
    // repeat wrap blends the first and last rows equally.
    for pole in [Vec3::Y, -Vec3::Y] {
        let m = li_towards(&l, &sc, p, rotate(pole), 2.0) / i_;
        let want = (texel(0, 0).y + texel(0, h - 1).y) / 2.0;
        assert!((m.y - want).abs() < 1e-5, "{pole}: {m}");
    }
    // Power: 4π·I times the map's average (a power-of-two map: the
    // average of its texels).
    let mean: Vec3 = (0..h)
        .flat_map(|j| (0..w).map(move |i| texel(i, j)))
        .sum::<Vec3>()
        / (w * h) as f32;
    let want = pbrs::geometry::luminance(4.0 * PI * i_ * mean);
    assert!(
        (l.power() - want).abs() < 1e-4 * want,
        "{} vs {want}",
        l.power()
    );
    // Without a map: a point light of intensity I.
    let (l, sc) = light_of("", "LightSource \"goniometric\" \"rgb I\" [2 3 4]", &files);
    assert!(close(
        li_towards(&l, &sc, Vec3::ZERO, Vec3::X, 3.0),
        i_,
        1e-6
    ));
}

#[test]
fn projection_reads_the_texel_of_each_direction() {
    // Aspect 2: the screen window is [−2, 2] × [−1, 1] and fov spans y.
    let (w, h) = (8, 4);
    let files = map(w, h);
    let fov = 50f32;
    let (l, sc) = light_of(
        ROTATE,
        &format!("LightSource \"projection\" \"rgb I\" [2 3 4] \"float fov\" {fov} \"string mapname\" \"map.pfm\""),
        &files,
    );
    let Light::Projection(_) = &l else {
        panic!("not a projection light")
    };
    let p = Vec3::new(1.0, 2.0, 3.0);
    let i_ = Vec3::new(2.0, 3.0, 4.0);
    let t = (fov.to_radians() / 2.0).tan();
    let dir = |sx: f32, sy: f32| rotate(Vec3::new(sx * t, sy * t, 1.0).normalize());
    for (i, j) in [(0, 0), (7, 3), (2, 1), (5, 2)] {
        let s = (i as f32 + 0.5) / w as f32;
        let u = (j as f32 + 0.5) / h as f32;
        // The first row (t = 0) falls on −y.
        let got = li_towards(&l, &sc, p, dir(-2.0 + 4.0 * s, -1.0 + 2.0 * u), 2.0);
        assert!(
            close(got, i_ * texel(i, j), 2e-4),
            "texel ({i}, {j}): {got} vs {}",
            i_ * texel(i, j)
        );
    }
    // Outside the window (x beyond ±2, y beyond ±1), behind the light.
    for d in [
        dir(2.05, 0.0),
        dir(-2.05, 0.5),
        dir(0.0, 1.05),
        dir(1.0, -1.05),
        rotate(-Vec3::Z),
        rotate(Vec3::X),
    ] {
        assert_eq!(li_towards(&l, &sc, p, d, 2.0), Vec3::ZERO, "{d}");
    }
    // Power: I times the average times the cone around the diagonal.
    let mean: Vec3 = (0..h)
        .flat_map(|j| (0..w).map(move |i| texel(i, j)))
        .sum::<Vec3>()
        / (w * h) as f32;
    let cos_total = (t * (1.0f32 + 1.0 / 4.0).sqrt()).atan().cos();
    let want = pbrs::geometry::luminance(i_ * mean * 2.0 * PI * (1.0 - cos_total));
    assert!(
        (l.power() - want).abs() < 1e-4 * want,
        "{} vs {want}",
        l.power()
    );
    // Aspect 1/2: the window is [−1, 1] × [−2, 2] and fov spans x.
    let files = map(4, 8);
    let (l, sc) = light_of(
        "",
        &format!("LightSource \"projection\" \"float fov\" {fov} \"string mapname\" \"map.pfm\""),
        &files,
    );
    let d = |sx: f32, sy: f32| Vec3::new(sx * t, sy * t, 1.0).normalize();
    let got = li_towards(
        &l,
        &sc,
        Vec3::ZERO,
        d(-1.0 + 2.0 * 0.625, -2.0 + 4.0 * 0.0625),
        1.0,
    );
    assert!(close(got, texel(2, 0), 2e-4), "{got}");
    assert_eq!(
        li_towards(&l, &sc, Vec3::ZERO, d(1.05, 0.0), 1.0),
        Vec3::ZERO
    );
    assert_ne!(
        li_towards(&l, &sc, Vec3::ZERO, d(0.0, 1.95), 1.0),
        Vec3::ZERO
    );
}

fn ones(w: usize, h: usize) -> MemFiles {
    let mut f = MemFiles::default();
    f.0.insert(
        tex_common::dir().join("ones.pfm"),
        pfm(w, h, &vec![[1.0; 3]; w * h]),
    );
    f
}

fn render_with(light: &str, files: &MemFiles) -> Image {
    let s = load(
        &format!(
            "LookAt 0 4 0  0 0 0  0 0 1\nCamera \"perspective\" \"float fov\" 60\n\
             Film \"image\" \"integer xresolution\" 32 \"integer yresolution\" 32\n\
             Sampler \"halton\" \"integer pixelsamples\" 4\nIntegrator \"path\" \"integer maxdepth\" 2\n\
             WorldBegin\nAttributeBegin\nTranslate 0 1.5 0\nRotate 90 1 0 0\n{light}\nAttributeEnd\n\
             Material \"matte\"\nShape \"trianglemesh\" \"point P\" [-3 0 -3  3 0 -3  3 0 3  -3 0 3] \"integer indices\" [0 1 2 0 2 3]\n\
             WorldEnd\n"
        ),
        files,
    );
    render(&s.scene, &RenderOptions::default(), &|_, _| {})
        .unwrap()
        .0
}

/// A map of ones: the goniometric light renders the point light's image
/// byte for byte; the projection light renders it inside its frustum and
/// black outside.
#[test]
fn maps_of_ones_render_the_point_light() {
    let files = ones(8, 4);
    let point = render_with("LightSource \"point\" \"rgb I\" [3 3 3]", &files);
    let gonio = render_with(
        "LightSource \"goniometric\" \"rgb I\" [3 3 3] \"string mapname\" \"ones.pfm\"",
        &files,
    );
    // (The bilinear weights of a lookup sum to 1 within rounding.)
    let same = |a: &[f32], b: &[f32]| {
        a.iter()
            .zip(b)
            .all(|(x, y)| (x - y).abs() <= 1e-6 * y.abs())
    };
    assert!(
        same(&gonio.data, &point.data),
        "goniometric and point images differ"
    );
    // The light looks down (−y) from 1.5 above the floor; fov 60 across the
    // map's shorter side (y of aspect 2) and 2·atan(2·tan 30°) across x.
    let proj = render_with(
        "LightSource \"projection\" \"rgb I\" [3 3 3] \"float fov\" 60 \"string mapname\" \"ones.pfm\"",
        &files,
    );
    // Pixels are dark (outside), the point light's (inside), or, where
    // the frustum's edge crosses the pixel filter, in between.
    let (mut inside, mut outside, mut edge) = (0, 0, 0);
    for (a, b) in proj.data.chunks(3).zip(point.data.chunks(3)) {
        if a[0] == 0.0 {
            outside += 1;
        } else if same(a, b) {
            inside += 1;
        } else {
            assert!(a[0] < b[0], "{a:?} vs {b:?}");
            edge += 1;
        }
    }
    assert!(
        inside > 150 && outside > 150 && edge < 160,
        "{inside} lit, {outside} dark, {edge} on the edge"
    );
}
