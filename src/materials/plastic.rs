//! `plastic`: a diffuse base under a glossy dielectric coat (pbrt-v3's
//! `PlasticMaterial`): a Lambertian lobe and a Trowbridge–Reitz microfacet
//! reflection with pbrt-v3's `FresnelDielectric(1.5, 1)` (η_i = 1.5, η_t = 1,
//! as pbrt-v3 has it: the coat reflects totally beyond 41.8° about the facet).
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `Kd` | spectrum texture | 0.25 | diffuse reflectance (clamped ≥ 0) |
//! | `Ks` | spectrum texture | 0.25 | glossy reflectance (clamped ≥ 0) |
//! | `roughness` | float texture | 0.1 | microfacet roughness (isotropic) |
//! | `remaproughness` | bool | true | roughness → α as pbrt-v3's `RoughnessToAlpha` |
//! | `bumpmap` | float texture | | displacement for bump mapping (every material: `bump.rs`) |
//!
//! Lobes: Lambertian if Kd ≠ 0, then the microfacet reflection if Ks ≠ 0.

use super::REMAP_ROUGHNESS;
use super::{trowbridge_reitz, Material, MaterialKind, ShadingContext, Support};
use crate::bxdf::{Bsdf, Fresnel, LambertianReflection, MicrofacetReflection};
use crate::scene::{FloatTex, ParamSpec, ParamValues, SpectrumTex};
use glam::Vec3;

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::spectrum("Kd", 0.25, "diffuse reflectance"),
    ParamSpec::spectrum("Ks", 0.25, "glossy reflectance"),
    ParamSpec::nonneg_tex("roughness", 0.1, "microfacet roughness"),
    REMAP_ROUGHNESS,
    ParamSpec::BUMPMAP,
];

pub const KIND: MaterialKind = MaterialKind {
    name: "plastic",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "diffuse base under a glossy dielectric coat",
    build: |p| Material::Plastic(Plastic::new(p)),
};

#[derive(Clone, Debug)]
pub struct Plastic {
    pub kd: SpectrumTex,
    pub ks: SpectrumTex,
    pub roughness: FloatTex,
    pub remap_roughness: bool,
}

impl Plastic {
    pub fn new(p: &ParamValues) -> Plastic {
        Plastic {
            kd: p.spectrum_tex("Kd").expect("default"),
            ks: p.spectrum_tex("Ks").expect("default"),
            roughness: p.float_tex("roughness").expect("default"),
            remap_roughness: p.boolean("remaproughness"),
        }
    }

    pub fn needs_geom(&self) -> bool {
        self.kd.as_constant().is_none()
            || self.ks.as_constant().is_none()
            || self.roughness.as_constant().is_none()
    }

    pub fn max_lobes(&self) -> usize {
        super::may_scatter(&self.kd) as usize + super::may_scatter(&self.ks) as usize
    }

    #[inline]
    pub fn scatter(&self, sc: &ShadingContext, bsdf: &mut Bsdf) {
        let kd = self.kd.eval(sc).max(Vec3::ZERO);
        if kd != Vec3::ZERO {
            bsdf.add(LambertianReflection { r: kd });
        }
        let ks = self.ks.eval(sc).max(Vec3::ZERO);
        if ks != Vec3::ZERO {
            let r = self.roughness.eval(sc);
            bsdf.add(MicrofacetReflection {
                r: ks,
                distribution: trowbridge_reitz(r, r, self.remap_roughness),
                fresnel: Fresnel::Dielectric {
                    eta_i: 1.5,
                    eta_t: 1.0,
                },
            });
        }
    }
}
