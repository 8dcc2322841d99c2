//! `subsurface` and `kdsubsurface` (entries of the material table):
//! built from their defaults and from a preset, their coefficients as
//! pbrt-v3's `CreateSubsurfaceMaterial` / `KdSubsurfaceMaterial` give them,
//! and their boundary BSDF as `glass`'s.

mod common;
mod tex_common;

use common::{load_text, warning_text};
use glam::Vec3;
use pbrs::bssrdf::table::RHO_SAMPLES;
use pbrs::materials::{BsdfContext, Material, MaterialKind, MATERIALS};
use pbrs::media::presets;
use pbrs::scene::{ParamKind, ParamValue, ParamValues, SpectrumDefault, SpectrumTex, Tex};
use tex_common::*;

fn kind(name: &str) -> &'static MaterialKind {
    MATERIALS.iter().find(|k| k.name == name).unwrap()
}

/// The kind's parameters at their defaults, with `extra` set on top.
fn params(k: &MaterialKind, extra: Vec<(&'static str, ParamValue)>) -> ParamValues {
    let mut p = ParamValues::default();
    for s in k.params {
        let v = match s.kind {
            ParamKind::FloatTexture(Some(d)) => ParamValue::FloatTexture(Tex::Constant(d)),
            ParamKind::SpectrumTexture(Some(SpectrumDefault::Rgb(c))) => {
                ParamValue::SpectrumTexture(Tex::Constant(Vec3::from(c)))
            }
            ParamKind::Float(d) => ParamValue::Float(d),
            ParamKind::Bool(d) => ParamValue::Bool(d),
            ParamKind::String(d) => ParamValue::String(d.to_string()),
            _ => continue,
        };
        p.set(s.name, v);
    }
    for (n, v) in extra {
        p.set(n, v);
    }
    p
}

#[test]
fn subsurface_defaults_and_presets() {
    let k = kind("subsurface");
    let at = At::uv(0.3, 0.6);
    let Material::Subsurface(m) = (k.build)(&params(k, vec![])) else {
        panic!("not a subsurface material")
    };
    let (sa, ss) = m.coefficients(&at.sc());
    assert_eq!(sa, Vec3::new(0.0011, 0.0024, 0.014));
    assert_eq!(ss, Vec3::new(2.55, 3.21, 3.77));
    assert_eq!((m.boundary.g, m.boundary.eta), (0.0, 1.33));
    assert_eq!(m.boundary.table.rho_eff.len(), RHO_SAMPLES);

    // A preset sets both coefficients (σ′s as σs), forces g = 0; scale
    // multiplies; a given sigma_a overrides the preset's.
    let skim = presets::measured("Skimmilk").unwrap();
    let Material::Subsurface(m) = (k.build)(&params(
        k,
        vec![
            ("name", ParamValue::String("Skimmilk".into())),
            ("g", ParamValue::Float(0.7)),
            ("scale", ParamValue::Float(10.0)),
            (
                "sigma_a",
                ParamValue::SpectrumTexture(SpectrumTex::Constant(Vec3::splat(0.5))),
            ),
        ],
    )) else {
        panic!()
    };
    let (sa, ss) = m.coefficients(&at.sc());
    assert_eq!(m.boundary.g, 0.0);
    assert_eq!(sa, Vec3::splat(5.0));
    assert_eq!(ss, 10.0 * Vec3::from(skim.sigma_prime_s));
    assert!(pbrs::materials::Subsurface::load_warnings(&params(k, vec![])).is_empty());
    let w = pbrs::materials::Subsurface::load_warnings(&params(
        k,
        vec![("name", ParamValue::String("Skimmlik".into()))],
    ));
    assert_eq!(w.len(), 1, "{w:?}");

    // The boundary is glass's: one FresnelSpecular lobe under the path
    // tracers, η = 1.33.
    let mats = [Material::Subsurface(m)];
    let ctx = BsdfContext {
        materials: &mats,
        multiple_lobes: true,
    };
    let b = mats[0].bsdf(&at.sc(), &ctx);
    assert_eq!(b.eta, 1.33);
}

#[test]
fn kdsubsurface_inverts_kd_through_the_table() {
    let k = kind("kdsubsurface");
    let at = At::uv(0.3, 0.6);
    let Material::KdSubsurface(m) = (k.build)(&params(
        k,
        vec![
            (
                "Kd",
                ParamValue::SpectrumTexture(SpectrumTex::Constant(Vec3::new(0.2, 0.5, 0.8))),
            ),
            (
                "mfp",
                ParamValue::SpectrumTexture(SpectrumTex::Constant(Vec3::new(1.0, 2.0, 0.5))),
            ),
            ("scale", ParamValue::Float(0.5)),
        ],
    )) else {
        panic!("not a kdsubsurface material")
    };
    let (sa, ss) = m.coefficients(&at.sc());
    let mfp = Vec3::new(0.5, 1.0, 0.25);
    for c in 0..3 {
        // σt = 1/(scale·mfp); the albedo grows with Kd.
        assert!(((sa[c] + ss[c]) * mfp[c] - 1.0).abs() < 1e-5, "{c}");
    }
    let rho = ss * mfp;
    assert!(
        rho.x < rho.y && rho.y < rho.z && rho.z < 1.0 && rho.x > 0.0,
        "{rho}"
    );
}

/// The probe walk of pbrt-v3's `Sample_Sp` on a loaded scene: a subsurface
/// sphere at the origin and a matte sphere at x = 3, both of radius 1.
#[test]
fn probe_rays_find_the_hits_of_the_entry_points_material() {
    use pbrs::bssrdf::probe::{find_exit, ProbeSegment};
    use pbrs::geometry::Ray;
    use pbrs::integrators::RenderScene;
    let s = load_text(
        "WorldBegin\nMaterial \"subsurface\"\nShape \"sphere\" \"float radius\" 1\nAttributeBegin\nTranslate 3 0 0\nMaterial \"matte\"\nShape \"sphere\" \"float radius\" 1\nAttributeEnd\nWorldEnd\n",
    );
    let rs = RenderScene::new(&s.scene);
    let g = &rs.aggregate;
    let material_at = |o: Vec3| {
        let h = g.intersect_at(&Ray::new(o, Vec3::NEG_Z), 0.0).unwrap();
        g.surface_at(&h, 0.0).material
    };
    let sss = material_at(Vec3::new(0.0, 0.0, 5.0));
    let matte = material_at(Vec3::new(3.0, 0.0, 5.0));
    assert_ne!(sss, matte);
    let seg = |start: Vec3, end: Vec3, u: f32| ProbeSegment {
        start,
        end,
        u_choice: u,
        channel: 0,
    };
    // Along the z axis through the subsurface sphere: two hits, z = 1 then
    // z = −1, chosen by u_choice in halves.
    let mut rays = 0u64;
    let (near, n) = find_exit(
        g,
        &seg(Vec3::new(0.0, 0.0, 2.0), Vec3::new(0.0, 0.0, -2.0), 0.2),
        sss,
        0.0,
        &mut rays,
    )
    .unwrap();
    assert_eq!(n, 2);
    assert!((near.point.p.z - 1.0).abs() < 1e-5, "{}", near.point.p);
    assert!(near.point.n.z.abs() > 0.999);
    // Counted twice, then up to the choice: 3 rays (the third misses) + 1.
    assert_eq!(rays, 4);
    let (far, n) = find_exit(
        g,
        &seg(Vec3::new(0.0, 0.0, 2.0), Vec3::new(0.0, 0.0, -2.0), 0.7),
        sss,
        0.0,
        &mut rays,
    )
    .unwrap();
    assert_eq!(n, 2);
    assert!((far.point.p.z + 1.0).abs() < 1e-5, "{}", far.point.p);
    // A probe that stops inside the sphere sees only the near hit.
    let (_, n) = find_exit(
        g,
        &seg(Vec3::new(0.0, 0.0, 2.0), Vec3::new(0.0, 0.0, 0.0), 0.9),
        sss,
        0.0,
        &mut rays,
    )
    .unwrap();
    assert_eq!(n, 1);
    // Through the matte sphere only: no admissible hit.
    assert!(find_exit(
        g,
        &seg(Vec3::new(3.0, 0.0, 2.0), Vec3::new(3.0, 0.0, -2.0), 0.5),
        sss,
        0.0,
        &mut rays,
    )
    .is_none());
    // Along x through both spheres: the matte sphere's two hits are skipped.
    for (u, x) in [(0.1, -1.0), (0.9, 1.0)] {
        let (h, n) = find_exit(
            g,
            &seg(Vec3::new(-2.0, 0.0, 0.0), Vec3::new(5.0, 0.0, 0.0), u),
            sss,
            0.0,
            &mut rays,
        )
        .unwrap();
        assert_eq!(n, 2);
        assert!((h.point.p.x - x).abs() < 1e-5, "{}", h.point.p);
        assert_eq!(h.material, sss);
    }
}

/// Subsurface materials render under `path` and `volpath` without a
/// warning, and the integrators that do not sample BSSRDFs say so.
#[test]
fn integrators_without_bssrdf_sampling_warn() {
    let scene = |integrator: &str| {
        format!("Integrator \"{integrator}\"\nWorldBegin\nLightSource \"point\"\nMaterial \"kdsubsurface\"\nShape \"sphere\"\nWorldEnd\n")
    };
    for i in ["path", "volpath"] {
        let w = warning_text(&load_text(&scene(i)));
        assert!(w.is_empty(), "{i}: {w}");
    }
    for i in ["directlighting", "whitted"] {
        let w = warning_text(&load_text(&scene(i)));
        assert!(
            w.contains(&format!(
                "the \"{i}\" integrator does not sample subsurface scattering"
            )),
            "{i}: {w}"
        );
    }
    // An unknown measured medium is a located warning (pbrt-v3 warns too).
    let w = warning_text(&load_text(
        "WorldBegin\nMaterial \"subsurface\" \"string name\" \"Ketchupp\"\nShape \"sphere\"\nWorldEnd\n",
    ));
    assert!(
        w.contains("mem.pbrt:2:10") && w.contains("unknown medium name \"Ketchupp\""),
        "{w}"
    );
}
