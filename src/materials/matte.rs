//! `matte`: diffuse reflection, Lambertian or Oren–Nayar.
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `Kd` | spectrum texture | 0.5 | reflectance |
//! | `sigma` | float texture | 0 | Oren–Nayar facet slope σ in degrees (0: Lambertian), clamped to [0, 90] |
//! | `bumpmap` | float texture | | displacement for bump mapping (every material: `bump.rs`) |

use super::{Material, MaterialKind, ShadingContext, Support};
use crate::bxdf::{Bsdf, LambertianReflection, OrenNayar};
use crate::scene::{FloatTex, ParamSpec, ParamValues, SpectrumTex};
use glam::Vec3;

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::spectrum("Kd", 0.5, "diffuse reflectance"),
    ParamSpec::nonneg_tex("sigma", 0.0, "Oren–Nayar σ in degrees (0: Lambertian)"),
    ParamSpec::BUMPMAP,
];

pub const KIND: MaterialKind = MaterialKind {
    name: "matte",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "diffuse reflection (Lambertian, or Oren–Nayar when sigma > 0)",
    build: |p| Material::Matte(Matte::new(p)),
};

#[derive(Clone, Debug)]
pub struct Matte {
    pub kd: SpectrumTex,
    pub sigma: FloatTex,
}

impl Matte {
    pub fn new(p: &ParamValues) -> Matte {
        Matte {
            kd: p.spectrum_tex("Kd").expect("default"),
            sigma: p.float_tex("sigma").expect("default"),
        }
    }

    pub fn needs_geom(&self) -> bool {
        self.kd.as_constant().is_none() || self.sigma.as_constant().is_none()
    }

    pub fn max_lobes(&self) -> usize {
        super::may_scatter(&self.kd) as usize
    }

    #[inline(always)]
    pub fn scatter(&self, sc: &ShadingContext, bsdf: &mut Bsdf) {
        let r = self.kd.eval(sc).max(Vec3::ZERO);
        let sigma = self.sigma.eval(sc).clamp(0.0, 90.0);
        if r != Vec3::ZERO {
            if sigma == 0.0 {
                bsdf.add(LambertianReflection { r });
            } else {
                bsdf.add(OrenNayar::new(r, sigma));
            }
        }
    }
}
