//! `translucent`: a thin diffuse-and-glossy sheet that reflects and
//! transmits (pbrt-v3's `TranslucentMaterial`), with a fixed index of
//! refraction 1.5 (also the BSDF's η).
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `Kd` | spectrum texture | 0.25 | diffuse weight |
//! | `Ks` | spectrum texture | 0.25 | glossy weight |
//! | `reflect` | spectrum texture | 0.5 | fraction reflected |
//! | `transmit` | spectrum texture | 0.5 | fraction transmitted |
//! | `roughness` | float texture | 0.1 | glossy roughness (isotropic) |
//! | `remaproughness` | bool | true | roughness → α as pbrt-v3's `RoughnessToAlpha` |
//! | `bumpmap` | float texture | | displacement for bump mapping (every material: `bump.rs`) |
//!
//! Lobes (weights clamped ≥ 0; none if reflect and transmit are both
//! black): Lambertian reflection reflect·Kd, Lambertian transmission
//! transmit·Kd, then Trowbridge–Reitz microfacet reflection reflect·Ks with
//! `FresnelDielectric(1, 1.5)` and microfacet transmission transmit·Ks from
//! 1 into 1.5, each only if its weight is not black.

use super::REMAP_ROUGHNESS;
use super::{may_scatter, trowbridge_reitz, Material, MaterialKind, ShadingContext, Support};
use crate::bxdf::{
    Bsdf, Fresnel, LambertianReflection, LambertianTransmission, MicrofacetReflection,
    MicrofacetTransmission,
};
use crate::scene::{FloatTex, ParamSpec, ParamValues, SpectrumTex};
use glam::Vec3;

/// pbrt-v3's fixed index of refraction of the sheet.
const ETA: f32 = 1.5;

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::spectrum("Kd", 0.25, "diffuse weight"),
    ParamSpec::spectrum("Ks", 0.25, "glossy weight"),
    ParamSpec::spectrum("reflect", 0.5, "fraction reflected"),
    ParamSpec::spectrum("transmit", 0.5, "fraction transmitted"),
    ParamSpec::nonneg_tex("roughness", 0.1, "glossy roughness"),
    REMAP_ROUGHNESS,
    ParamSpec::BUMPMAP,
];

pub const KIND: MaterialKind = MaterialKind {
    name: "translucent",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "a thin sheet that reflects and transmits, diffusely and glossily",
    build: |p| Material::Translucent(Translucent::new(p)),
};

#[derive(Clone, Debug)]
pub struct Translucent {
    pub kd: SpectrumTex,
    pub ks: SpectrumTex,
    pub reflect: SpectrumTex,
    pub transmit: SpectrumTex,
    pub roughness: FloatTex,
    pub remap_roughness: bool,
}

impl Translucent {
    pub fn new(p: &ParamValues) -> Translucent {
        Translucent {
            kd: p.spectrum_tex("Kd").expect("default"),
            ks: p.spectrum_tex("Ks").expect("default"),
            reflect: p.spectrum_tex("reflect").expect("default"),
            transmit: p.spectrum_tex("transmit").expect("default"),
            roughness: p.float_tex("roughness").expect("default"),
            remap_roughness: p.boolean("remaproughness"),
        }
    }

    pub fn needs_geom(&self) -> bool {
        [&self.kd, &self.ks, &self.reflect, &self.transmit]
            .iter()
            .any(|t| t.as_constant().is_none())
            || self.roughness.as_constant().is_none()
    }

    pub fn max_lobes(&self) -> usize {
        let (r, t) = (may_scatter(&self.reflect), may_scatter(&self.transmit));
        let per_weight = (r as usize) + (t as usize);
        per_weight * (may_scatter(&self.kd) as usize + may_scatter(&self.ks) as usize)
    }

    #[inline]
    pub fn scatter(&self, sc: &ShadingContext, bsdf: &mut Bsdf) {
        bsdf.eta = ETA;
        let r = self.reflect.eval(sc).max(Vec3::ZERO);
        let t = self.transmit.eval(sc).max(Vec3::ZERO);
        if r == Vec3::ZERO && t == Vec3::ZERO {
            return;
        }
        let kd = self.kd.eval(sc).max(Vec3::ZERO);
        if kd != Vec3::ZERO {
            if r != Vec3::ZERO {
                bsdf.add(LambertianReflection { r: r * kd });
            }
            if t != Vec3::ZERO {
                bsdf.add(LambertianTransmission { t: t * kd });
            }
        }
        let ks = self.ks.eval(sc).max(Vec3::ZERO);
        if ks != Vec3::ZERO {
            let rough = self.roughness.eval(sc);
            let distribution = trowbridge_reitz(rough, rough, self.remap_roughness);
            if r != Vec3::ZERO {
                bsdf.add(MicrofacetReflection {
                    r: r * ks,
                    distribution,
                    fresnel: Fresnel::Dielectric {
                        eta_i: 1.0,
                        eta_t: ETA,
                    },
                });
            }
            if t != Vec3::ZERO {
                bsdf.add(MicrofacetTransmission {
                    t: t * ks,
                    distribution,
                    eta_a: 1.0,
                    eta_b: ETA,
                });
            }
        }
    }
}
