//! The table-driven light test: every name of `LIGHTS` and `AREA_LIGHTS`
//! (types and aliases) has a case here, and a test fails when one has none.
//! Each case is a scene loaded through the real loader and built by
//! `RenderScene::new`; then
//!
//! - supported types: the light's own checks (position, direction,
//!   radiance, falloff, power, the parameters' defaults and overrides), and
//!   for every light, sampling against its density: each sample's density
//!   is `pdf_li` of its direction (1 and 0 for delta lights), and for the
//!   others the mean of 1/pdf over many samples is the solid angle the light
//!   subtends (the sampler covers it, and its density integrates to one);

mod common;

use common::{load_text, warning_text};
use glam::{Vec2, Vec3};
use pbrs::geometry::luminance;
use pbrs::integrators::RenderScene;
use pbrs::lights::{Light, AREA_LIGHTS, LIGHTS};
use pbrs::loader::LoadedScene;
use pbrs::sampling::Pcg32;
use pbrs::scene::kind;
use pbrs::shapes::SurfacePoint;
use std::f32::consts::PI;

struct Case {
    /// The type as written in the scene (a name or an alias of the table).
    ty: &'static str,
    /// The world block (a small sphere at (0, -3, 0) is added to every case).
    world: &'static str,
    /// Points to sample the light from, each with the solid angle its
    /// samples cover (ignored for delta lights).
    from: &'static [([f32; 3], f32)],
    check: fn(&LoadedScene, &RenderScene),
}

/// Solid angle of a sphere of radius `r` seen from distance `d` > r.
fn cone(r: f32, d: f32) -> f32 {
    2.0 * PI * (1.0 - (1.0 - (r / d) * (r / d)).sqrt())
}

const FOUR_PI: f32 = 4.0 * PI;

const CASES: &[Case] = &[
    Case {
        ty: "point",
        world: "Translate 1 0 0\nLightSource \"point\" \"point from\" [0 2 0] \"rgb I\" [1 2 3] \"float scale\" 2",
        from: &[([1.0, 0.0, 0.0], 0.0), ([0.3, -1.0, 2.0], 0.0)],
        check: |_, sc| {
            let Light::Point(l) = the_light(sc) else {
                panic!("not a point light")
            };
            // pbrt-v3: Translate(from)·CTM, so from is added to CTM·origin.
            assert_eq!(l.p, Vec3::new(1.0, 2.0, 0.0));
            assert_eq!(l.intensity, Vec3::new(2.0, 4.0, 6.0));
            let s = sample(sc, Vec3::new(1.0, 0.0, 0.0));
            assert_eq!(s.li, l.intensity / 4.0);
            assert_eq!(s.wi, Vec3::Y);
            assert_close(
                sc.lights[0].power(),
                4.0 * PI * luminance(l.intensity),
                "power",
            );
            // Defaults: I 1, scale 1, from 0 0 0.
            let Light::Point(d) = only_light("LightSource \"point\"") else {
                panic!()
            };
            assert_eq!((d.p, d.intensity), (Vec3::ZERO, Vec3::ONE));
        },
    },
    Case {
        ty: "spot",
        world: "LightSource \"spot\" \"point from\" [0 3 0] \"point to\" [0 0 0] \"float coneangle\" 30 \"float conedeltaangle\" 10 \"rgb I\" [4 4 4] \"rgb scale\" [1 0.5 2]",
        from: &[([0.0, 0.0, 0.0], 0.0), ([0.5, 0.0, 0.5], 0.0)],
        check: |_, sc| {
            let Light::Spot(l) = the_light(sc) else {
                panic!("not a spot light")
            };
            assert_eq!(l.p, Vec3::new(0.0, 3.0, 0.0));
            assert!((l.frame.n - Vec3::NEG_Y).length() < 1e-6);
            let i = Vec3::new(4.0, 2.0, 8.0);
            let (cos_total, cos_start) = (30f32.to_radians().cos(), 20f32.to_radians().cos());
            // On the axis, in the falloff band and outside the cone.
            for (deg, falloff) in [
                (0.0f32, Some(1.0f32)),
                (15.0, Some(1.0)),
                (25.0, None),
                (35.0, Some(0.0)),
            ] {
                let x = 3.0 * deg.to_radians().tan();
                let s = sample(sc, Vec3::new(x, 0.0, 0.0));
                let d2 = 9.0 + x * x;
                let want = falloff.unwrap_or_else(|| {
                    let t = (deg.to_radians().cos() - cos_total) / (cos_start - cos_total);
                    t * t * t * t
                });
                assert!(
                    (s.li - i * want / d2).abs().max_element() < 1e-5,
                    "{deg}°: {} vs {}",
                    s.li,
                    i * want / d2
                );
            }
            assert_close(
                sc.lights[0].power(),
                luminance(i) * 2.0 * PI * (1.0 - 0.5 * (cos_start + cos_total)),
                "power",
            );
            // from = to: pbrt-v3's check, in the spot's builder.
            let s = load_text(&scene(
                "LightSource \"spot\" \"point from\" [1 1 1] \"point to\" [1 1 1]",
            ));
            assert!(s.scene.lights.is_empty());
            assert!(warning_text(&s)
                .contains("spot light with \"from\" equal to \"to\" has no direction: skipped"));
        },
    },
    Case {
        ty: "distant",
        world: "LightSource \"distant\" \"point from\" [0 0 5] \"point to\" [0 0 0] \"rgb L\" [1 2 3]",
        from: &[([0.0, 0.0, 0.0], 0.0), ([0.2, -3.0, 0.1], 0.0)],
        check: |_, sc| {
            let Light::Distant(l) = the_light(sc) else {
                panic!("not a distant light")
            };
            assert_eq!(l.w, Vec3::Z);
            let s = sample(sc, Vec3::ZERO);
            assert_eq!((s.li, s.wi), (Vec3::new(1.0, 2.0, 3.0), Vec3::Z));
            // The scene radius comes from the built scene (preprocess).
            let (_, r) = sc.aggregate.bounds.bounding_sphere();
            assert!(r > 0.0 && l.scene_radius == r);
            assert_close(
                sc.lights[0].power(),
                luminance(l.l) * PI * r * r,
                "power",
            );
            let s = load_text(&scene("LightSource \"distant\" \"point to\" [0 0 0]"));
            assert!(s.scene.lights.is_empty());
            assert!(warning_text(&s).contains("distant light with \"from\" equal to \"to\""));
        },
    },
    Case {
        ty: "infinite",
        world: "LightSource \"infinite\" \"rgb L\" [0.5 1 2] \"rgb scale\" [2 2 2] \"integer nsamples\" 3",
        from: &[([0.0, 0.0, 0.0], FOUR_PI), ([0.0, -3.0, 0.3], FOUR_PI)],
        check: |_, sc| {
            let Light::Infinite(l) = the_light(sc) else {
                panic!("not an infinite light")
            };
            assert_eq!(l.n_samples, 3);
            assert!(sc.lights[0].is_infinite() && sc.infinite_lights == [0]);
            for d in [Vec3::X, Vec3::new(0.3, 0.4, -0.5).normalize()] {
                let le = sc.lights[0].le(d);
                assert!((le - Vec3::new(1.0, 2.0, 4.0)).abs().max_element() < 1e-5, "{le}");
            }
            // pbrt-v3 reads `scale` as a spectrum only.
            let f = load_text(&scene("LightSource \"infinite\" \"float scale\" 3"));
            assert!(warning_text(&f).contains("\"float scale\" not used"));
        },
    },
    Case {
        ty: "exinfinite",
        world: "LightSource \"exinfinite\" \"string sampling\" \"uniform\" \"integer nsamples\" 2 \"integer samples\" 5",
        from: &[([0.0, 1.0, 0.0], FOUR_PI)],
        check: |_, sc| {
            let Light::Infinite(l) = the_light(sc) else {
                panic!("not an infinite light")
            };
            // `samples` wins over `nsamples`.
            assert_eq!(l.n_samples, 5);
            let s = sample(sc, Vec3::ZERO);
            assert_eq!(s.pdf, 1.0 / (4.0 * PI));
            let w = load_text(&scene(
                "LightSource \"infinite\" \"string sampling\" \"importance\"",
            ));
            assert!(warning_text(&w).contains("unknown infinite light sampling \"importance\""));
        },
    },
    Case {
        ty: "diffuse",
        world: "AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [1 2 3] \"float scale\" 0.5 \"bool twosided\" \"true\" \"integer samples\" 4\nTranslate 0 1 0\nShape \"sphere\" \"float radius\" 0.5\nAttributeEnd",
        from: &[
            ([0.1, 1.2, 0.15], FOUR_PI),
            ([0.0, -1.0, 0.0], 0.0),
            ([2.0, 1.0, 0.0], 0.0),
        ],
        check: |_, sc| {
            let Light::Diffuse(l) = the_light(sc) else {
                panic!("not an area light")
            };
            assert_eq!(l.l, Vec3::new(0.5, 1.0, 1.5));
            assert!(l.two_sided);
            assert_eq!(sc.lights[0].n_samples(), 4);
            assert_close(
                sc.lights[0].power(),
                luminance(l.l) * (4.0 * PI * 0.25) * PI * 2.0,
                "power",
            );
            // Two-sided: seen from inside and outside.
            assert_eq!(sc.lights[0].emitted(Vec3::Y, -Vec3::Y), l.l);
        },
    },
    Case {
        ty: "area",
        world: "AttributeBegin\nAreaLightSource \"area\" \"rgb L\" [2 2 2]\nShape \"trianglemesh\" \"point P\" [-1 -1 2  1 -1 2  1 1 2  -1 1 2] \"integer indices\" [0 1 2 0 2 3]\nAttributeEnd",
        from: &[([0.0, 0.0, 0.0], 0.0), ([0.0, 0.0, 3.0], 0.0), ([0.5, -0.2, 1.0], 0.0)],
        check: |_, sc| {
            assert_eq!(sc.lights.len(), 2, "one light per triangle");
            for light in &sc.lights {
                let Light::Diffuse(l) = light else {
                    panic!("not an area light")
                };
                assert!(!l.two_sided);
                assert_eq!(l.l, Vec3::splat(2.0));
                // One-sided: it emits along its normal (+z) only.
                assert_eq!(light.emitted(Vec3::Z, Vec3::Z), l.l);
                assert_eq!(light.emitted(Vec3::Z, -Vec3::Z), Vec3::ZERO);
            }
            // The two triangles cover the square's solid angle from its axis:
            // 4·asin(a·b / ((a² + d²)(b² + d²))^½), a = b = 1, d = 2.
            let want = 4.0 * (1.0f32 / 5.0).asin();
            let got: f32 = sc
                .lights
                .iter()
                .map(|l| mean_inverse_pdf(l, sc, Vec3::ZERO))
                .sum();
            assert!((got - want).abs() < 0.01 * want, "{got} vs {want}");
        },
    },
    Case {
        ty: "goniometric",
        world: "Translate 0 2 0\nLightSource \"goniometric\" \"rgb I\" [1 2 3] \"float scale\" 2",
        from: &[([0.0, 0.0, 0.0], 0.0), ([1.0, 1.0, 2.0], 0.0)],
        check: |_, sc| {
            let Light::Goniometric(l) = the_light(sc) else {
                panic!("not a goniometric light")
            };
            // No map: a point light of I·scale at the CTM's origin.
            assert_eq!(l.p, Vec3::new(0.0, 2.0, 0.0));
            assert_eq!(l.intensity, Vec3::new(2.0, 4.0, 6.0));
            let s = sample(sc, Vec3::ZERO);
            assert_eq!(s.li, l.intensity / 4.0);
            assert_close(
                sc.lights[0].power(),
                4.0 * PI * luminance(l.intensity),
                "power",
            );
        },
    },
    Case {
        ty: "projection",
        world: "Translate 0 2 0\nRotate 90 1 0 0\nLightSource \"projection\" \"float fov\" 30 \"rgb I\" [2 2 2]",
        from: &[([0.0, 0.0, 0.0], 0.0), ([0.2, 0.0, 0.1], 0.0)],
        check: |_, sc| {
            let Light::Projection(l) = the_light(sc) else {
                panic!("not a projection light")
            };
            // Rotate 90 about x takes the light's +z to world −y: the
            // frustum looks down at the origin.
            assert!((l.axis - Vec3::new(0.0, -1.0, 0.0)).length() < 1e-6);
            let s = sample(sc, Vec3::ZERO);
            assert_eq!(s.li, Vec3::splat(0.5));
            // 30° across a square window: nothing 20° off the axis.
            let off = Vec3::new(2.0 * 20f32.to_radians().tan(), 0.0, 0.0);
            let r = at(off);
            let s = sc.lights[0].sample_li(&r, Vec2::ZERO, &sc.aggregate).unwrap();
            assert_eq!(s.li, Vec3::ZERO);
            let cos_total = (15f32.to_radians().tan() * 2f32.sqrt()).atan().cos();
            assert_close(
                sc.lights[0].power(),
                luminance(Vec3::splat(2.0)) * 2.0 * PI * (1.0 - cos_total),
                "power",
            );
        },
    },
];

fn scene(world: &str) -> String {
    format!(
        "WorldBegin\nAttributeBegin\nTranslate 0 -3 0\nShape \"sphere\" \"float radius\" 0.25\nAttributeEnd\n{world}\nWorldEnd\n"
    )
}

fn only_light(world: &str) -> Light {
    let s = load_text(&scene(world));
    assert_eq!(s.scene.lights.len(), 1, "{world}");
    s.scene.lights[0].clone()
}

fn the_light(sc: &RenderScene) -> &Light {
    assert_eq!(sc.lights.len(), 1);
    &sc.lights[0]
}

fn at(p: Vec3) -> SurfacePoint {
    SurfacePoint {
        p,
        p_error: Vec3::ZERO,
        n: Vec3::ZERO,
        ns: Vec3::ZERO,
    }
}

fn sample(sc: &RenderScene, p: Vec3) -> pbrs::lights::LightSample {
    sc.lights[0]
        .sample_li(&at(p), Vec2::new(0.3, 0.6), &sc.aggregate)
        .expect("a sample")
}

fn assert_close(a: f32, b: f32, what: &str) {
    assert!((a - b).abs() <= 1e-5 * b.abs(), "{what}: {a} vs {b}");
}

const SAMPLES: usize = 200_000;

/// Mean of 1/pdf over `SAMPLES` samples from `p`, counting rejected ones as
/// 0: the solid angle the light's samples cover.
fn mean_inverse_pdf(light: &Light, sc: &RenderScene, p: Vec3) -> f32 {
    let mut rng = Pcg32::with_sequence(7);
    let r = at(p);
    let mut sum = 0.0f64;
    for _ in 0..SAMPLES {
        let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
        if let Some(s) = light.sample_li(&r, u, &sc.aggregate) {
            sum += 1.0 / s.pdf as f64;
        }
    }
    (sum / SAMPLES as f64) as f32
}

/// Each sample's density is `pdf_li` of its direction (1 and 0 for delta
/// lights); radiance and direction are finite.
fn check_sampling(name: &str, light: &Light, sc: &RenderScene, p: Vec3) {
    let mut rng = Pcg32::with_sequence(3);
    let r = at(p);
    let mut some = 0;
    for _ in 0..2000 {
        let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
        let Some(s) = light.sample_li(&r, u, &sc.aggregate) else {
            continue;
        };
        some += 1;
        assert!(
            s.li.is_finite() && s.li.min_element() >= 0.0,
            "{name}: {}",
            s.li
        );
        assert!((s.wi.length() - 1.0).abs() < 1e-4, "{name}: {}", s.wi);
        let pdf = light.pdf_li(&r, s.wi, &sc.aggregate);
        if light.is_delta() {
            assert_eq!((s.pdf, pdf), (1.0, 0.0), "{name}");
        } else {
            // 1%: an infinite light's density goes as 1/sin θ, and near its
            // poles θ's f32 round trip through the direction loses digits.
            assert!(
                s.pdf > 0.0 && (pdf - s.pdf).abs() <= 1e-2 * s.pdf,
                "{name} from {p}: sampled density {} vs pdf_li {pdf}",
                s.pdf
            );
        }
    }
    assert!(some > 0, "{name}: no sample from {p}");
}

#[test]
fn every_light_type_has_a_case() {
    let names = kind::names(LIGHTS)
        .into_iter()
        .chain(kind::names(AREA_LIGHTS));
    for n in names {
        assert!(
            CASES.iter().any(|c| c.ty == n),
            "light type \"{n}\" is in the tables but has no case in tests/lights_table.rs"
        );
    }
    for c in CASES {
        assert!(
            kind::find(LIGHTS, c.ty).is_some() || kind::find(AREA_LIGHTS, c.ty).is_some(),
            "case for \"{}\", which the tables do not have",
            c.ty
        );
    }
}

#[test]
fn every_case_loads_samples_and_checks() {
    for c in CASES {
        let s = load_text(&scene(c.world));
        let sc = RenderScene::new(&s.scene);
        // The light is the kind the case names (aliases build their kind).
        let kind_name = kind::find(LIGHTS, c.ty)
            .map(|k| k.name)
            .or_else(|| kind::find(AREA_LIGHTS, c.ty).map(|k| k.name))
            .unwrap();
        for l in &sc.lights {
            assert_eq!(l.name(), kind_name, "{}", c.ty);
        }
        (c.check)(&s, &sc);
        for &(p, solid_angle) in c.from {
            let p = Vec3::from_array(p);
            for l in &sc.lights {
                check_sampling(c.ty, l, &sc, p);
            }
            if solid_angle > 0.0 && sc.lights.len() == 1 && !sc.lights[0].is_delta() {
                let got = mean_inverse_pdf(&sc.lights[0], &sc, p);
                assert!(
                    (got - solid_angle).abs() < 0.01 * solid_angle,
                    "{} from {p}: E[1/pdf] = {got}, want {solid_angle}",
                    c.ty
                );
            }
        }
    }
}

/// A sphere light seen from outside covers its cone (pbrt-v3's cone
/// sampling).
#[test]
fn sphere_light_from_outside_covers_its_cone() {
    let s = load_text(&scene(
        "AttributeBegin\nAreaLightSource \"diffuse\"\nShape \"sphere\" \"float radius\" 0.5\nAttributeEnd",
    ));
    let sc = RenderScene::new(&s.scene);
    for d in [1.5f32, 4.0] {
        let want = cone(0.5, d);
        let got = mean_inverse_pdf(&sc.lights[0], &sc, Vec3::new(0.0, 0.0, d));
        assert!((got - want).abs() < 0.01 * want, "d {d}: {got} vs {want}");
    }
}

/// Every type builds from its defaults alone (a builder that reads a
/// parameter its table does not declare panics here).
#[test]
fn every_type_builds_with_its_defaults() {
    for k in LIGHTS {
        let s = load_text(&scene(&format!("LightSource \"{}\"", k.name)));
        let built = s.scene.lights.len();
        assert_eq!(built, usize::from(k.is_supported()), "{}", k.name);
    }
    for k in AREA_LIGHTS {
        let s = load_text(&scene(&format!(
            "AttributeBegin\nAreaLightSource \"{}\"\nShape \"sphere\"\nAttributeEnd",
            k.name
        )));
        let sc = RenderScene::new(&s.scene);
        assert_eq!(sc.lights.len(), 1, "{}", k.name);
        assert!(sc.lights[0].power() > 0.0, "{}", k.name);
    }
}

/// Unknown types: a warning (with "did you mean" from the table for
/// `LightSource`), nothing built, later shapes not emissive.
#[test]
fn unknown_types_are_warned_about_and_ignored() {
    let s = load_text(&scene("LightSource \"pont\" \"rgb I\" [1 1 1]"));
    assert!(s.scene.lights.is_empty());
    let w = warning_text(&s);
    assert!(
        w.contains("unknown light type \"pont\" (did you mean \"point\"?): ignored"),
        "{w}"
    );
    assert!(!w.contains("not used"), "{w}");
    let s = load_text(&scene(
        "AreaLightSource \"glow\" \"rgb L\" [1 1 1]\nShape \"sphere\"",
    ));
    assert!(s.scene.shapes.iter().all(|sh| sh.area_light.is_none()));
    let w = warning_text(&s);
    assert!(
        w.contains("unknown area light \"glow\" (pbrt-v3 has \"diffuse\", alias \"area\"): ignored, later shapes are not emissive"),
        "{w}"
    );
}
