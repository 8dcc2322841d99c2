//! `uber`: pbrt-v3's `UberMaterial`, a kitchen-sink material: partial
//! opacity, diffuse, glossy, specular reflection and specular transmission.
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `Kd` | spectrum texture | 0.25 | diffuse reflectance |
//! | `Ks` | spectrum texture | 0.25 | glossy reflectance |
//! | `Kr` | spectrum texture | 0 | specular reflectance |
//! | `Kt` | spectrum texture | 0 | specular transmittance |
//! | `roughness` | float texture | 0.1 | glossy roughness when `uroughness` is absent |
//! | `uroughness` | float texture | `roughness` | roughness along dp/du |
//! | `vroughness` | float texture | `uroughness`'s value | roughness along dp/dv (pbrt-v3 defaults it to the u roughness) |
//! | `eta` | float texture | | index of refraction (pbrt-v3 reads `eta` first) |
//! | `index` | float texture | 1.5 | index of refraction when `eta` is absent |
//! | `opacity` | spectrum texture | 1 | 1 − opacity passes straight through |
//! | `remaproughness` | bool | true | roughness → α as pbrt-v3's `RoughnessToAlpha` |
//! | `bumpmap` | float texture | | displacement for bump mapping (every material: `bump.rs`) |
//!
//! Lobes, in pbrt-v3's order, each only if its weight is not black (all
//! weights clamped ≥ 0; op = opacity):
//! 1. specular transmission of 1 − op with η 1 on both sides (then the
//!    BSDF's η is 1, else `eta`),
//! 2. Lambertian op·Kd,
//! 3. Trowbridge–Reitz microfacet reflection op·Ks, `FresnelDielectric(1, eta)`,
//! 4. specular reflection op·Kr, `FresnelDielectric(1, eta)`,
//! 5. specular transmission op·Kt from η 1 into `eta`.

use super::Roughness;
use super::REMAP_ROUGHNESS;
use super::{may_scatter, Material, MaterialKind, ShadingContext, Support};
use crate::bxdf::{
    Bsdf, Fresnel, LambertianReflection, MicrofacetReflection, SpecularReflection,
    SpecularTransmission,
};
use crate::scene::{FloatTex, ParamSpec, ParamValues, SpectrumTex};
use glam::Vec3;

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::spectrum("Kd", 0.25, "diffuse reflectance"),
    ParamSpec::spectrum("Ks", 0.25, "glossy reflectance"),
    ParamSpec::spectrum("Kr", 0.0, "specular reflectance"),
    ParamSpec::spectrum("Kt", 0.0, "specular transmittance"),
    ParamSpec::nonneg_tex(
        "roughness",
        0.1,
        "glossy roughness when uroughness is absent",
    ),
    ParamSpec::nonneg_tex_opt("uroughness", "roughness along dp/du (default: roughness)"),
    ParamSpec::nonneg_tex_opt(
        "vroughness",
        "roughness along dp/dv (default: the u roughness)",
    ),
    ParamSpec::float_tex_opt("eta", "index of refraction (read before `index`)"),
    ParamSpec::float_tex("index", 1.5, "index of refraction when `eta` is absent"),
    ParamSpec::spectrum("opacity", 1.0, "opacity (1 − opacity passes through)"),
    REMAP_ROUGHNESS,
    ParamSpec::BUMPMAP,
];

pub const KIND: MaterialKind = MaterialKind {
    name: "uber",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "opacity, diffuse, glossy, specular reflection and transmission",
    build: |p| Material::Uber(Uber::new(p)),
};

#[derive(Clone, Debug)]
pub struct Uber {
    pub kd: SpectrumTex,
    pub ks: SpectrumTex,
    pub kr: SpectrumTex,
    pub kt: SpectrumTex,
    pub roughness: Roughness,
    pub eta: FloatTex,
    pub opacity: SpectrumTex,
}

impl Uber {
    pub fn new(p: &ParamValues) -> Uber {
        let u_roughness = p
            .float_tex("uroughness")
            .unwrap_or_else(|| p.float_tex("roughness").expect("default"));
        Uber {
            kd: p.spectrum_tex("Kd").expect("default"),
            ks: p.spectrum_tex("Ks").expect("default"),
            kr: p.spectrum_tex("Kr").expect("default"),
            kt: p.spectrum_tex("Kt").expect("default"),
            roughness: Roughness {
                v: p.float_tex("vroughness").unwrap_or(u_roughness.clone()),
                u: u_roughness,
                remap: p.boolean("remaproughness"),
            },
            eta: p
                .float_tex("eta")
                .unwrap_or_else(|| p.float_tex("index").expect("default")),
            opacity: p.spectrum_tex("opacity").expect("default"),
        }
    }

    pub fn anisotropic(&self) -> bool {
        self.roughness.anisotropic()
    }

    pub fn needs_geom(&self) -> bool {
        [&self.kd, &self.ks, &self.kr, &self.kt, &self.opacity]
            .iter()
            .any(|t| t.as_constant().is_none())
            || self.eta.as_constant().is_none()
            || self.roughness.needs_geom()
    }

    pub fn max_lobes(&self) -> usize {
        let see_through = match self.opacity.as_constant() {
            Some(op) => op.min_element() < 1.0,
            None => true,
        };
        let opaque_part = may_scatter(&self.opacity);
        let lobes = [&self.kd, &self.ks, &self.kr, &self.kt]
            .iter()
            .filter(|t| opaque_part && may_scatter(t))
            .count();
        see_through as usize + lobes
    }

    #[inline]
    pub fn scatter(&self, sc: &ShadingContext, bsdf: &mut Bsdf) {
        let eta = self.eta.eval(sc);
        let op = self.opacity.eval(sc).max(Vec3::ZERO);
        let through = (Vec3::ONE - op).max(Vec3::ZERO);
        if through != Vec3::ZERO {
            bsdf.eta = 1.0;
            bsdf.add(SpecularTransmission {
                t: through,
                eta_a: 1.0,
                eta_b: 1.0,
            });
        } else {
            bsdf.eta = eta;
        }
        let kd = op * self.kd.eval(sc).max(Vec3::ZERO);
        if kd != Vec3::ZERO {
            bsdf.add(LambertianReflection { r: kd });
        }
        let dielectric = Fresnel::Dielectric {
            eta_i: 1.0,
            eta_t: eta,
        };
        let ks = op * self.ks.eval(sc).max(Vec3::ZERO);
        if ks != Vec3::ZERO {
            let (u, v) = self.roughness.eval(sc);
            bsdf.add(MicrofacetReflection {
                r: ks,
                distribution: self.roughness.distribution((u, v)),
                fresnel: dielectric,
            });
        }
        let kr = op * self.kr.eval(sc).max(Vec3::ZERO);
        if kr != Vec3::ZERO {
            bsdf.add(SpecularReflection {
                r: kr,
                fresnel: dielectric,
            });
        }
        let kt = op * self.kt.eval(sc).max(Vec3::ZERO);
        if kt != Vec3::ZERO {
            bsdf.add(SpecularTransmission {
                t: kt,
                eta_a: 1.0,
                eta_b: eta,
            });
        }
    }
}
