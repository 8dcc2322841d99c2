//! Scene building semantics, as pbrt-v3 defines them (see grammar/REFERENCE.md).

mod common;

use common::{error_text as errors, load_text as load, warning_text as warnings};
use glam::{DMat4, DVec3, Vec2, Vec3};
use pbrs::cameras::Projection;
use pbrs::filters::{BoxFilter, Filter, Gaussian, LanczosSinc, Mitchell, Triangle};
use pbrs::loader::{load_scene, load_scene_str, LoadedScene};
use pbrs::scene::*;
use pbrs::shapes::AnalyticShape;
use std::path::{Path, PathBuf};
use std::sync::Arc;

fn tmpdir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pbrs-lang-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn close(a: DVec3, b: DVec3) -> bool {
    (a - b).length() < 1e-9
}

/// `close` for what the render core holds in f32 (built lights).
fn close32(a: Vec3, b: Vec3) -> bool {
    (a - b).length() < 1e-6
}

/// (Kd, sigma) of a matte description (panics for other kinds).
fn matte_of(d: &MaterialDesc) -> (Vec3, f32) {
    assert_eq!(d.kind, "matte", "{d:?}");
    (
        d.constant_spectrum("Kd").unwrap(),
        d.constant_float("sigma").unwrap(),
    )
}

/// (Kr, Kt, eta) of a glass description.
fn glass_of(d: &MaterialDesc) -> (Vec3, Vec3, f32) {
    assert_eq!(d.kind, "glass", "{d:?}");
    let eta = d
        .constant_float("eta")
        .or_else(|| d.constant_float("index"))
        .unwrap();
    (
        d.constant_spectrum("Kr").unwrap(),
        d.constant_spectrum("Kt").unwrap(),
        eta,
    )
}

#[test]
fn defaults_without_options() {
    let s = load("WorldBegin\nWorldEnd\n").scene;
    assert_eq!((s.film.xresolution, s.film.yresolution), (1280, 720));
    assert_eq!(s.film.filename, PathBuf::from("pbrt.exr"));
    assert_eq!(s.film.cropwindow, [0.0, 1.0, 0.0, 1.0]);
    assert_eq!(
        s.filter,
        Filter::Box(BoxFilter {
            radius: Vec2::splat(0.5)
        })
    );
    assert_eq!(
        s.sampler,
        SamplerDesc {
            kind: SamplerKind::Halton,
            pixel_samples: 16,
            sample_pixel_center: false
        }
    );
    assert_eq!(
        s.integrator,
        IntegratorSettings::Path(pbrs::scene::PathSettings {
            max_depth: 5,
            rr_threshold: 1.0,
            light_sample_strategy: LightSampleStrategy::Spatial
        })
    );
    let Projection::Perspective(c) = &s.camera.projection else {
        panic!("not perspective")
    };
    assert_eq!((c.fov, c.focal_distance()), (90.0, 1e6));
}

#[test]
fn filters_and_samplers_defaults() {
    let f = |t: &str| {
        load(&format!("PixelFilter \"{t}\"\nWorldBegin\nWorldEnd"))
            .scene
            .filter
    };
    assert_eq!(
        f("gaussian"),
        Filter::Gaussian(Gaussian::new(Vec2::splat(2.0), 2.0))
    );
    assert_eq!(
        f("triangle"),
        Filter::Triangle(Triangle {
            radius: Vec2::splat(2.0)
        })
    );
    assert_eq!(
        f("mitchell"),
        Filter::Mitchell(Mitchell {
            radius: Vec2::splat(2.0),
            b: 1.0 / 3.0,
            c: 1.0 / 3.0
        })
    );
    assert_eq!(
        f("sinc"),
        Filter::LanczosSinc(LanczosSinc {
            radius: Vec2::splat(4.0),
            tau: 3.0
        })
    );
    let s = |t: &str| {
        load(&format!("Sampler {t}\nWorldBegin\nWorldEnd"))
            .scene
            .sampler
    };
    assert_eq!(
        s("\"stratified\" \"bool jitter\" \"false\" \"integer xsamples\" 2"),
        SamplerDesc {
            kind: SamplerKind::Stratified {
                jitter: false,
                xsamples: 2,
                ysamples: 4
            },
            pixel_samples: 8,
            sample_pixel_center: false
        }
    );
    assert_eq!(s("\"random\"").pixel_samples, 4);
    assert_eq!(
        s("\"lowdiscrepancy\"").kind,
        SamplerKind::ZeroTwoSequence { dimensions: 4 }
    );
    assert_eq!(
        s("\"02sequence\"").kind,
        SamplerKind::ZeroTwoSequence { dimensions: 4 }
    );
    assert_eq!(
        s("\"maxmindist\"").kind,
        SamplerKind::MaxMinDist { dimensions: 4 }
    );
    assert_eq!(s("\"sobol\" \"integer pixelsamples\" 32").pixel_samples, 32);
}

#[test]
fn integrators() {
    let i = |t: &str| load(&format!("Integrator {t}\nWorldBegin\nWorldEnd"));
    assert_eq!(
        i("\"whitted\" \"integer maxdepth\" 3").scene.integrator,
        IntegratorSettings::Whitted(pbrs::scene::WhittedSettings { max_depth: 3 })
    );
    assert_eq!(
        i("\"directlighting\" \"string strategy\" \"one\"")
            .scene
            .integrator,
        IntegratorSettings::DirectLighting(pbrs::scene::DirectLightingSettings {
            max_depth: 5,
            strategy: DirectStrategy::One
        })
    );
    let b = i("\"bdpt\" \"integer maxdepth\" 7");
    assert!(matches!(
        b.scene.integrator,
        IntegratorSettings::Bdpt(pbrs::integrators::BdptSettings { max_depth: 7, .. })
    ));
    assert_eq!(warnings(&b), "");
    let m = i("\"mlt\" \"integer maxdepth\" 7 \"integer chains\" 12 \"float sigma\" 0.05");
    assert_eq!(
        m.scene.integrator,
        IntegratorSettings::Mlt(pbrs::integrators::MltSettings {
            max_depth: 7,
            chains: 12,
            sigma: 0.05,
            ..Default::default()
        })
    );
    assert_eq!(warnings(&m), "");
}

#[test]
fn transforms_post_multiply_and_transform_is_column_major() {
    let s = load("WorldBegin\nTranslate 1 0 0\nScale 2 2 2\nShape \"sphere\"\nTransform [1 0 0 0  0 1 0 0  0 0 1 0  5 6 7 1]\nShape \"sphere\"\nConcatTransform [2 0 0 0 0 2 0 0 0 0 2 0 0 0 0 1]\nShape \"sphere\"\nWorldEnd").scene;
    let m = s.shapes[0].object_to_world;
    assert!(close(
        m.transform_point3(DVec3::X),
        DVec3::new(3.0, 0.0, 0.0)
    ));
    assert!(close(
        s.shapes[1].object_to_world.transform_point3(DVec3::ZERO),
        DVec3::new(5.0, 6.0, 7.0)
    ));
    assert!(close(
        s.shapes[2].object_to_world.transform_point3(DVec3::X),
        DVec3::new(7.0, 6.0, 7.0)
    ));
}

#[test]
fn rotate_is_in_degrees() {
    let s = load("WorldBegin\nRotate 90 0 0 1\nShape \"sphere\"\nWorldEnd").scene;
    assert!(close(
        s.shapes[0].object_to_world.transform_point3(DVec3::X),
        DVec3::Y
    ));
}

#[test]
fn attribute_and_transform_stacks() {
    let s = load("WorldBegin\nAttributeBegin\nTranslate 1 0 0\nMaterial \"mirror\"\nReverseOrientation\nAttributeEnd\nShape \"sphere\"\nTransformBegin\nTranslate 0 1 0\nMaterial \"glass\"\nTransformEnd\nShape \"sphere\"\nWorldEnd").scene;
    assert_eq!(s.shapes[0].object_to_world, DMat4::IDENTITY);
    assert!(!s.shapes[0].reverse_orientation);
    assert_eq!(
        matte_of(&s.materials[s.shapes[0].material.0 as usize]),
        (Vec3::splat(0.5), 0.0)
    );
    // TransformEnd restores the CTM only: the material set inside stays.
    assert_eq!(s.shapes[1].object_to_world, DMat4::IDENTITY);
    assert_eq!(
        glass_of(&s.materials[s.shapes[1].material.0 as usize]).2,
        1.5
    );
}

#[test]
fn camera_coordinate_system_and_world_reset() {
    let s = load("Translate 0 0 5\nCamera \"perspective\" \"float fov\" 45\nWorldBegin\nCoordSysTransform \"camera\"\nLightSource \"point\"\nWorldEnd").scene;
    // Camera-to-world = inverse(CTM) = Translate(0,0,-5); the light sits at the camera.
    assert!(close(
        s.camera.camera_to_world.transform_point3(DVec3::ZERO),
        DVec3::new(0.0, 0.0, -5.0)
    ));
    let Light::Point(light) = &s.lights[0] else {
        panic!()
    };
    assert!(close32(light.p, Vec3::new(0.0, 0.0, -5.0)));
    let Projection::Perspective(c) = &s.camera.projection else {
        panic!("not perspective")
    };
    assert_eq!(c.fov, 45.0);
}

#[test]
fn halffov_and_named_coordinate_systems() {
    let s = load("Camera \"perspective\" \"float halffov\" 30\nWorldBegin\nTranslate 1 2 3\nCoordinateSystem \"here\"\nIdentity\nCoordSysTransform \"here\"\nShape \"sphere\"\nCoordSysTransform \"nowhere\"\nWorldEnd");
    let Projection::Perspective(c) = &s.scene.camera.projection else {
        panic!("not perspective")
    };
    assert_eq!(c.fov, 60.0);
    assert!(close(
        s.scene.shapes[0]
            .object_to_world
            .transform_point3(DVec3::ZERO),
        DVec3::new(1.0, 2.0, 3.0)
    ));
    assert!(
        warnings(&s).contains("mem.pbrt:8:19: unknown coordinate system \"nowhere\""),
        "{}",
        warnings(&s)
    );
}

#[test]
fn area_light_applies_to_later_shapes_in_scope() {
    let s = load("WorldBegin\nShape \"sphere\"\nAttributeBegin\nAreaLightSource \"area\" \"rgb L\" [1 2 3] \"float scale\" 2 \"bool twosided\" \"true\" \"integer samples\" 4\nShape \"sphere\"\nShape \"sphere\"\nAttributeEnd\nShape \"sphere\"\nWorldEnd").scene;
    let lit: Vec<bool> = s.shapes.iter().map(|sh| sh.area_light.is_some()).collect();
    assert_eq!(lit, [false, true, true, false]);
    assert_eq!(
        s.shapes[1].area_light,
        Some(DiffuseEmission {
            l: Vec3::new(2.0, 4.0, 6.0),
            two_sided: true,
            n_samples: 4
        })
    );
}

#[test]
fn lights() {
    let s = load("WorldBegin\nTranslate 1 0 0\nLightSource \"point\" \"rgb I\" [1 1 1] \"rgb scale\" [2 2 2] \"point from\" [0 1 0]\nLightSource \"distant\" \"point from\" [0 0 0] \"point to\" [0 0 1]\nLightSource \"spot\" \"point from\" [0 0 0] \"point to\" [0 1 0] \"float coneangle\" 20\nLightSource \"infinite\" \"rgb L\" [0.5 0.5 0.5]\nLightSource \"goniometric\"\nWorldEnd");
    let l = &s.scene.lights;
    assert_eq!(l.len(), 5);
    let Light::Point(point) = &l[0] else { panic!() };
    assert!(close32(point.p, Vec3::new(1.0, 1.0, 0.0)));
    assert_eq!(point.intensity, Vec3::splat(2.0));
    let Light::Distant(distant) = &l[1] else {
        panic!()
    };
    assert!(close32(distant.w, Vec3::new(0.0, 0.0, -1.0)));
    let Light::Spot(spot) = &l[2] else { panic!() };
    assert_eq!(spot.cos_total, 20f32.to_radians().cos());
    // The spot's +z axis points from `from` to `to`, its origin at CTM·from.
    assert!(close32(spot.frame.n, Vec3::Y));
    assert!(close32(spot.p, Vec3::X));
    assert!(matches!(&l[3], Light::Infinite(i) if i.n_samples == 1));
    let Light::Goniometric(g) = &l[4] else {
        panic!()
    };
    assert!(close32(g.p, Vec3::X) && g.map.is_none());
    // pbrt-v3 point.cpp: Translate(from) · CTM, so `from` is not scaled by the CTM.
    let s = load("WorldBegin\nTranslate 1 0 0\nScale 2 2 2\nLightSource \"point\" \"point from\" [0 1 0]\nWorldEnd");
    let Light::Point(point) = &s.scene.lights[0] else {
        panic!()
    };
    assert!(close32(point.p, Vec3::new(1.0, 1.0, 0.0)), "{}", point.p);
}

#[test]
fn colours() {
    let kd = |p: &str| {
        let s = load(&format!(
            "WorldBegin\nMaterial \"matte\" {p}\nShape \"sphere\"\nWorldEnd"
        ));
        matte_of(&s.scene.materials[0]).0
    };
    assert_eq!(kd("\"color Kd\" [0.1 0.2 0.3]"), Vec3::new(0.1, 0.2, 0.3));
    let x = kd("\"xyz Kd\" [0.9505 1 1.089]");
    assert!((x - Vec3::ONE).abs().max_element() < 0.01, "{x}");
    let b = kd("\"blackbody Kd\" [3000 1]");
    assert!(b.x > b.y && b.y > b.z, "{b}");
    let flat = kd("\"spectrum Kd\" [400 0.5 700 0.5]");
    let y = 0.2126 * flat.x + 0.7152 * flat.y + 0.0722 * flat.z;
    assert!((y - 0.5).abs() < 0.02, "{flat}");
    let s = load(
        "WorldBegin\nMaterial \"matte\" \"spectrum Kd\" \"metal.spd\"\nShape \"sphere\"\nWorldEnd",
    );
    // A spectrum file that cannot be read is black, with a warning (pbrt-v3);
    // files that can are tested in tests/lang_spectra.rs.
    assert!(
        warnings(&s).contains("cannot read spectrum file \"metal.spd\" for \"Kd\""),
        "{}",
        warnings(&s)
    );
    assert_eq!(matte_of(&s.scene.materials[0]), (Vec3::ZERO, 0.0));
}

#[test]
fn materials_and_substitutes() {
    let m = |t: &str| {
        let s = load(&format!(
            "WorldBegin\nMaterial {t}\nShape \"sphere\"\nWorldEnd"
        ));
        (s.scene.materials[0].clone(), warnings(&s))
    };
    assert_eq!(glass_of(&m("\"glass\"").0), (Vec3::ONE, Vec3::ONE, 1.5));
    assert_eq!(
        glass_of(&m("\"glass\" \"float index\" 1.33").0),
        (Vec3::ONE, Vec3::ONE, 1.33)
    );
    assert_eq!(
        glass_of(&m("\"glass\" \"float eta\" 2 \"float index\" 1.2").0),
        (Vec3::ONE, Vec3::ONE, 2.0)
    );
    // Rough glass is rendered as rough glass: no warning.
    let (g, w) = m("\"glass\" \"float uroughness\" 0.1");
    assert!(g.kind == "glass" && w.is_empty(), "{w}");
    assert_eq!(g.constant_float("uroughness"), Some(0.1));
    assert_eq!(g.constant_float("vroughness"), Some(0.0));
    assert_eq!(
        m("\"mirror\"").0.constant_spectrum("Kr"),
        Some(Vec3::splat(0.9))
    );
    assert_eq!(m("\"none\"").0.kind, "none");
    assert_eq!(m("\"\"").0.kind, "none");
    let (h, w) = m("\"hair\" \"float eumelanin\" 1.3");
    assert!(h.kind == "hair" && w.is_empty(), "{w}");
    // pbrt-v3's warnings about the absorption parameters it ignores.
    let (_, w) =
        m("\"hair\" \"rgb sigma_a\" [1 1 1] \"rgb color\" [0.5 0.5 0.5] \"float pheomelanin\" 1");
    assert!(
        w.contains("ignoring \"color\" parameter since \"sigma_a\" was provided")
            && w.contains("ignoring \"pheomelanin\" parameter since \"sigma_a\" was provided"),
        "{w}"
    );
    // A shape parameter that nothing uses is reported even when the material is substituted.
    let s = load("WorldBegin\nMaterial \"metal\"\nShape \"sphere\" \"float radiuss\" 2\nWorldEnd");
    assert!(
        warnings(&s)
            .contains("mem.pbrt:3:16: parameter \"float radiuss\" not used by Shape \"sphere\""),
        "{}",
        warnings(&s)
    );
    let (u, w) = m("\"BUSH1\"");
    assert_eq!(matte_of(&u), (Vec3::splat(0.5), 0.0));
    assert!(w.contains("unknown material type \"BUSH1\""), "{w}");
    assert_eq!(
        matte_of(&m("\"matte\" \"float sigma\" 20").0),
        (Vec3::splat(0.5), 20.0)
    );
}

#[test]
fn textures_constant_named_and_missing() {
    let s = load("WorldBegin\nTexture \"c\" \"color\" \"constant\" \"rgb value\" [0.1 0.2 0.3]\nTexture \"s\" \"float\" \"constant\" \"float value\" 10\nTexture \"ch\" \"color\" \"checkerboard\"\nMaterial \"matte\" \"texture Kd\" \"c\" \"texture sigma\" \"s\"\nShape \"sphere\"\nMaterial \"matte\" \"texture Kd\" \"ch\"\nShape \"sphere\"\nMaterial \"matte\" \"texture Kd\" \"missing\"\nShape \"sphere\"\nMaterial \"matte\" \"texture Kd\" \"s\"\nShape \"sphere\"\nWorldEnd");
    let m = &s.scene.materials;
    assert_eq!(matte_of(&m[0]), (Vec3::new(0.1, 0.2, 0.3), 10.0));
    assert!(
        m[1].constant_spectrum("Kd").is_none(),
        "a checkerboard Kd is a texture: {:?}",
        m[1]
    );
    assert_eq!(matte_of(&m[2]), (Vec3::splat(0.5), 0.0));
    assert_eq!(m.len(), 3, "the default-valued materials are one");
    let w = warnings(&s);
    assert!(
        w.contains("mem.pbrt:9:31: unknown spectrum texture \"missing\""),
        "{w}"
    );
    assert!(
        w.contains("unknown spectrum texture \"s\" for \"Kd\" (\"s\" is a float texture)"),
        "{w}"
    );
}

#[test]
fn named_materials_are_scoped_and_unused_ones_left_out() {
    let s = load("WorldBegin\nMakeNamedMaterial \"red\" \"string type\" \"matte\" \"rgb Kd\" [1 0 0]\nMakeNamedMaterial \"unused\" \"string type\" \"mirror\"\nAttributeBegin\nMakeNamedMaterial \"inner\" \"string type\" \"glass\"\nAttributeEnd\nNamedMaterial \"red\"\nShape \"sphere\"\nWorldEnd");
    assert_eq!(s.scene.materials.len(), 1);
    assert_eq!(matte_of(&s.scene.materials[0]), (Vec3::X, 0.0));
    let skipped = s.scene.skipped.join("\n");
    assert!(skipped.contains("named material \"unused\""), "{skipped}");
    assert!(skipped.contains("named material \"inner\""), "{skipped}");
    let e = errors("WorldBegin\nAttributeBegin\nMakeNamedMaterial \"inner\" \"string type\" \"glass\"\nAttributeEnd\nNamedMaterial \"inner\"\nWorldEnd");
    assert!(
        e.contains("mem.pbrt:5:15: unknown named material \"inner\""),
        "{e}"
    );
}

#[test]
fn shape_parameters_override_the_material() {
    let s = load("WorldBegin\nMaterial \"matte\" \"rgb Kd\" [1 0 0]\nShape \"sphere\" \"rgb Kd\" [0 1 0]\nShape \"sphere\"\nWorldEnd");
    let m = |i: usize| s.scene.materials[s.scene.shapes[i].material.0 as usize].clone();
    assert_eq!(matte_of(&m(0)), (Vec3::Y, 0.0));
    assert_eq!(matte_of(&m(1)), (Vec3::X, 0.0));
    assert!(s.warnings.is_empty(), "{}", warnings(&s));
}

#[test]
fn unused_parameters_are_reported_by_name() {
    let s = load("Camera \"perspective\" \"float fov\" 30 \"float fovv\" 3\nWorldBegin\nShape \"sphere\" \"float radius\" 2 \"integer radius2\" 1\nLightSource \"point\" \"rgb L\" [1 1 1]\nWorldEnd");
    let w = warnings(&s);
    assert!(
        w.contains("mem.pbrt:1:37: parameter \"float fovv\" not used by Camera \"perspective\""),
        "{w}"
    );
    assert!(
        w.contains("mem.pbrt:3:33: parameter \"integer radius2\" not used by Shape \"sphere\""),
        "{w}"
    );
    assert!(
        w.contains("mem.pbrt:4:21: parameter \"rgb L\" not used by LightSource \"point\""),
        "{w}"
    );
}

#[test]
fn later_parameter_replaces_earlier() {
    let s = load("Film \"image\" \"integer xresolution\" 100 \"integer xresolution\" 200\nWorldBegin\nWorldEnd");
    assert_eq!(s.scene.film.xresolution, 200);
    assert!(s.warnings.is_empty());
}

#[test]
fn film_crop_and_options() {
    let s = load("Film \"image\" \"float cropwindow\" [0.8 0.2 -1 0.5] \"string filename\" \"out.png\" \"float scale\" 2\nWorldBegin\nWorldEnd").scene;
    assert_eq!(s.film.cropwindow, [0.2, 0.8, 0.0, 0.5]);
    assert_eq!(s.film.filename, PathBuf::from("out.png"));
    assert_eq!(s.film.scale, 2.0);
}

#[test]
fn triangle_mesh_details() {
    let s = load("WorldBegin\nShape \"trianglemesh\" \"point P\" [0 0 0 1 0 0 0 1 0] \"float uv\" [0 0 1 0 0 1]\nShape \"trianglemesh\" \"integer indices\" [0 1 2] \"point P\" [0 0 0 1 0 0 0 1 0] \"normal N\" [0 0 1] \"point2 st\" [0 0 1 0 0 1] \"float alpha\" 0.5\nWorldEnd");
    let mesh = |i: usize| match &s.scene.shapes[i].surface {
        Surface::TriangleMesh(m) => m.clone(),
        g => panic!("{g:?}"),
    };
    assert_eq!(*mesh(0).indices, vec![0, 1, 2]);
    assert_eq!(mesh(0).uvs.as_ref().unwrap()[1], Vec2::new(1.0, 0.0));
    assert!(mesh(1).normals.is_none());
    assert!(mesh(1).uvs.is_some());
    let w = warnings(&s);
    assert!(
        w.contains("\"N\" has 1 normals but \"P\" has 3 vertices"),
        "{w}"
    );
    assert!(
        s.scene.shapes[1].alpha.is_none(),
        "a constant alpha other than 0 cuts nothing"
    );
}

#[test]
fn sphere_parameters() {
    let s = load("WorldBegin\nShape \"sphere\" \"float radius\" 2 \"float zmin\" 5 \"float zmax\" -1 \"float phimax\" 400\nWorldEnd");
    let Surface::Analytic(AnalyticShape::Sphere(sp)) = &s.scene.shapes[0].surface else {
        panic!()
    };
    // As the kind built it: zmin and zmax ordered and clamped, phimax clamped.
    assert_eq!(sp.at.args, (2.0, -1.0, 2.0, 360.0));
    assert_eq!((sp.radius, sp.z_min, sp.z_max), (2.0, -1.0, 2.0));
}

/// `disk` with pbrt-v3's defaults; an empty one is skipped with a warning, a
/// negative inner radius is taken as 0.
#[test]
fn disk_parameters_and_bad_disks() {
    let s = load("WorldBegin\nShape \"disk\"\nShape \"disk\" \"float radius\" 2 \"float innerradius\" 3\nShape \"disk\" \"float innerradius\" -1 \"float height\" 0.5 \"float phimax\" 400\nWorldEnd");
    assert_eq!(s.scene.shapes.len(), 2);
    let disk = |i: usize| match &s.scene.shapes[i].surface {
        Surface::Analytic(AnalyticShape::Disk(d)) => d.at.args,
        _ => panic!(),
    };
    assert_eq!(disk(0), (0.0, 1.0, 0.0, 360.0));
    assert_eq!(disk(1), (0.5, 1.0, 0.0, 360.0));
    let w = warnings(&s);
    assert!(w.contains("mem.pbrt:3:7: disk with an empty extent"), "{w}");
    assert!(w.contains("innerradius -1 is negative"), "{w}");
}

#[test]
fn unsupported_shapes_and_directives_warn_and_load() {
    let s = load("WorldBegin\nShape \"curvy\" \"float width\" 3\nShape \"cylindr\"\nMakeNamedMedium \"fog\" \"string type\" \"homogeneous\"\nMediumInterface \"fog\" \"\"\nTexture \"t\" \"float\" \"ptex\"\nShape \"sphere\"\nWorldEnd");
    assert_eq!(s.scene.shapes.len(), 1);
    let w = warnings(&s);
    assert!(
        w.contains("mem.pbrt:2:7: unknown shape \"curvy\" (did you mean \"curve\"?)"),
        "{w}"
    );
    assert!(w.contains("did you mean \"cylinder\""), "{w}");
    assert!(
        w.contains("mem.pbrt:5:1: the scene has participating media but the \"path\" integrator ignores them"),
        "{w}"
    );
    assert!(!w.contains("not supported by pbrs; ignored"), "{w}");
    assert!(w.contains("cannot read Ptex file"), "{w}");
}

#[test]
fn phase_rules() {
    let s = load("Shape \"sphere\"\nWorldBegin\nCamera \"perspective\" \"float fov\" 10\nShape \"sphere\"\nWorldEnd\nWorldBegin\nShape \"sphere\"\nWorldEnd");
    assert_eq!(s.scene.shapes.len(), 1);
    let Projection::Perspective(c) = &s.scene.camera.projection else {
        panic!("not perspective")
    };
    assert_eq!(c.fov, 90.0);
    let w = warnings(&s);
    assert!(
        w.contains("mem.pbrt:1:1: `Shape` before WorldBegin is ignored"),
        "{w}"
    );
    assert!(
        w.contains("mem.pbrt:3:1: `Camera` inside the world block is ignored"),
        "{w}"
    );
    assert!(
        w.contains("mem.pbrt:6:1: `WorldBegin` after WorldEnd"),
        "{w}"
    );
    let s = load("WorldBegin\nShape \"sphere\"\n");
    assert_eq!(s.scene.shapes.len(), 1);
    assert!(warnings(&s).contains("without WorldEnd"));
    let s = load("WorldBegin\nAttributeBegin\nShape \"sphere\"\nWorldEnd");
    assert!(warnings(&s).contains("mem.pbrt:2:1: AttributeBegin is not closed"));
}

#[test]
fn motion_is_recorded_without_warnings() {
    let s = load("TransformTimes 0 2\nWorldBegin\nActiveTransform EndTime\nTranslate 1 0 0\nActiveTransform All\nShape \"sphere\"\nWorldEnd");
    let shape = &s.scene.shapes[0];
    assert_eq!(shape.object_to_world, DMat4::IDENTITY);
    let m = shape.motion.as_ref().expect("animated");
    assert_eq!((m.start_time, m.end_time), (0.0, 2.0));
    assert_eq!(m.end, DMat4::from_translation(glam::DVec3::X));
    let w = warnings(&s);
    assert!(!w.contains("TransformTimes"), "{w}");
    // The renderer interpolates it: nothing to warn about.
    assert!(!w.contains("animated"), "{w}");
}

#[test]
fn object_instancing() {
    let s = load("WorldBegin\nObjectBegin \"unused\"\nShape \"sphere\"\nObjectEnd\nTranslate 0 0 1\nObjectBegin \"thing\"\nAreaLightSource \"diffuse\"\nShape \"sphere\"\nObjectEnd\nIdentity\nTranslate 5 0 0\nObjectInstance \"thing\"\nTranslate 5 0 0\nObjectInstance \"thing\"\nWorldEnd");
    let sc = &s.scene;
    assert!(sc.shapes.is_empty());
    assert_eq!(sc.objects.len(), 1, "only instanced objects are built");
    assert_eq!(sc.objects[0].name, "thing");
    // Object shapes keep the CTM of their definition; instances add theirs on top.
    let sh = &sc.objects[0].shapes[0];
    assert!(close(
        sh.object_to_world.transform_point3(DVec3::ZERO),
        DVec3::Z
    ));
    assert!(sh.area_light.is_none());
    assert_eq!(sc.instances.len(), 2);
    assert!(close(
        sc.instances[1]
            .instance_to_world
            .transform_point3(DVec3::ZERO),
        DVec3::new(10.0, 0.0, 0.0)
    ));
    assert!(sc.skipped.join("\n").contains("object \"unused\""));
    assert!(
        warnings(&s).contains("area light inside the definition of object \"thing\" is ignored")
    );
    assert_eq!(s.summary.instances, 2);
}

#[test]
fn include_splices_and_resolves_against_the_top_level_directory() {
    let d = tmpdir("include");
    std::fs::create_dir_all(d.join("sub")).unwrap();
    // sub/a.inc includes "sub/b.inc": relative to the top-level directory, not to sub/.
    std::fs::write(d.join("sub/a.inc"), "Include \"sub/b.inc\"\n").unwrap();
    std::fs::write(d.join("sub/b.inc"), "Shape \"sphere\"\n").unwrap();
    std::fs::write(
        d.join("main.pbrt"),
        "WorldBegin\nInclude \"sub/a.inc\" \"float radius\" 3\nShape \"bogus\"\nWorldEnd\n",
    )
    .unwrap();
    let s = load_scene(&d.join("main.pbrt")).unwrap_or_else(|f| panic!("{f:?}"));
    let Surface::Analytic(AnalyticShape::Sphere(sp)) = &s.scene.shapes[0].surface else {
        panic!()
    };
    assert_eq!(sp.radius, 3.0);
    std::fs::write(
        d.join("sub/b.inc"),
        "Shape \"sphere\" \"float radius\" 1 \"float bogus\" 2\n",
    )
    .unwrap();
    let s = load_scene(&d.join("main.pbrt")).unwrap();
    let w = s
        .warnings
        .iter()
        .find(|w| w.to_string().contains("\"float bogus\" not used"))
        .unwrap();
    let help = w.help().unwrap().to_string();
    let main = d.join("main.pbrt").display().to_string();
    let a = d.join("sub/a.inc").display().to_string();
    assert!(help.contains(&format!("included from {a}:1:1")), "{help}");
    assert!(
        help.contains(&format!("included from {main}:2:1")),
        "{help}"
    );
}

#[test]
fn ply_meshes_are_shared() {
    let d = tmpdir("ply");
    std::fs::write(d.join("tri.ply"), "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nelement face 1\nproperty list uint8 int vertex_index\nend_header\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n").unwrap();
    let text = "WorldBegin\nShape \"plymesh\" \"string filename\" \"tri.ply\"\nTranslate 1 0 0\nShape \"plymesh\" \"string filename\" \"tri.ply\"\nWorldEnd";
    let s = load_scene_str(text, &d.join("scene.pbrt"))
        .unwrap_or_else(|f| panic!("{f:?}"))
        .scene;
    let (Surface::TriangleMesh(a), Surface::TriangleMesh(b)) =
        (&s.shapes[0].surface, &s.shapes[1].surface)
    else {
        panic!()
    };
    assert!(Arc::ptr_eq(a, b));
    assert_eq!(a.normals.as_ref().unwrap()[0], Vec3::Z);
}

#[test]
fn diagnostics_print_file_line_col() {
    // print_diagnostics writes to stderr; here we check the rendered report text.
    let f = load_scene_str(
        "WorldBegin\n  Shape \"sphere\" \"float radius\" [ 1 2 ]\nShap \"x\"\nWorldEnd",
        Path::new("x.pbrt"),
    )
    .err()
    .unwrap();
    let handler =
        miette::GraphicalReportHandler::new_themed(miette::GraphicalTheme::unicode_nocolor());
    let mut out = String::new();
    handler
        .render_report(&mut out, f.errors[0].as_ref())
        .unwrap();
    assert!(out.contains("x.pbrt:3:1"), "{out}");
    assert!(out.contains("[x.pbrt:3:1]"), "{out}");
}

#[test]
fn snippets_of_very_long_lines_are_cut() {
    let text = format!(
        "WorldBegin Shape \"trianglemesh\" \"point P\" [{} 1.2.3 ] WorldEnd",
        "0.5 ".repeat(100_000)
    );
    let f = load_scene_str(&text, Path::new("long.pbrt")).err().unwrap();
    let handler =
        miette::GraphicalReportHandler::new_themed(miette::GraphicalTheme::unicode_nocolor());
    let mut out = String::new();
    handler
        .render_report(&mut out, f.errors[0].as_ref())
        .unwrap();
    assert!(
        out.contains("long.pbrt:1:400045: bad number `1.2.3`"),
        "{}",
        &out[..out.len().min(500)]
    );
    assert!(out.len() < 2000, "snippet of {} bytes", out.len());
}

/// Each warning as its message, then its help (if any) after " | help: ".
fn warnings_with_help(s: &LoadedScene) -> Vec<String> {
    s.warnings
        .iter()
        .map(|w| match w.help() {
            Some(h) => format!("{w} | help: {h}"),
            None => w.to_string(),
        })
        .collect()
}

#[test]
fn unused_material_parameters_say_what_was_meant() {
    let one = |decl: &str| {
        let s = load(&format!("WorldBegin\n{decl}\nShape \"sphere\"\nWorldEnd"));
        let w = warnings_with_help(&s);
        assert_eq!(w.len(), 1, "{decl}: {w:?}");
        (w[0].clone(), s)
    };
    let cases = [
        // A known name with a type the kind does not read it as.
        (
            "Material \"matte\" \"float Kd\" 0.3",
            "mem.pbrt:2:18: parameter \"float Kd\" not used by Material \"matte\" | help: \"Kd\" is a spectrum texture parameter, not \"float\": write \"rgb Kd\", \"xyz Kd\", \"blackbody Kd\", \"spectrum Kd\" or \"texture Kd\"",
        ),
        (
            "Material \"glass\" \"rgb uroughness\" [0.1 0.1 0.1]",
            "help: \"uroughness\" is a float texture parameter, not \"rgb\": write \"float uroughness\" or \"texture uroughness\"",
        ),
        (
            "Material \"glass\" \"float remaproughness\" 0",
            "help: \"remaproughness\" is a bool parameter, not \"float\": write \"bool remaproughness\"",
        ),
        // A name close to a known one: the type as written when it fits.
        ("Material \"matte\" \"rgb kd\" [1 0 0]", "help: did you mean \"rgb Kd\"?"),
        ("Material \"matte\" \"color Kdd\" [1 0 0]", "help: did you mean \"color Kd\"?"),
        ("Material \"matte\" \"float sigm\" 10", "help: did you mean \"float sigma\"?"),
        // ... and the kind's type when it does not.
        ("Material \"mirror\" \"float kr\" 0.5", "help: did you mean \"rgb Kr\"?"),
        (
            "MakeNamedMaterial \"m\" \"string type\" \"glass\" \"float indx\" 1.3\nNamedMaterial \"m\"",
            "not used by Material \"glass\" | help: did you mean \"float index\"?",
        ),
        // The right type, but a list where one value belongs.
        (
            "Material \"matte\" \"float sigma\" [10 20]",
            "help: \"sigma\" takes one value; 2 were given",
        ),
    ];
    for (decl, want) in cases {
        let (w, _) = one(decl);
        assert!(w.contains(want), "{decl}:\n  {w}\nlacks\n  {want}");
    }
    // Nothing close: no help.
    let (w, _) = one("Material \"matte\" \"float zzzzzz\" 1");
    assert!(!w.contains("help:"), "{w}");
    // The value is not used: Kd keeps pbrt-v3's default.
    let (_, s) = one("Material \"matte\" \"float Kd\" 0.3");
    assert_eq!(matte_of(&s.scene.materials[0]), (Vec3::splat(0.5), 0.0));
    // An unknown type is read as a matte: matte's names would mislead, so no help.
    let s = load("WorldBegin\nMaterial \"plastik\" \"rgb Ks\" [1 1 1] \"rgb kd\" [1 0 0]\nShape \"sphere\"\nWorldEnd");
    let w = warnings_with_help(&s);
    assert!(
        w.iter()
            .any(|w| w.contains("unknown material type \"plastik\"")),
        "{w:?}"
    );
    let unused: Vec<&String> = w.iter().filter(|w| w.contains("not used")).collect();
    assert_eq!(unused.len(), 2, "{w:?}");
    assert!(unused.iter().all(|w| !w.contains("help:")), "{w:?}");
}

#[test]
fn summary_counts_declared_material_kinds() {
    let s = load("WorldBegin\nMaterial \"matte\"\nShape \"sphere\"\nMaterial \"glass\"\nShape \"sphere\"\nMaterial \"hair\"\nShape \"sphere\"\nMaterial \"BUSH1\"\nShape \"sphere\"\nShape \"sphere\" \"float radius\" 2\nWorldEnd");
    let sum = &s.summary;
    let by: Vec<(&str, usize)> = sum
        .materials_by_type
        .iter()
        .map(|(k, v)| (*k, *v))
        .collect();
    assert_eq!(by, [("glass", 1), ("hair", 1), ("matte", 1)]);
    assert_eq!(sum.unknown_materials.get("BUSH1"), Some(&1));
    assert_eq!(s.scene.materials.len(), 4);
    let text = sum.to_string();
    assert!(
        text.contains("materials:  4 (1 glass, 1 hair, 1 matte, 1 \"BUSH1\" (unknown))"),
        "{text}"
    );
    assert!(
        text.contains("\"BUSH1\": unknown material type, read as matte (as pbrt-v3)"),
        "{text}"
    );
    // Only supported kinds: no extra lines.
    let plain = load("WorldBegin\nMaterial \"glass\"\nShape \"sphere\"\nWorldEnd")
        .summary
        .to_string();
    assert!(
        plain.contains(
            "materials:  1 (1 glass)\nmotion:     none (no motion structures built)\nwarnings:"
        ),
        "{plain}"
    );
}
