//! `subsurface` and `kdsubsurface` (pending entries of the material table):
//! built from their defaults and from a preset, their coefficients as
//! pbrt-v3's `CreateSubsurfaceMaterial` / `KdSubsurfaceMaterial` give them,
//! and their boundary BSDF as `glass`'s.

mod tex_common;

use glam::Vec3;
use pbrs::render::bssrdf::table::RHO_SAMPLES;
use pbrs::render::materials::{BsdfContext, Material, MaterialKind, PENDING};
use pbrs::render::media::presets;
use pbrs::scene::{ParamKind, ParamValue, ParamValues, SpectrumDefault, SpectrumTex, Tex};
use tex_common::*;

fn kind(name: &str) -> &'static MaterialKind {
    PENDING.iter().find(|k| k.name == name).unwrap()
}

/// The kind's parameters at their defaults, with `extra` set on top.
fn params(k: &MaterialKind, extra: Vec<(&'static str, ParamValue)>) -> ParamValues {
    let mut p = ParamValues { values: Vec::new() };
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
    assert_eq!((m.g, m.eta), (0.0, 1.33));
    assert_eq!(m.table.rho_eff.len(), RHO_SAMPLES);

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
    assert_eq!(m.g, 0.0);
    assert_eq!(sa, Vec3::splat(5.0));
    assert_eq!(ss, 10.0 * Vec3::from(skim.sigma_prime_s));
    assert!(pbrs::render::materials::Subsurface::load_warnings(&params(k, vec![])).is_empty());
    let w = pbrs::render::materials::Subsurface::load_warnings(&params(
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
