//! `subsurface`: a dielectric boundary over a homogeneous scattering medium,
//! rendered with pbrt-v3's tabulated (photon beam diffusion) BSSRDF.
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `name` | string | "" | a measured medium of pbrt-v3's table (`render/media/presets.rs`): sets `sigma_a` and (its reduced) `sigma_s`, and forces `g` to 0 |
//! | `sigma_a` | spectrum texture | (.0011, .0024, .014) or the preset's | absorption coefficient (mm⁻¹ for the presets), clamped to ≥ 0 |
//! | `sigma_s` | spectrum texture | (2.55, 3.21, 3.77) or the preset's | scattering coefficient, clamped to ≥ 0 |
//! | `scale` | float | 1 | multiplies both coefficients (scene units per mm for the presets) |
//! | `g` | float | 0 | Henyey–Greenstein asymmetry of the medium (ignored with `name`) |
//! | `eta` | float | 1.33 | index of refraction of the boundary and of the table |
//! | `Kr` | spectrum texture | 1 | reflection scale of the boundary |
//! | `Kt` | spectrum texture | 1 | transmission scale of the boundary |
//! | `uroughness`, `vroughness` | float texture | 0 | microfacet roughness of the boundary (0: smooth) |
//! | `remaproughness` | bool | true | roughness → α as pbrt-v3's `RoughnessToAlpha` |
//! | `bumpmap` | float texture | | displacement for bump mapping (every material: `bump.rs`) |
//!
//! pbrt-v3 (materials/subsurface.cpp) reads no `mfp` for this material
//! (only `kdsubsurface` does); neither does pbrs. An unknown `name` keeps
//! the default coefficients and `g` (pbrt-v3 warns the same;
//! [`Subsurface::load_warnings`]).
//!
//! The boundary is the BSDF of `glass` with `eta` (one FresnelSpecular lobe
//! under the path tracers, else specular or microfacet reflection and
//! transmission). The BSSRDF under it is built per hit from
//! [`Subsurface::coefficients`] and the table (computed once per material,
//! for its `g` and `eta`).

use super::REMAP_ROUGHNESS;
use super::{BsdfContext, Glass, Material, MaterialKind, ShadingContext, Support};
use crate::bssrdf::{BssrdfTable, TabulatedBssrdf};
use crate::bxdf::Bsdf;
use crate::media::presets;
use crate::scene::{ParamSpec, ParamValues, SpectrumTex};
use glam::Vec3;
use std::sync::Arc;

/// pbrt-v3's default coefficients (`CreateSubsurfaceMaterial`).
pub const DEFAULT_SIGMA_A: [f32; 3] = [0.0011, 0.0024, 0.014];
pub const DEFAULT_SIGMA_S: [f32; 3] = [2.55, 3.21, 3.77];

const B: [ParamSpec; 7] = BOUNDARY_PARAMS;

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::string(
        "name",
        "",
        "measured medium (pbrt-v3's table): sets sigma_a, sigma_s, g = 0",
    ),
    ParamSpec::spectrum_opt(
        "sigma_a",
        "absorption coefficient (default (.0011, .0024, .014))",
    ),
    ParamSpec::spectrum_opt(
        "sigma_s",
        "scattering coefficient (default (2.55, 3.21, 3.77))",
    ),
    ParamSpec::float("scale", 1.0, "multiplies sigma_a and sigma_s"),
    ParamSpec::float("g", 0.0, "Henyey–Greenstein asymmetry (0 with a name)"),
    B[0],
    B[1],
    B[2],
    B[3],
    B[4],
    B[5],
    B[6],
];

/// The parameters of the dielectric boundary both subsurface materials
/// read ([`Boundary`]), after their own.
pub const BOUNDARY_PARAMS: [ParamSpec; 7] = [
    ParamSpec::float("eta", 1.33, "index of refraction"),
    ParamSpec::spectrum("Kr", 1.0, "reflection scale"),
    ParamSpec::spectrum("Kt", 1.0, "transmission scale"),
    ParamSpec::nonneg_tex("uroughness", 0.0, "roughness along dp/du (0: smooth)"),
    ParamSpec::nonneg_tex("vroughness", 0.0, "roughness along dp/dv (0: smooth)"),
    REMAP_ROUGHNESS,
    ParamSpec::BUMPMAP,
];

/// The entry of [`super::MATERIALS`].
pub const KIND: MaterialKind = MaterialKind {
    name: "subsurface",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "a dielectric boundary over a scattering medium (tabulated BSSRDF)",
    build: |p| Material::Subsurface(Arc::new(Subsurface::new(p))),
};

/// What `subsurface` and `kdsubsurface` share besides their coefficients:
/// the dielectric boundary (`Kr`, `Kt`, `eta`, roughness: `glass`'s BSDF)
/// and the medium's `scale`, asymmetry, index and photon-beam-diffusion
/// table (computed once per material, for its `g` and `eta`).
#[derive(Clone, Debug)]
pub struct Boundary {
    pub glass: Glass,
    pub scale: f32,
    pub g: f32,
    pub eta: f32,
    pub table: Arc<BssrdfTable>,
}

impl Boundary {
    pub fn new(p: &ParamValues, g: f32) -> Boundary {
        let eta = p.float("eta");
        Boundary {
            glass: Glass::with_eta(p, eta),
            scale: p.float("scale"),
            g,
            eta,
            table: BssrdfTable::shared(g, eta),
        }
    }

    pub fn anisotropic(&self) -> bool {
        self.glass.anisotropic()
    }

    pub fn max_lobes(&self) -> usize {
        self.glass.max_lobes()
    }

    #[inline]
    pub fn scatter(&self, sc: &ShadingContext, ctx: &BsdfContext, bsdf: &mut Bsdf) {
        self.glass.scatter(sc, ctx, bsdf);
    }

    /// The BSSRDF under the boundary for the medium's coefficients at a hit.
    pub fn bssrdf(&self, (sigma_a, sigma_s): (Vec3, Vec3)) -> TabulatedBssrdf<'_> {
        TabulatedBssrdf::new(&self.table, sigma_a, sigma_s, self.eta)
    }
}

#[derive(Clone, Debug)]
pub struct Subsurface {
    pub boundary: Boundary,
    pub sigma_a: SpectrumTex,
    pub sigma_s: SpectrumTex,
}

impl Subsurface {
    pub fn new(p: &ParamValues) -> Subsurface {
        let preset = presets::measured(p.string("name"));
        let (sa, ss, g) = match preset {
            Some(m) => (m.sigma_a, m.sigma_prime_s, 0.0),
            None => (DEFAULT_SIGMA_A, DEFAULT_SIGMA_S, p.float("g")),
        };
        Subsurface {
            boundary: Boundary::new(p, g),
            sigma_a: p
                .spectrum_tex("sigma_a")
                .unwrap_or(SpectrumTex::Constant(Vec3::from(sa))),
            sigma_s: p
                .spectrum_tex("sigma_s")
                .unwrap_or(SpectrumTex::Constant(Vec3::from(ss))),
        }
    }

    /// What the loader says about the values (each a located warning).
    pub fn load_warnings(p: &ParamValues) -> Vec<String> {
        let name = p.string("name");
        let mut out = Vec::new();
        if !name.is_empty() && presets::measured(name).is_none() {
            out.push(format!(
                "unknown medium name \"{name}\": pbrt-v3's default coefficients are used (as pbrt-v3)"
            ));
        }
        out
    }

    pub fn needs_geom(&self) -> bool {
        self.boundary.glass.needs_geom()
            || self.sigma_a.as_constant().is_none()
            || self.sigma_s.as_constant().is_none()
    }

    /// The medium's `(sigma_a, sigma_s)` at a hit (scaled, clamped to ≥ 0).
    #[inline]
    pub fn coefficients(&self, sc: &ShadingContext) -> (Vec3, Vec3) {
        let scale = self.boundary.scale;
        (
            scale * self.sigma_a.eval(sc).max(Vec3::ZERO),
            scale * self.sigma_s.eval(sc).max(Vec3::ZERO),
        )
    }
}
