//! `metal`: a rough conductor (pbrt-v3's `MetalMaterial`): one
//! Trowbridge–Reitz microfacet reflection with `FresnelConductor(1, eta, k)`
//! and reflectance 1, anisotropic when the two roughnesses differ.
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `eta` | spectrum texture | copper (measured, below) | index of refraction (not clamped) |
//! | `k` | spectrum texture | copper (measured, below) | absorption coefficient (not clamped) |
//! | `roughness` | float texture | 0.01 | roughness when `uroughness`/`vroughness` are absent |
//! | `uroughness` | float texture | `roughness` | roughness along dp/du |
//! | `vroughness` | float texture | `roughness` | roughness along dp/dv |
//! | `remaproughness` | bool | true | roughness → α as pbrt-v3's `RoughnessToAlpha` |
//! | `bumpmap` | float texture | | displacement for bump mapping (every material: `bump.rs`) |
//!
//! The default η and k are pbrt-v3's measured copper, converted to RGB by the
//! loader as pbrt-v3's `RGBSpectrum::FromSampled` does.

use super::Roughness;
use super::REMAP_ROUGHNESS;
use super::{Material, MaterialKind, ShadingContext, Support};
use crate::bxdf::{Bsdf, Fresnel, MicrofacetReflection};
use crate::scene::{ParamSpec, ParamValues, SpectrumDefault, SpectrumTex};
use glam::Vec3;

// Measured copper, 56 samples: wavelengths (nm), index of refraction n and
// absorption k. Data copied from pbrt-v3 @13d871f, src/materials/metal.cpp
// (CopperWavelengths, CopperN, CopperK), digits as printed there.
#[allow(clippy::excessive_precision)]
const COPPER_WAVELENGTHS: [f32; 56] = [
    298.7570554,
    302.4004341,
    306.1337728,
    309.960445,
    313.8839949,
    317.9081487,
    322.036826,
    326.2741526,
    330.6244747,
    335.092373,
    339.6826795,
    344.4004944,
    349.2512056,
    354.2405086,
    359.374429,
    364.6593471,
    370.1020239,
    375.7096303,
    381.4897785,
    387.4505563,
    393.6005651,
    399.9489613,
    406.5055016,
    413.2805933,
    420.2853492,
    427.5316483,
    435.0322035,
    442.8006357,
    450.8515564,
    459.2006593,
    467.8648226,
    476.8622231,
    486.2124627,
    495.936712,
    506.0578694,
    516.6007417,
    527.5922468,
    539.0616435,
    551.0407911,
    563.5644455,
    576.6705953,
    590.4008476,
    604.8008683,
    619.92089,
    635.8162974,
    652.5483053,
    670.1847459,
    688.8009889,
    708.4810171,
    729.3186941,
    751.4192606,
    774.9011125,
    799.8979226,
    826.5611867,
    855.0632966,
    885.6012714,
];

const COPPER_N: [f32; 56] = [
    1.400313, 1.38, 1.358438, 1.34, 1.329063, 1.325, 1.3325, 1.34, 1.334375, 1.325, 1.317812, 1.31,
    1.300313, 1.29, 1.281563, 1.27, 1.249062, 1.225, 1.2, 1.18, 1.174375, 1.175, 1.1775, 1.18,
    1.178125, 1.175, 1.172812, 1.17, 1.165312, 1.16, 1.155312, 1.15, 1.142812, 1.135, 1.131562,
    1.12, 1.092437, 1.04, 0.950375, 0.826, 0.645875, 0.468, 0.35125, 0.272, 0.230813, 0.214,
    0.20925, 0.213, 0.21625, 0.223, 0.2365, 0.25, 0.254188, 0.26, 0.28, 0.3,
];

const COPPER_K: [f32; 56] = [
    1.662125, 1.687, 1.703313, 1.72, 1.744563, 1.77, 1.791625, 1.81, 1.822125, 1.834, 1.85175,
    1.872, 1.89425, 1.916, 1.931688, 1.95, 1.972438, 2.015, 2.121562, 2.21, 2.177188, 2.13,
    2.160063, 2.21, 2.249938, 2.289, 2.326, 2.362, 2.397625, 2.433, 2.469187, 2.504, 2.535875,
    2.564, 2.589625, 2.605, 2.595562, 2.583, 2.5765, 2.599, 2.678062, 2.809, 3.01075, 3.24,
    3.458187, 3.67, 3.863125, 4.05, 4.239563, 4.43, 4.619563, 4.817, 5.034125, 5.26, 5.485625,
    5.717,
];

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::spectrum_with(
        "eta",
        SpectrumDefault::Sampled {
            lambda: &COPPER_WAVELENGTHS,
            values: &COPPER_N,
        },
        "index of refraction (default: measured copper)",
    ),
    ParamSpec::spectrum_with(
        "k",
        SpectrumDefault::Sampled {
            lambda: &COPPER_WAVELENGTHS,
            values: &COPPER_K,
        },
        "absorption coefficient (default: measured copper)",
    ),
    ParamSpec::nonneg_tex(
        "roughness",
        0.01,
        "roughness when uroughness/vroughness are absent",
    ),
    ParamSpec::nonneg_tex_opt("uroughness", "roughness along dp/du (default: roughness)"),
    ParamSpec::nonneg_tex_opt("vroughness", "roughness along dp/dv (default: roughness)"),
    REMAP_ROUGHNESS,
    ParamSpec::BUMPMAP,
];

pub const KIND: MaterialKind = MaterialKind {
    name: "metal",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "a rough conductor (default: copper)",
    build: |p| Material::Metal(Metal::new(p)),
};

#[derive(Clone, Debug)]
pub struct Metal {
    pub eta: SpectrumTex,
    pub k: SpectrumTex,
    pub roughness: Roughness,
}

impl Metal {
    pub fn new(p: &ParamValues) -> Metal {
        let roughness = p.float_tex("roughness").expect("default");
        Metal {
            eta: p.spectrum_tex("eta").expect("default"),
            k: p.spectrum_tex("k").expect("default"),
            roughness: Roughness {
                u: p.float_tex("uroughness").unwrap_or(roughness.clone()),
                v: p.float_tex("vroughness").unwrap_or(roughness),
                remap: p.boolean("remaproughness"),
            },
        }
    }

    pub fn anisotropic(&self) -> bool {
        self.roughness.anisotropic()
    }

    pub fn needs_geom(&self) -> bool {
        self.eta.as_constant().is_none()
            || self.k.as_constant().is_none()
            || self.roughness.needs_geom()
    }

    pub fn max_lobes(&self) -> usize {
        1
    }

    #[inline]
    pub fn scatter(&self, sc: &ShadingContext, bsdf: &mut Bsdf) {
        let (u, v) = self.roughness.eval(sc);
        bsdf.add(MicrofacetReflection {
            r: Vec3::ONE,
            distribution: self.roughness.distribution((u, v)),
            fresnel: Fresnel::Conductor {
                eta_i: Vec3::ONE,
                eta_t: self.eta.eval(sc),
                k: self.k.eval(sc),
            },
        });
    }
}
