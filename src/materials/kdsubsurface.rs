//! `kdsubsurface`: subsurface scattering specified by its diffuse
//! reflectance and mean free path (pbrt-v3's `KdSubsurfaceMaterial`); the
//! coefficients come from inverting the BSSRDF table's effective albedo
//! (`SubsurfaceFromDiffuse`).
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `Kd` | spectrum texture | 0.5 | effective (multiple-scattering) albedo, clamped to ≥ 0 (values beyond the table's range invert to its ends) |
//! | `mfp` | spectrum texture | 1 | mean free path 1/σt (scene units), times `scale` |
//! | `scale` | float | 1 | multiplies `mfp` |
//! | `g` | float | 0 | Henyey–Greenstein asymmetry of the table |
//! | `eta` | float | 1.33 | index of refraction of the boundary and of the table |
//! | `Kr` | spectrum texture | 1 | reflection scale of the boundary |
//! | `Kt` | spectrum texture | 1 | transmission scale of the boundary |
//! | `uroughness`, `vroughness` | float texture | 0 | microfacet roughness of the boundary (0: smooth) |
//! | `remaproughness` | bool | true | roughness → α as pbrt-v3's `RoughnessToAlpha` |
//! | `bumpmap` | float texture | | displacement for bump mapping (every material: `bump.rs`) |
//!
//! The boundary is `glass`'s BSDF with `eta`, as for `subsurface`.

use super::subsurface::{Boundary, BOUNDARY_PARAMS};
use super::{Material, MaterialKind, ShadingContext, Support};
use crate::bssrdf::subsurface_from_diffuse;
use crate::scene::{ParamSpec, ParamValues, SpectrumTex};
use glam::Vec3;
use std::sync::Arc;

const B: [ParamSpec; 7] = BOUNDARY_PARAMS;

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::spectrum("Kd", 0.5, "effective diffuse albedo"),
    ParamSpec::spectrum("mfp", 1.0, "mean free path (times scale)"),
    ParamSpec::float("scale", 1.0, "multiplies mfp"),
    ParamSpec::float("g", 0.0, "Henyey–Greenstein asymmetry"),
    B[0],
    B[1],
    B[2],
    B[3],
    B[4],
    B[5],
    B[6],
];

/// The entry of [`super::MATERIALS`].
pub const KIND: MaterialKind = MaterialKind {
    name: "kdsubsurface",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "subsurface scattering given by diffuse albedo and mean free path",
    build: |p| Material::KdSubsurface(Arc::new(KdSubsurface::new(p))),
};

#[derive(Clone, Debug)]
pub struct KdSubsurface {
    pub boundary: Boundary,
    pub kd: SpectrumTex,
    pub mfp: SpectrumTex,
}

impl KdSubsurface {
    pub fn new(p: &ParamValues) -> KdSubsurface {
        KdSubsurface {
            boundary: Boundary::new(p, p.float("g")),
            kd: p.spectrum_tex("Kd").expect("default"),
            mfp: p.spectrum_tex("mfp").expect("default"),
        }
    }

    pub fn needs_geom(&self) -> bool {
        self.boundary.glass.needs_geom()
            || self.kd.as_constant().is_none()
            || self.mfp.as_constant().is_none()
    }

    /// The medium's `(sigma_a, sigma_s)` at a hit: the albedo whose
    /// tabulated effective albedo is `Kd` (clamped to ≥ 0), over `scale · mfp`.
    #[inline]
    pub fn coefficients(&self, sc: &ShadingContext) -> (Vec3, Vec3) {
        let mfp = self.boundary.scale * self.mfp.eval(sc).max(Vec3::ZERO);
        let kd = self.kd.eval(sc).max(Vec3::ZERO);
        subsurface_from_diffuse(&self.boundary.table, kd, mfp)
    }
}
