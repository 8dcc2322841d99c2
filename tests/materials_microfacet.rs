//! The microfacet materials through the real loader (`common::material_bsdf`):
//! the lobes pbrt-v3's `ComputeScatteringFunctions` would add, in its order,
//! with its defaults and a few parameter sets; anisotropy and the shading
//! frame; `mix` weights, η and frame, nesting, and the warning when a mix
//! could exceed pbrt-v3's 8 lobes.

mod common;

use common::{material_bsdf, materials_of};
use glam::Vec3;
use pbrs::bxdf::{
    roughness_to_alpha, Bxdf, Fresnel, MicrofacetDistribution, TrowbridgeReitz, MAX_BXDFS,
};
use pbrs::materials::{Bsdf, BxdfFlags, MATERIALS};

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).abs().max_element() < 1e-5
}

/// The Trowbridge–Reitz distribution pbrt-v3 builds from two roughnesses
/// (remapped, visible-normal sampling).
fn tr(u: f32, v: f32) -> MicrofacetDistribution {
    MicrofacetDistribution::TrowbridgeReitz(TrowbridgeReitz {
        alpha_x: roughness_to_alpha(u),
        alpha_y: roughness_to_alpha(v),
        sample_visible: true,
    })
}

/// A short name per lobe, in order.
fn kinds(b: &Bsdf) -> Vec<&'static str> {
    b.lobes()
        .iter()
        .map(|l| match l.bxdf {
            Bxdf::LambertianReflection(_) => "lambert",
            Bxdf::LambertianTransmission(_) => "lambert-t",
            Bxdf::OrenNayar(_) => "oren-nayar",
            Bxdf::SpecularReflection(_) => "spec-r",
            Bxdf::SpecularTransmission(_) => "spec-t",
            Bxdf::FresnelSpecular(_) => "fresnel-spec",
            Bxdf::MicrofacetReflection(_) => "micro-r",
            Bxdf::MicrofacetTransmission(_) => "micro-t",
            Bxdf::FresnelBlend(_) => "blend",
            Bxdf::DisneyDiffuse(_) => "disney-diffuse",
            Bxdf::DisneyFakeSS(_) => "disney-fakess",
            Bxdf::DisneyRetro(_) => "disney-retro",
            Bxdf::DisneySheen(_) => "disney-sheen",
            Bxdf::DisneyClearcoat(_) => "disney-clearcoat",
            Bxdf::Fourier(_) => "fourier",
            Bxdf::SwAdapter(_) => "sw-adapter",
            Bxdf::Hair(_) => "hair",
        })
        .collect()
}

fn warnings_of(text: &str) -> String {
    let l = pbrs::loader::load_scene_str(text, &common::repo().join("mem.pbrt"))
        .unwrap_or_else(|f| panic!("{:?}", f.errors));
    l.warnings
        .iter()
        .map(|w| w.to_string())
        .collect::<Vec<_>>()
        .join("\n")
}

fn anisotropic(decl: &str) -> bool {
    let (m, i) = materials_of(decl);
    m[i].anisotropic()
}

#[test]
fn every_material_kind_is_in_the_table() {
    for name in [
        "plastic",
        "metal",
        "substrate",
        "uber",
        "translucent",
        "glass",
        "mix",
    ] {
        let k = MATERIALS.iter().find(|k| k.name == name);
        assert!(k.is_some(), "{name} not in MATERIALS");
        assert!(
            warnings_of(&format!(
                "WorldBegin\nMaterial \"{name}\"\nShape \"sphere\"\nWorldEnd"
            ))
            .lines()
            .all(|w| name == "mix" && w.contains("namedmaterial")),
            "{name}: unexpected warnings"
        );
    }
}

#[test]
fn plastic_lobes() {
    let b = material_bsdf("\"plastic\"", true);
    assert_eq!(kinds(&b), ["lambert", "micro-r"]);
    assert_eq!(b.eta, 1.0);
    let Bxdf::LambertianReflection(l) = b.lobes()[0].bxdf else {
        unreachable!()
    };
    assert!(close(l.r, Vec3::splat(0.25)));
    let Bxdf::MicrofacetReflection(m) = b.lobes()[1].bxdf else {
        unreachable!()
    };
    assert!(close(m.r, Vec3::splat(0.25)));
    assert_eq!(m.distribution, tr(0.1, 0.1));
    // pbrt-v3's FresnelDielectric(1.5, 1).
    assert!(
        matches!(m.fresnel, Fresnel::Dielectric { eta_i, eta_t } if eta_i == 1.5 && eta_t == 1.0)
    );
    // No diffuse lobe for a black Kd; α as given without remapping.
    let b = material_bsdf(
        "\"plastic\" \"rgb Kd\" [0 0 0] \"rgb Ks\" [0.3 0.2 0.1] \"float roughness\" 0.2 \"bool remaproughness\" \"false\"",
        false,
    );
    assert_eq!(kinds(&b), ["micro-r"]);
    let Bxdf::MicrofacetReflection(m) = b.lobes()[0].bxdf else {
        unreachable!()
    };
    assert!(close(m.r, Vec3::new(0.3, 0.2, 0.1)));
    assert!(
        matches!(m.distribution, MicrofacetDistribution::TrowbridgeReitz(d) if d.alpha_x == 0.2 && d.alpha_y == 0.2)
    );
    let b = material_bsdf("\"plastic\" \"rgb Ks\" [0 0 0]", true);
    assert_eq!(kinds(&b), ["lambert"]);
    assert!(!anisotropic("\"plastic\""));
}

#[test]
fn metal_lobes_and_default_copper() {
    let b = material_bsdf("\"metal\"", true);
    assert_eq!(kinds(&b), ["micro-r"]);
    let Bxdf::MicrofacetReflection(m) = b.lobes()[0].bxdf else {
        unreachable!()
    };
    assert_eq!(m.r, Vec3::ONE);
    assert_eq!(m.distribution, tr(0.01, 0.01));
    let Fresnel::Conductor { eta_i, eta_t, k } = m.fresnel else {
        panic!("{:?}", m.fresnel)
    };
    assert_eq!(eta_i, Vec3::ONE);
    // Measured copper in RGB: a low index in red (it is the red metal),
    // about 1 in green and blue, absorption falling from red to blue
    // (about 0.2 0.92 1.1 and 3.9 2.45 2.14 in the usual RGB tables).
    println!("copper eta {eta_t}, k {k}");
    assert!(
        (eta_t - Vec3::new(0.2, 0.92, 1.1)).abs().max_element() < 0.08,
        "{eta_t}"
    );
    assert!(
        (k - Vec3::new(3.9, 2.45, 2.14)).abs().max_element() < 0.12,
        "{k}"
    );
    // Normal-incidence reflectance: reddish.
    let f0 = m.fresnel.evaluate(1.0);
    assert!(f0.x > f0.y && f0.y > f0.z && f0.x > 0.9, "{f0}");
    // uroughness/vroughness default to roughness, each on its own.
    let b = material_bsdf(
        "\"metal\" \"float roughness\" 0.3 \"float uroughness\" 0.05 \"rgb eta\" [1 1 1] \"rgb k\" [2 2 2]",
        true,
    );
    let Bxdf::MicrofacetReflection(m) = b.lobes()[0].bxdf else {
        unreachable!()
    };
    assert_eq!(m.distribution, tr(0.05, 0.3));
    assert!(
        matches!(m.fresnel, Fresnel::Conductor { eta_t, k, .. } if eta_t == Vec3::ONE && k == Vec3::splat(2.0))
    );
    assert!(anisotropic("\"metal\" \"float uroughness\" 0.05"));
    assert!(!anisotropic(
        "\"metal\" \"float uroughness\" 0.05 \"float vroughness\" 0.05"
    ));
    assert!(!anisotropic("\"metal\" \"float roughness\" 0.2"));
    // Anisotropic: the frame's x axis is dp/du (+x at the test point).
    let b = material_bsdf(
        "\"metal\" \"float uroughness\" 0.05 \"float vroughness\" 0.3",
        true,
    );
    assert!((b.frame.s - Vec3::X).length() < 1e-6 && (b.frame.n - Vec3::Z).length() < 1e-6);
}

#[test]
fn substrate_lobes() {
    let b = material_bsdf("\"substrate\"", true);
    assert_eq!(kinds(&b), ["blend"]);
    let Bxdf::FresnelBlend(f) = b.lobes()[0].bxdf else {
        unreachable!()
    };
    assert!(close(f.rd, Vec3::splat(0.5)) && close(f.rs, Vec3::splat(0.5)));
    assert_eq!(f.distribution, tr(0.1, 0.1));
    let b = material_bsdf(
        "\"substrate\" \"rgb Kd\" [0.6 0.1 0.1] \"rgb Ks\" [0.04 0.04 0.04] \"float uroughness\" 0.02 \"float vroughness\" 0.2",
        true,
    );
    let Bxdf::FresnelBlend(f) = b.lobes()[0].bxdf else {
        unreachable!()
    };
    assert!(close(f.rd, Vec3::new(0.6, 0.1, 0.1)));
    assert_eq!(f.distribution, tr(0.02, 0.2));
    assert!(anisotropic(
        "\"substrate\" \"float uroughness\" 0.02 \"float vroughness\" 0.2"
    ));
    assert!(!anisotropic("\"substrate\""));
    // Both black: no lobe.
    let b = material_bsdf("\"substrate\" \"rgb Kd\" [0 0 0] \"rgb Ks\" [0 0 0]", true);
    assert!(b.is_empty());
}

#[test]
fn uber_lobes_in_pbrt_order() {
    let b = material_bsdf("\"uber\"", true);
    assert_eq!(kinds(&b), ["lambert", "micro-r"]);
    assert_eq!(b.eta, 1.5);
    let Bxdf::MicrofacetReflection(m) = b.lobes()[1].bxdf else {
        unreachable!()
    };
    assert_eq!(m.distribution, tr(0.1, 0.1));
    assert!(
        matches!(m.fresnel, Fresnel::Dielectric { eta_i, eta_t } if eta_i == 1.0 && eta_t == 1.5)
    );
    // Everything: pass-through first, then diffuse, glossy, mirror, glass;
    // all but the pass-through scaled by the opacity.
    let b = material_bsdf(
        "\"uber\" \"rgb opacity\" [0.5 0.5 0.5] \"rgb Kr\" [0.3 0.3 0.3] \"rgb Kt\" [0.4 0.4 0.4] \"float index\" 1.33",
        false,
    );
    assert_eq!(
        kinds(&b),
        ["spec-t", "lambert", "micro-r", "spec-r", "spec-t"]
    );
    assert_eq!(b.eta, 1.0, "see-through: η 1");
    let l = b.lobes();
    let Bxdf::SpecularTransmission(t0) = l[0].bxdf else {
        unreachable!()
    };
    assert!(close(t0.t, Vec3::splat(0.5)) && t0.eta_a == 1.0 && t0.eta_b == 1.0);
    let Bxdf::LambertianReflection(d) = l[1].bxdf else {
        unreachable!()
    };
    assert!(close(d.r, Vec3::splat(0.125)));
    let Bxdf::SpecularReflection(r) = l[3].bxdf else {
        unreachable!()
    };
    assert!(close(r.r, Vec3::splat(0.15)));
    assert!(matches!(r.fresnel, Fresnel::Dielectric { eta_t, .. } if eta_t == 1.33));
    let Bxdf::SpecularTransmission(t) = l[4].bxdf else {
        unreachable!()
    };
    assert!(close(t.t, Vec3::splat(0.2)) && t.eta_a == 1.0 && t.eta_b == 1.33);
    // Opaque with Kt: η is the index; eta before index.
    let b = material_bsdf(
        "\"uber\" \"rgb Kt\" [1 1 1] \"float eta\" 2 \"float index\" 1.2",
        true,
    );
    assert_eq!(b.eta, 2.0);
    // pbrt-v3: vroughness defaults to the u roughness, not to roughness.
    let b = material_bsdf(
        "\"uber\" \"float roughness\" 0.5 \"float uroughness\" 0.05",
        true,
    );
    let Bxdf::MicrofacetReflection(m) = b.lobes()[1].bxdf else {
        unreachable!()
    };
    assert_eq!(m.distribution, tr(0.05, 0.05));
    assert!(!anisotropic("\"uber\" \"float uroughness\" 0.05"));
    assert!(anisotropic(
        "\"uber\" \"float uroughness\" 0.05 \"float vroughness\" 0.2"
    ));
    // Fully transparent: only the pass-through.
    let b = material_bsdf("\"uber\" \"rgb opacity\" [0 0 0]", true);
    assert_eq!(kinds(&b), ["spec-t"]);
}

#[test]
fn translucent_lobes() {
    let b = material_bsdf("\"translucent\"", true);
    assert_eq!(kinds(&b), ["lambert", "lambert-t", "micro-r", "micro-t"]);
    assert_eq!(b.eta, 1.5);
    for l in b.lobes() {
        let w = match l.bxdf {
            Bxdf::LambertianReflection(x) => x.r,
            Bxdf::LambertianTransmission(x) => x.t,
            Bxdf::MicrofacetReflection(x) => {
                assert_eq!(x.distribution, tr(0.1, 0.1));
                x.r
            }
            Bxdf::MicrofacetTransmission(x) => {
                assert!(x.eta_a == 1.0 && x.eta_b == 1.5);
                x.t
            }
            _ => unreachable!(),
        };
        assert!(close(w, Vec3::splat(0.125)), "{w}");
    }
    let b = material_bsdf("\"translucent\" \"rgb transmit\" [0 0 0]", true);
    assert_eq!(kinds(&b), ["lambert", "micro-r"]);
    let b = material_bsdf("\"translucent\" \"rgb Ks\" [0 0 0]", true);
    assert_eq!(kinds(&b), ["lambert", "lambert-t"]);
    let b = material_bsdf(
        "\"translucent\" \"rgb reflect\" [0 0 0] \"rgb transmit\" [0 0 0]",
        true,
    );
    assert!(b.is_empty() && b.eta == 1.5);
}

#[test]
fn rough_glass_lobes() {
    for multiple in [true, false] {
        let b = material_bsdf(
            "\"glass\" \"float uroughness\" 0.1 \"float vroughness\" 0.1",
            multiple,
        );
        assert_eq!(
            kinds(&b),
            ["micro-r", "micro-t"],
            "multiple lobes {multiple}"
        );
        assert_eq!(b.eta, 1.5);
        let Bxdf::MicrofacetTransmission(t) = b.lobes()[1].bxdf else {
            unreachable!()
        };
        assert_eq!(t.distribution, tr(0.1, 0.1));
        assert!(t.eta_a == 1.0 && t.eta_b == 1.5);
    }
    // One roughness > 0 is rough (and anisotropic).
    let b = material_bsdf("\"glass\" \"float vroughness\" 0.2", true);
    assert_eq!(kinds(&b), ["micro-r", "micro-t"]);
    let Bxdf::MicrofacetReflection(r) = b.lobes()[0].bxdf else {
        unreachable!()
    };
    assert_eq!(r.distribution, tr(0.0, 0.2));
    assert!(anisotropic("\"glass\" \"float vroughness\" 0.2"));
    assert!(!anisotropic("\"glass\""));
    // Kt black: reflection only.
    let b = material_bsdf(
        "\"glass\" \"float uroughness\" 0.1 \"float vroughness\" 0.1 \"rgb Kt\" [0 0 0]",
        true,
    );
    assert_eq!(kinds(&b), ["micro-r"]);
    // Smooth glass is unchanged.
    assert_eq!(kinds(&material_bsdf("\"glass\"", true)), ["fresnel-spec"]);
    assert_eq!(
        kinds(&material_bsdf("\"glass\"", false)),
        ["spec-r", "spec-t"]
    );
    // Rough glass transmits glossily: the BSDF samples non-specular
    // transmission through the surface.
    let b = material_bsdf(
        "\"glass\" \"float uroughness\" 0.3 \"float vroughness\" 0.3",
        true,
    );
    let wo = Vec3::new(0.3, 0.1, 0.9).normalize();
    let mut transmitted = 0;
    for i in 0..1000 {
        let u = glam::Vec2::new((i as f32 + 0.5) / 1000.0, 0.37);
        if let Some(s) = b.sample(wo, u, BxdfFlags::ALL) {
            assert!(!s.is_specular());
            if s.wi.z < 0.0 {
                assert!(s.is_transmission());
                transmitted += 1;
            }
        }
    }
    assert!(transmitted > 400, "{transmitted}");
}

/// Named materials (whole statements: `common::materials_of` takes the
/// text as it is when it has several lines).
const NAMED: &str = "MakeNamedMaterial \"red\" \"string type\" \"matte\" \"rgb Kd\" [0.8 0 0]
MakeNamedMaterial \"coat\" \"string type\" \"plastic\"
MakeNamedMaterial \"clear\" \"string type\" \"glass\" \"float index\" 1.7
MakeNamedMaterial \"brushed\" \"string type\" \"metal\" \"float uroughness\" 0.05 \"float vroughness\" 0.3
MakeNamedMaterial \"full\" \"string type\" \"uber\" \"rgb opacity\" [0.5 0.5 0.5] \"rgb Kr\" [0.3 0.3 0.3] \"rgb Kt\" [0.4 0.4 0.4]
";

#[test]
fn mix_scales_both_materials() {
    let b = material_bsdf(
        &format!("{NAMED}Material \"mix\" \"string namedmaterial1\" \"red\" \"string namedmaterial2\" \"coat\" \"rgb amount\" [0.25 0.5 1.5]"),
        true,
    );
    assert_eq!(kinds(&b), ["lambert", "lambert", "micro-r"]);
    let l = b.lobes();
    assert!(close(l[0].scale, Vec3::new(0.25, 0.5, 1.5)));
    // 1 − amount, clamped at 0.
    assert!(close(l[1].scale, Vec3::new(0.75, 0.5, 0.0)));
    assert!(close(l[2].scale, Vec3::new(0.75, 0.5, 0.0)));
    // Value: the weighted sum of the two materials' values.
    let (wo, wi) = (
        Vec3::new(0.2, 0.1, 0.9).normalize(),
        Vec3::new(-0.3, 0.2, 0.8).normalize(),
    );
    let red = material_bsdf(&format!("{NAMED}NamedMaterial \"red\""), true);
    let coat = material_bsdf(&format!("{NAMED}NamedMaterial \"coat\""), true);
    let want = red.f(wo, wi, BxdfFlags::ALL) * Vec3::new(0.25, 0.5, 1.5)
        + coat.f(wo, wi, BxdfFlags::ALL) * Vec3::new(0.75, 0.5, 0.0);
    assert!(close(b.f(wo, wi, BxdfFlags::ALL), want));
    // Default amount 0.5; η and frame from material 1.
    let b = material_bsdf(
        &format!("{NAMED}Material \"mix\" \"string namedmaterial1\" \"clear\" \"string namedmaterial2\" \"red\""),
        true,
    );
    assert_eq!(kinds(&b), ["fresnel-spec", "lambert"]);
    assert!(b.lobes().iter().all(|l| close(l.scale, Vec3::splat(0.5))));
    assert_eq!(b.eta, 1.7);
    let b = material_bsdf(
        &format!("{NAMED}Material \"mix\" \"string namedmaterial1\" \"red\" \"string namedmaterial2\" \"clear\""),
        true,
    );
    assert_eq!(b.eta, 1.0, "η of material 1 (matte), not of the glass");
    // An anisotropic material makes the mix anisotropic (frame along dp/du).
    let decl = format!("{NAMED}Material \"mix\" \"string namedmaterial1\" \"red\" \"string namedmaterial2\" \"brushed\"");
    let (m, i) = materials_of(&decl);
    assert!(m[i].anisotropic() && m[i].needs_geom());
    let decl = format!("{NAMED}Material \"mix\" \"string namedmaterial1\" \"red\" \"string namedmaterial2\" \"coat\"");
    let (m, i) = materials_of(&decl);
    assert!(!m[i].anisotropic() && !m[i].needs_geom());
}

#[test]
fn nested_mix_multiplies_weights() {
    let decl = format!(
        "{NAMED}MakeNamedMaterial \"inner\" \"string type\" \"mix\" \"string namedmaterial1\" \"red\" \"string namedmaterial2\" \"coat\" \"rgb amount\" [0.2 0.2 0.2]
Material \"mix\" \"string namedmaterial1\" \"inner\" \"string namedmaterial2\" \"red\" \"rgb amount\" [0.6 0.6 0.6]"
    );
    let b = material_bsdf(&decl, true);
    assert_eq!(kinds(&b), ["lambert", "lambert", "micro-r", "lambert"]);
    let s: Vec<f32> = b.lobes().iter().map(|l| l.scale.x).collect();
    let want = [0.6 * 0.2, 0.6 * 0.8, 0.6 * 0.8, 0.4];
    for (a, w) in s.iter().zip(want) {
        assert!((a - w).abs() < 1e-6, "{s:?} vs {want:?}");
    }
    assert!(
        !warnings_of(&format!("WorldBegin\n{decl}\nShape \"sphere\"\nWorldEnd")).contains("lobes")
    );
}

#[test]
fn mix_beyond_eight_lobes_warns_and_drops() {
    // uber with opacity, Kr and Kt has 5 lobes: two of them are 10.
    let decl = format!("{NAMED}Material \"mix\" \"string namedmaterial1\" \"full\" \"string namedmaterial2\" \"full\" \"rgb amount\" [0.3 0.3 0.3]");
    let text = format!("WorldBegin\n{decl}\nShape \"sphere\"\nWorldEnd");
    let w = warnings_of(&text);
    assert!(
        w.contains("mem.pbrt:7:") && w.contains("up to 10 lobes, more than the 8 a BSDF holds"),
        "{w}"
    );
    let b = material_bsdf(&decl, false);
    assert_eq!(b.lobes().len(), MAX_BXDFS);
    // Nested: (full + red) + full = 11, warned at the outer mix, located.
    let decl = format!(
        "{NAMED}MakeNamedMaterial \"inner\" \"string type\" \"mix\" \"string namedmaterial1\" \"full\" \"string namedmaterial2\" \"red\"
Material \"mix\" \"string namedmaterial1\" \"inner\" \"string namedmaterial2\" \"full\""
    );
    let w = warnings_of(&format!("WorldBegin\n{decl}\nShape \"sphere\"\nWorldEnd"));
    assert!(
        w.contains("mem.pbrt:8:") && w.contains("up to 11 lobes"),
        "{w}"
    );
    assert_eq!(w.matches("lobes, more than").count(), 1, "{w}");
    // Within 8 (5 + 2): no warning.
    let w = warnings_of(&format!(
        "WorldBegin\n{NAMED}Material \"mix\" \"string namedmaterial1\" \"full\" \"string namedmaterial2\" \"coat\"\nShape \"sphere\"\nWorldEnd"
    ));
    assert!(!w.contains("lobes"), "{w}");
}
