//! `glass`: a dielectric interface, smooth (specular) or rough (microfacet,
//! Trowbridge–Reitz).
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `Kr` | spectrum texture | 1 | reflection scale |
//! | `Kt` | spectrum texture | 1 | transmission scale |
//! | `eta` | float texture | | index of refraction (pbrt-v3 reads `eta` first) |
//! | `index` | float texture | 1.5 | index of refraction when `eta` is absent |
//! | `uroughness`, `vroughness` | float texture | 0 | microfacet roughness along dp/du and dp/dv (0: smooth) |
//! | `remaproughness` | bool | true | map roughness to α as pbrt-v3's `RoughnessToAlpha` |
//! | `bumpmap` | float texture | | displacement for bump mapping (every material: `bump.rs`) |
//!
//! Smooth glass (both roughnesses 0) under the path tracer is one
//! FresnelSpecular lobe; under directlighting and whitted a specular
//! reflection and a specular transmission lobe (pbrt-v3's
//! `allowMultipleLobes`). Rough glass is a Trowbridge–Reitz microfacet
//! reflection with `FresnelDielectric(1, eta)` and a microfacet transmission
//! from 1 into `eta`, anisotropic when the roughnesses differ. Each
//! reflection or transmission lobe only if Kr or Kt is not black.

use super::Roughness;
use super::REMAP_ROUGHNESS;
use super::{BsdfContext, Material, MaterialKind, ShadingContext, Support};
use crate::bxdf::{
    Bsdf, Fresnel, FresnelSpecular, MicrofacetReflection, MicrofacetTransmission,
    SpecularReflection, SpecularTransmission,
};
use crate::scene::{FloatTex, ParamSpec, ParamValues, SpectrumTex};
use glam::Vec3;

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::spectrum("Kr", 1.0, "reflection scale"),
    ParamSpec::spectrum("Kt", 1.0, "transmission scale"),
    ParamSpec::float_tex_opt("eta", "index of refraction (read before `index`)"),
    ParamSpec::float_tex("index", 1.5, "index of refraction when `eta` is absent"),
    ParamSpec::nonneg_tex("uroughness", 0.0, "roughness along dp/du (0: smooth)"),
    ParamSpec::nonneg_tex("vroughness", 0.0, "roughness along dp/dv (0: smooth)"),
    REMAP_ROUGHNESS,
    ParamSpec::BUMPMAP,
];

pub const KIND: MaterialKind = MaterialKind {
    name: "glass",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "a dielectric interface, smooth or rough",
    build: |p| Material::Glass(Glass::new(p)),
};

#[derive(Clone, Debug)]
pub struct Glass {
    pub kr: SpectrumTex,
    pub kt: SpectrumTex,
    pub eta: FloatTex,
    pub roughness: Roughness,
}

impl Glass {
    pub fn new(p: &ParamValues) -> Glass {
        Glass {
            kr: p.spectrum_tex("Kr").expect("default"),
            kt: p.spectrum_tex("Kt").expect("default"),
            eta: p
                .float_tex("eta")
                .unwrap_or_else(|| p.float_tex("index").expect("default")),
            roughness: Roughness::read(p),
        }
    }

    /// The boundary of `subsurface` and `kdsubsurface`: `Kr`, `Kt` and the
    /// roughness parameters from `p`, a constant index `eta`.
    pub fn with_eta(p: &ParamValues, eta: f32) -> Glass {
        Glass {
            kr: p.spectrum_tex("Kr").expect("default"),
            kt: p.spectrum_tex("Kt").expect("default"),
            eta: FloatTex::Constant(eta),
            roughness: Roughness::read(p),
        }
    }

    pub fn anisotropic(&self) -> bool {
        self.roughness.anisotropic()
    }

    pub fn needs_geom(&self) -> bool {
        self.kr.as_constant().is_none()
            || self.kt.as_constant().is_none()
            || self.eta.as_constant().is_none()
            || self.roughness.needs_geom()
    }

    pub fn max_lobes(&self) -> usize {
        2
    }

    #[inline]
    pub fn scatter(&self, sc: &ShadingContext, ctx: &BsdfContext, bsdf: &mut Bsdf) {
        let eta = self.eta.eval(sc);
        bsdf.eta = eta;
        let r = self.kr.eval(sc).max(Vec3::ZERO);
        let t = self.kt.eval(sc).max(Vec3::ZERO);
        if r == Vec3::ZERO && t == Vec3::ZERO {
            return;
        }
        let (u, v) = self.roughness.eval(sc);
        let fresnel = Fresnel::Dielectric {
            eta_i: 1.0,
            eta_t: eta,
        };
        if u == 0.0 && v == 0.0 {
            if ctx.multiple_lobes {
                bsdf.add(FresnelSpecular {
                    r,
                    t,
                    eta_a: 1.0,
                    eta_b: eta,
                });
                return;
            }
            if r != Vec3::ZERO {
                bsdf.add(SpecularReflection { r, fresnel });
            }
            if t != Vec3::ZERO {
                bsdf.add(SpecularTransmission {
                    t,
                    eta_a: 1.0,
                    eta_b: eta,
                });
            }
            return;
        }
        let distribution = self.roughness.distribution((u, v));
        if r != Vec3::ZERO {
            bsdf.add(MicrofacetReflection {
                r,
                distribution,
                fresnel,
            });
        }
        if t != Vec3::ZERO {
            bsdf.add(MicrofacetTransmission {
                t,
                distribution,
                eta_a: 1.0,
                eta_b: eta,
            });
        }
    }
}
