//! `substrate`: Ashikhmin–Shirley's diffuse base under a glossy layer
//! (pbrt-v3's `SubstrateMaterial`): one `FresnelBlend` lobe over a
//! Trowbridge–Reitz distribution, anisotropic when the two roughnesses
//! differ.
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `Kd` | spectrum texture | 0.5 | diffuse reflectance (clamped ≥ 0) |
//! | `Ks` | spectrum texture | 0.5 | glossy reflectance at normal incidence (clamped ≥ 0) |
//! | `uroughness` | float texture | 0.1 | roughness along dp/du |
//! | `vroughness` | float texture | 0.1 | roughness along dp/dv |
//! | `remaproughness` | bool | true | roughness → α as pbrt-v3's `RoughnessToAlpha` |
//! | `bumpmap` | float texture | | displacement for bump mapping (every material: `bump.rs`) |
//!
//! Lobes: the FresnelBlend if Kd or Ks ≠ 0.

use super::Roughness;
use super::REMAP_ROUGHNESS;
use super::{Material, MaterialKind, ShadingContext, Support};
use crate::bxdf::{Bsdf, FresnelBlend};
use crate::scene::{ParamSpec, ParamValues, SpectrumTex};
use glam::Vec3;

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::spectrum("Kd", 0.5, "diffuse reflectance"),
    ParamSpec::spectrum("Ks", 0.5, "glossy reflectance at normal incidence"),
    ParamSpec::nonneg_tex("uroughness", 0.1, "roughness along dp/du"),
    ParamSpec::nonneg_tex("vroughness", 0.1, "roughness along dp/dv"),
    REMAP_ROUGHNESS,
    ParamSpec::BUMPMAP,
];

pub const KIND: MaterialKind = MaterialKind {
    name: "substrate",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "Ashikhmin–Shirley diffuse base under a glossy layer",
    build: |p| Material::Substrate(Substrate::new(p)),
};

#[derive(Clone, Debug)]
pub struct Substrate {
    pub kd: SpectrumTex,
    pub ks: SpectrumTex,
    pub roughness: Roughness,
}

impl Substrate {
    pub fn new(p: &ParamValues) -> Substrate {
        Substrate {
            kd: p.spectrum_tex("Kd").expect("default"),
            ks: p.spectrum_tex("Ks").expect("default"),
            roughness: Roughness::read(p),
        }
    }

    pub fn anisotropic(&self) -> bool {
        self.roughness.anisotropic()
    }

    pub fn needs_geom(&self) -> bool {
        self.kd.as_constant().is_none()
            || self.ks.as_constant().is_none()
            || self.roughness.needs_geom()
    }

    pub fn max_lobes(&self) -> usize {
        (super::may_scatter(&self.kd) || super::may_scatter(&self.ks)) as usize
    }

    #[inline]
    pub fn scatter(&self, sc: &ShadingContext, bsdf: &mut Bsdf) {
        let rd = self.kd.eval(sc).max(Vec3::ZERO);
        let rs = self.ks.eval(sc).max(Vec3::ZERO);
        if rd == Vec3::ZERO && rs == Vec3::ZERO {
            return;
        }
        let (u, v) = self.roughness.eval(sc);
        bsdf.add(FresnelBlend {
            rd,
            rs,
            distribution: self.roughness.distribution((u, v)),
        });
    }
}
