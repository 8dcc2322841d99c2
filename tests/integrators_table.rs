//! The integrator table's completeness test: every kind that
//! `INTEGRATORS` marks as supported has a case here (a kind without one
//! fails), loaded through the real scene loader from an `Integrator`
//! statement and rendered; the image must be finite and lit, and the
//! description must hold that kind's settings. Kinds pbrs does not render
//! must be substituted by `path` with the statement's `maxdepth`, with
//! pbrt-v3's warning.

mod common;

use common::{load_text, render_at, warning_text};
use pbrs::integrators::INTEGRATORS;

/// A kind and the parameters of its `Integrator` statement.
struct Case {
    kind: &'static str,
    params: &'static str,
    /// The settings' line in `--check`.
    summary: &'static str,
}

const CASES: &[Case] = &[
    Case {
        kind: "path",
        params: "\"integer maxdepth\" 3 \"string lightsamplestrategy\" \"power\"",
        summary: "path, maxdepth 3, rrthreshold 1, light samples power",
    },
    Case {
        kind: "volpath",
        params: "\"integer maxdepth\" 4",
        summary: "volpath, maxdepth 4, rrthreshold 1, light samples spatial",
    },
    Case {
        kind: "directlighting",
        params: "\"string strategy\" \"one\"",
        summary: "directlighting, maxdepth 5, strategy one",
    },
    Case {
        kind: "whitted",
        params: "\"integer maxdepth\" 2",
        summary: "whitted, maxdepth 2",
    },
    Case {
        kind: "ambientocclusion",
        params: "\"integer nsamples\" 8 \"bool cossample\" \"false\"",
        summary: "ambientocclusion, nsamples 8, uniform sampling",
    },
    Case {
        kind: "sppm",
        params:
            "\"integer iterations\" 4 \"integer photonsperiteration\" 2000 \"float radius\" 0.2",
        summary: "sppm, iterations 4, photons per iteration 2000, maxdepth 5, radius 0.2",
    },
    Case {
        kind: "bdpt",
        params: "\"integer maxdepth\" 4",
        summary: "bdpt, maxdepth 4, light samples power",
    },
    Case {
        kind: "mlt",
        params: "\"integer bootstrapsamples\" 1000 \"integer chains\" 10 \"integer mutationsperpixel\" 4",
        summary: "mlt, maxdepth 5, bootstrap samples 1000, chains 10, mutations per pixel 4, large step probability 0.3, sigma 0.01",
    },
];

/// A small scene lit by a point light and an area light: a matte floor, a
/// glass sphere and a mirror sphere (so the specular trees have children).
fn scene(integrator: &str) -> String {
    format!(
        r#"LookAt 0 1 -4  0 0.5 0  0 1 0
Camera "perspective" "float fov" 45
Film "image" "integer xresolution" 16 "integer yresolution" 16
Sampler "halton" "integer pixelsamples" 4
Integrator {integrator}
WorldBegin
LightSource "point" "point from" [0 3 -1] "rgb I" [6 6 6]
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [2 2 2]
  Translate 0 3 1
  Shape "sphere" "float radius" 0.3
AttributeEnd
Material "matte" "rgb Kd" [0.5 0.5 0.5]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
  "point P" [-5 0 -5  5 0 -5  5 0 5  -5 0 5]
AttributeBegin
  Material "glass"
  Translate -0.6 0.5 0
  Shape "sphere" "float radius" 0.5
AttributeEnd
AttributeBegin
  Material "mirror"
  Translate 0.6 0.5 0
  Shape "sphere" "float radius" 0.5
AttributeEnd
WorldEnd
"#
    )
}

#[test]
fn every_supported_kind_has_a_case_that_renders() {
    for k in INTEGRATORS.iter().filter(|k| k.is_supported()) {
        let case = CASES.iter().find(|c| c.kind == k.name);
        let Some(case) = case else {
            panic!(
                "integrator \"{}\" has no case in tests/integrators_table.rs",
                k.name
            );
        };
        let loaded = load_text(&scene(&format!("\"{}\" {}", case.kind, case.params)));
        assert_eq!(warning_text(&loaded), "", "{}", k.name);
        let settings = loaded.scene.integrator;
        assert_eq!(settings.name(), k.name);
        assert_eq!(settings.summary(), case.summary);
        let (img, stats) = render_at(loaded.scene, 16, 4, Some(1));
        let sum: f64 = img.data.iter().map(|&v| v as f64).sum();
        assert!(sum.is_finite() && sum > 0.0, "{}: {sum}", k.name);
        assert!(stats.rays.shadow > 0, "{}: no light sampled", k.name);
    }
    for c in CASES {
        assert!(
            INTEGRATORS
                .iter()
                .any(|k| k.name == c.kind && k.is_supported()),
            "case for unknown kind {}",
            c.kind
        );
    }
}

#[test]
fn unsupported_kinds_are_path_with_their_maxdepth() {
    for k in INTEGRATORS.iter().filter(|k| !k.is_supported()) {
        let loaded = load_text(&scene(&format!(
            "\"{}\" \"integer maxdepth\" 2 \"bool visualizestrategies\" \"true\"",
            k.name
        )));
        let w = warning_text(&loaded);
        assert!(
            w.contains(&format!(
                "integrator \"{}\" is not supported by pbrs: substituted by \"path\" with maxdepth 2",
                k.name
            )),
            "{w}"
        );
        assert!(!w.contains("visualizestrategies"), "{w}");
        assert_eq!(loaded.scene.integrator.name(), "path");
        let pbrs::scene::IntegratorSettings::Path(p) = loaded.scene.integrator else {
            panic!("not path")
        };
        assert_eq!(p.max_depth, 2);
    }
}

/// Ambient occlusion against closed forms: each unoccluded direction adds
/// cos θ / (pdf · n), so an open hemisphere gives π (exactly, by cosine
/// sampling; on average, uniformly), and a point at the foot of a wall
/// that fills half the hemisphere π/2 on average.
#[test]
fn ambient_occlusion_closed_forms() {
    let ao = |cos: bool, wall: bool| {
        let wall = if wall {
            // The wall x = 0, from the floor up: the camera sees the floor
            // just beside it (x slightly above 0), half of whose hemisphere
            // (x < 0) it closes.
            "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] \"point P\" [0 0 -10  0 0 10  0 10 10  0 10 -10]"
        } else {
            ""
        };
        let text = format!(
            r#"LookAt 0.001 1 0  0.001 0 0  0 0 1
Camera "orthographic" "float screenwindow" [-0.0001 0.0001 -0.0001 0.0001]
Film "image" "integer xresolution" 4 "integer yresolution" 4
Sampler "random" "integer pixelsamples" 64
Integrator "ambientocclusion" "integer nsamples" 16 "bool cossample" "{cos}"
WorldBegin
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3] "point P" [-10 0 -10  10 0 -10  10 0 10  -10 0 10]
{wall}
WorldEnd
"#
        );
        let (img, _) = render_at(load_text(&text).scene, 4, 64, Some(1));
        img.data.iter().map(|&v| v as f64).sum::<f64>() / img.data.len() as f64
    };
    let pi = std::f64::consts::PI;
    let open = ao(true, false);
    assert!((open - pi).abs() < 1e-5, "open, cosine: {open}");
    let open = ao(false, false);
    assert!((open - pi).abs() < 0.02 * pi, "open, uniform: {open}");
    for cos in [true, false] {
        let half = ao(cos, true);
        assert!(
            (half - pi / 2.0).abs() < 0.03 * pi,
            "wall, cosine {cos}: {half}"
        );
    }
}

/// pbrt-v3's AOIntegrator takes the sampler's `RoundCount` of `nsamples`
/// and says so when it differs: the pixel samplers round up to a power of
/// two, the others take the count as it is.
#[test]
fn ambient_occlusion_says_when_the_sampler_rounds_nsamples() {
    let text = |sampler: &str, n: u32| {
        format!(
            "Sampler \"{sampler}\" \"integer pixelsamples\" 4\nIntegrator \"ambientocclusion\" \"integer nsamples\" {n}\nWorldBegin\nShape \"sphere\"\nWorldEnd\n"
        )
    };
    for sampler in ["02sequence", "lowdiscrepancy", "maxmindist"] {
        let w = warning_text(&load_text(&text(sampler, 12)));
        assert!(
            w.contains("Taking 16 samples, not 12 as specified"),
            "{sampler}: {w}"
        );
        assert!(w.contains(":2:"), "located at the Integrator line: {w}");
        let w = warning_text(&load_text(&text(sampler, 16)));
        assert!(!w.contains("Taking"), "{sampler}: {w}");
    }
    for sampler in ["halton", "sobol", "random", "stratified"] {
        let w = warning_text(&load_text(&text(sampler, 12)));
        assert!(!w.contains("Taking"), "{sampler}: {w}");
    }
}
