//! Bump mapping (pbrt-v3's `Material::Bump` for every material) on known
//! height fields, and alpha cutouts (`alpha`, `shadowalpha`) for closest
//! hits, shadow rays, instances and whole renders.

mod tex_common;

use glam::{Vec2, Vec3};
use pbrs::geometry::Ray;
use pbrs::integrators::RenderScene;
use pbrs::materials::{BsdfContext, Material};
use pbrs::render::driver::{render, RenderOptions};
use pbrs::scene::Surface;
use tex_common::*;

/// The material of `Material {decl}` (with texture statements `textures`
/// before it), built for rendering.
fn material(textures: &str, decl: &str) -> Material {
    let s = load(
        &format!("WorldBegin\n{textures}\nMaterial {decl}\nShape \"sphere\"\nWorldEnd\n"),
        &MemFiles::default(),
    );
    let w = warnings(&s);
    assert!(w.is_empty(), "{w}");
    Material::new(&s.scene.materials[0])
}

/// The shading normal of the material's BSDF at `at`.
fn bumped_normal(m: &Material, at: &At) -> Vec3 {
    let ms = [m.clone()];
    let ctx = BsdfContext {
        materials: &ms,
        multiple_lobes: true,
    };
    let n = m.bsdf(&at.sc(), &ctx).frame.n;
    n
}

#[track_caller]
fn assert_dir(got: Vec3, want: Vec3) {
    let want = want.normalize();
    assert!(
        (got - want).length() < 2e-4,
        "normal {got} vs expected {want}"
    );
}

/// d(u, v) = k·u as a float bilerp (v00 = v01 = 0, v10 = v11 = k).
fn ramp(name: &str, k: f32) -> String {
    format!("Texture \"{name}\" \"float\" \"bilerp\" \"float v00\" 0 \"float v01\" 0 \"float v10\" {k} \"float v11\" {k}")
}

#[test]
fn a_linear_ramp_tilts_the_normal() {
    for k in [0.5f32, -2.0] {
        let m = material(&ramp("d", k), "\"matte\" \"texture bumpmap\" \"d\"");
        assert!(matches!(m, Material::Bumped(_)));
        assert!(m.needs_geom());
        // z-up plane, dp/du = x, dp/dv = y: dp'/du = x + k·z, so the
        // normal is (−k, 0, 1) normalised, whatever the step.
        for at in [At::uv(0.3, 0.6), At::uv(0.9, 0.1).duv(0.1, 0.0, 0.2, 0.05)] {
            assert_dir(bumped_normal(&m, &at), Vec3::new(-k, 0.0, 1.0));
        }
    }
}

#[test]
fn the_finite_difference_step_is_pbrt_v3s() {
    // d = u² (a ramp times itself): pbrt-v3's forward difference gives the
    // slope 2u + du, with du = ½(|du/dx| + |du/dy|), or 0.0005 without
    // differentials.
    let tex = format!(
        "{}\nTexture \"d\" \"float\" \"scale\" \"texture tex1\" \"r\" \"texture tex2\" \"r\"",
        ramp("r", 1.0)
    );
    let m = material(&tex, "\"mirror\" \"texture bumpmap\" \"d\"");
    let u = 0.3f32;
    assert_dir(
        bumped_normal(&m, &At::uv(u, 0.5)),
        Vec3::new(-(2.0 * u + 0.0005), 0.0, 1.0),
    );
    let at = At::uv(u, 0.5).duv(0.1, 0.0, -0.3, 0.0);
    assert_dir(
        bumped_normal(&m, &at),
        Vec3::new(-(2.0 * u + 0.2), 0.0, 1.0),
    );
    // The same along v.
    let tex_v = "Texture \"r\" \"float\" \"bilerp\" \"float v00\" 0 \"float v10\" 0 \"float v01\" 1 \"float v11\" 1\nTexture \"d\" \"float\" \"scale\" \"texture tex1\" \"r\" \"texture tex2\" \"r\"";
    let m = material(tex_v, "\"glass\" \"texture bumpmap\" \"d\"");
    let at = At::uv(0.5, 0.7).duv(0.0, 0.05, 0.0, 0.05);
    assert_dir(bumped_normal(&m, &at), Vec3::new(0.0, -(1.4 + 0.05), 1.0));
}

#[test]
fn bump_orientation_and_normal_derivatives() {
    // A reversed surface (normals −z, tangents unchanged): the bumped
    // normal is turned to the geometric normal's side.
    let m = material(&ramp("d", 0.5), "\"matte\" \"texture bumpmap\" \"d\"");
    let mut at = At::uv(0.4, 0.4);
    at.hit.point.n = -Vec3::Z;
    at.hit.point.ns = -Vec3::Z;
    // (p' = p + d·ns = p − ½u·z: the tangent (1, 0, −½), the normal on
    // the −z side (−½, 0, −1).)
    assert_dir(bumped_normal(&m, &at), Vec3::new(-0.5, 0.0, -1.0));
    // A constant displacement moves the surface along the normal: with
    // ∂n/∂u = (0, 0, 0.5), dp'/du = x + 0.2·(0, 0, 0.5).
    let c = material("", "\"matte\" \"float bumpmap\" 0.2");
    let mut at = At::uv(0.4, 0.4);
    at.geom.shading_dndu = Vec3::new(0.0, 0.0, 0.5);
    assert_dir(bumped_normal(&c, &at), Vec3::new(-0.1, 0.0, 1.0));
    // A constant 0 displaces nothing: no bump at all.
    let z = material("", "\"matte\" \"float bumpmap\" 0");
    assert!(matches!(z, Material::Matte(_)));
}

/// A z-up 2×2 quad at the origin with uv over [0, 1]², as a Shape.
const QUAD: &str = "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] \"point P\" [-1 -1 0 1 -1 0 1 1 0 -1 1 0] \"point2 uv\" [0 0 1 0 1 1 0 1]";

#[test]
fn the_integrator_shades_with_the_bumped_normal() {
    // Light straight down on a bumped matte plane, seen from above, with
    // directlighting (a delta light: no noise). d = u over a plane 2 wide:
    // dp'/du = (2, 0, 1), dp'/dv = (0, 2, 0), so cos θ = 4/√20.
    let scene = format!(
        "Film \"image\" \"integer xresolution\" 8 \"integer yresolution\" 8\nSampler \"random\" \"integer pixelsamples\" 1\nIntegrator \"directlighting\"\nLookAt 0 0 5 0 0 0 0 1 0\nCamera \"perspective\" \"float fov\" 10\nWorldBegin\nLightSource \"distant\" \"point from\" [0 0 1] \"point to\" [0 0 0] \"rgb L\" [1 1 1]\n{}\nMaterial \"matte\" \"rgb Kd\" [0.5 0.5 0.5] \"texture bumpmap\" \"d\"\n{QUAD}\nWorldEnd",
        ramp("d", 1.0)
    );
    let s = load(&scene, &MemFiles::default());
    let (img, _) = render(&s.scene, &RenderOptions::default(), &|_, _| {}).unwrap();
    let expect = 0.5 / std::f32::consts::PI * 4.0 / 20f32.sqrt();
    for v in &img.data {
        assert!((v - expect).abs() < 1e-3 * expect, "{v} vs {expect}");
    }
}

/// The render-ready scene of world statements `world`.
fn render_scene(world: &str) -> (RenderScene, String, Vec<String>) {
    let s = load(
        &format!("WorldBegin\n{world}\nWorldEnd\n"),
        &MemFiles::default(),
    );
    let w = warnings(&s);
    (RenderScene::new(&s.scene), w, s.scene.skipped.clone())
}

fn down_ray(x: f32, y: f32) -> Ray {
    Ray {
        o: Vec3::new(x, y, -1.0),
        d: Vec3::Z,
        t_max: 10.0,
    }
}

/// Cell parity of the alpha checkerboard "ck" (tex1 1 on even cells of
/// (2u, 2v), tex2 0 on odd ones) at world (x, y) of [`QUAD`].
fn solid(x: f32, y: f32) -> bool {
    let (u, v) = ((x + 1.0) / 2.0, (y + 1.0) / 2.0);
    ((2.0 * u).floor() + (2.0 * v).floor()) as i32 % 2 == 0
}

const CK: &str = "Texture \"ck\" \"float\" \"checkerboard\" \"float uscale\" 2 \"float vscale\" 2 \"string aamode\" \"none\"";

fn sample_points() -> Vec<Vec2> {
    let mut v = Vec::new();
    for i in 0..9 {
        for j in 0..9 {
            v.push(Vec2::new(
                -0.9 + 0.2 * i as f32 + 0.013,
                -0.9 + 0.2 * j as f32 + 0.007,
            ));
        }
    }
    v
}

#[test]
fn alpha_cuts_closest_hits_and_shadow_rays() {
    let (rs, w, _) = render_scene(&format!(
        "{CK}\n{QUAD} \"texture alpha\" \"ck\"\nTranslate 5 0 0\n{QUAD} \"texture shadowalpha\" \"ck\""
    ));
    assert!(w.is_empty(), "{w}");
    let g = &rs.aggregate;
    let (mut cut, mut kept) = (0, 0);
    for p in sample_points() {
        let s = solid(p.x, p.y);
        // alpha: ignored by every ray where it is 0.
        assert_eq!(g.intersect(&down_ray(p.x, p.y)).is_some(), s, "{p}");
        assert_eq!(g.occluded(&down_ray(p.x, p.y)), s, "{p}");
        // shadowalpha: seen by closest-hit rays, ignored by shadow rays.
        assert!(g.intersect(&down_ray(p.x + 5.0, p.y)).is_some(), "{p}");
        assert_eq!(g.occluded(&down_ray(p.x + 5.0, p.y)), s, "{p}");
        if s {
            kept += 1
        } else {
            cut += 1
        }
    }
    assert!(cut > 20 && kept > 20);
    // A ray through a hole finds what lies behind.
    let behind = render_scene(&format!(
        "{CK}\n{QUAD} \"texture alpha\" \"ck\"\nTranslate 0 0 2\n{QUAD}"
    ))
    .0;
    let hole = sample_points()
        .into_iter()
        .find(|p| !solid(p.x, p.y))
        .unwrap();
    let h = behind
        .aggregate
        .intersect(&down_ray(hole.x, hole.y))
        .unwrap();
    assert!((h.t - 3.0).abs() < 1e-4, "{}", h.t);
}

#[test]
fn alpha_in_instances_and_constant_alphas() {
    let (rs, _, _) = render_scene(&format!(
        "{CK}\nObjectBegin \"o\"\n{QUAD} \"texture alpha\" \"ck\"\nObjectEnd\nTranslate 0 10 0\nObjectInstance \"o\""
    ));
    for p in sample_points() {
        assert_eq!(
            rs.aggregate.intersect(&down_ray(p.x, p.y + 10.0)).is_some(),
            solid(p.x, p.y),
            "{p}"
        );
    }
    // A constant alpha 0 hides a shape from every ray: it is left out
    // (noted), unless it emits (lights still sample it).
    let (rs, _, skipped) = render_scene(&format!("{QUAD} \"float alpha\" 0"));
    assert!(rs.aggregate.meshes.is_empty());
    assert!(
        skipped.iter().any(|s| s.contains("\"alpha\" 0")),
        "{skipped:?}"
    );
    let (rs, _, _) = render_scene(&format!(
        "AreaLightSource \"diffuse\"\n{QUAD} \"float alpha\" 0"
    ));
    assert_eq!(rs.lights.len(), 2, "an emitter stays a light");
    assert!(rs.aggregate.intersect(&down_ray(0.1, 0.1)).is_none());
    // Constants other than 0 cut nothing; a missing texture warns.
    let (rs, w, _) = render_scene(&format!(
        "{QUAD} \"float alpha\" 0.5\nTranslate 5 0 0\n{QUAD} \"texture alpha\" \"nope\"\nShape \"sphere\" \"float alpha\" 0"
    ));
    assert!(rs.aggregate.meshes.iter().all(|m| m.alpha.is_none()));
    assert!(
        w.contains("couldn't find float texture \"nope\" for \"alpha\""),
        "{w}"
    );
    // pbrt-v3 reads alpha for triangle meshes only.
    assert!(w.contains("\"float alpha\" not used"), "{w}");
    let s = load(
        &format!("WorldBegin\n{CK}\n{QUAD} \"texture alpha\" \"ck\"\nWorldEnd"),
        &MemFiles::default(),
    );
    assert!(matches!(
        s.scene.shapes[0].surface,
        Surface::TriangleMesh(_)
    ));
    assert!(s
        .summary
        .to_string()
        .contains("alpha:      1 shapes with alpha masks"));
}

#[test]
fn a_checkerboard_cutout_shows_half_of_the_light_behind() {
    // Camera at z = −5 looking at a black quad with an 8×8 checkerboard
    // alpha, an emitter behind it. The view spans uv [0.25, 0.75]² (4×4
    // checks, 8×8 pixels each at 32×32), so every pixel is wholly light or
    // wholly black, half of them light.
    let fov = 2.0 * 0.1f64.atan().to_degrees();
    let scene = format!(
        "Film \"image\" \"integer xresolution\" 32 \"integer yresolution\" 32\nSampler \"halton\" \"integer pixelsamples\" 4\nIntegrator \"path\" \"integer maxdepth\" 1\nLookAt 0 0 -5 0 0 0 0 1 0\nCamera \"perspective\" \"float fov\" {fov}\nWorldBegin\nTexture \"ck\" \"float\" \"checkerboard\" \"float uscale\" 8 \"float vscale\" 8 \"string aamode\" \"none\"\nAttributeBegin\nMaterial \"matte\" \"rgb Kd\" [0 0 0]\n{QUAD} \"texture alpha\" \"ck\"\nAttributeEnd\nAttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [1 1 1] \"bool twosided\" \"true\"\nTranslate 0 0 1\nScale 10 10 1\n{QUAD}\nAttributeEnd\nWorldEnd"
    );
    let s = load(&scene, &MemFiles::default());
    let (img, _) = render(&s.scene, &RenderOptions::default(), &|_, _| {}).unwrap();
    let px: Vec<f32> = img.data.chunks(3).map(|c| c[0]).collect();
    // (Samples that fall exactly on a pixel edge, which is a check edge,
    // land on either side: a few pixels are partly covered.)
    let partial = px
        .iter()
        .filter(|&&v| v.abs() > 1e-4 && (v - 1.0).abs() > 1e-4)
        .count();
    assert!(partial < 16, "{partial} pixels partly covered");
    let mean = px.iter().map(|&v| v as f64).sum::<f64>() / px.len() as f64;
    assert!((mean - 0.5).abs() < 0.005, "hole fraction {mean}");
    // 8×8 blocks, alternating.
    let at = |x: usize, y: usize| px[y * 32 + x] > 0.5;
    for y in 0..32 {
        for x in 0..32 {
            assert_eq!(at(x, y), at(x % 8, y % 8) ^ ((x / 8 + y / 8) % 2 == 1));
        }
    }
}
