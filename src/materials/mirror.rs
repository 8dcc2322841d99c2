//! `mirror`: perfect specular reflection with no Fresnel term.
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `Kr` | spectrum texture | 0.9 | reflectance |
//! | `bumpmap` | float texture | | displacement for bump mapping (every material: `bump.rs`) |

use super::{Material, MaterialKind, ShadingContext, Support};
use crate::bxdf::{Bsdf, Fresnel, SpecularReflection};
use crate::scene::{ParamSpec, ParamValues, SpectrumTex};
use glam::Vec3;

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::spectrum("Kr", 0.9, "reflectance"),
    ParamSpec::BUMPMAP,
];

pub const KIND: MaterialKind = MaterialKind {
    name: "mirror",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "perfect specular reflection",
    build: |p| Material::Mirror(Mirror::new(p)),
};

#[derive(Clone, Debug)]
pub struct Mirror {
    pub kr: SpectrumTex,
}

impl Mirror {
    pub fn new(p: &ParamValues) -> Mirror {
        Mirror {
            kr: p.spectrum_tex("Kr").expect("default"),
        }
    }

    pub fn needs_geom(&self) -> bool {
        self.kr.as_constant().is_none()
    }

    pub fn max_lobes(&self) -> usize {
        super::may_scatter(&self.kr) as usize
    }

    #[inline]
    pub fn scatter(&self, sc: &ShadingContext, bsdf: &mut Bsdf) {
        let r = self.kr.eval(sc).max(Vec3::ZERO);
        if r != Vec3::ZERO {
            bsdf.add(SpecularReflection {
                r,
                fresnel: Fresnel::NoOp,
            });
        }
    }
}
