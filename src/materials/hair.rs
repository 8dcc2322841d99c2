//! `hair`: pbrt-v3's `HairMaterial`, the hair scattering model of
//! [`HairBsdf`] on `curve` shapes.
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `sigma_a` | spectrum texture | | absorption coefficient inside the hair (per unit of its radius) |
//! | `color` | spectrum texture | | the colour the hair should have: σ_a from pbrt-v3's `SigmaAFromReflectance` |
//! | `eumelanin` | float texture | | eumelanin concentration: σ_a from pbrt-v3's `SigmaAFromConcentration` |
//! | `pheomelanin` | float texture | | pheomelanin concentration, likewise |
//! | `eta` | float texture | 1.55 | index of refraction of the hair |
//! | `beta_m` | float texture | 0.3 | longitudinal roughness, in [0, 1] |
//! | `beta_n` | float texture | 0.3 | azimuthal roughness, in [0, 1] |
//! | `alpha` | float texture | 2 | tilt of the hair's scales, degrees |
//!
//! σ_a comes from the first of `sigma_a`, `color`, `eumelanin`/`pheomelanin`
//! that is given (the others are ignored with pbrt-v3's warnings); with
//! none, from a eumelanin concentration of 1.3 (brown hair). As pbrt-v3,
//! `alpha` is converted to radians twice (the material converts it and
//! the BSDF converts again), so the scales tilt by α·π²/180² radians.
//! `h`, where the ray meets the hair's width, is −1 + 2v of the curve's
//! (u, v); the BSDF's frame has x along the curve's dp/du. pbrt-v3 stops on
//! a β outside [0, 1]; pbrs clamps it.

use super::{Material, MaterialKind, ShadingContext, Support};
use crate::bxdf::hair::{sigma_a_from_concentration, sigma_a_from_reflectance};
use crate::bxdf::{Bsdf, HairBsdf};
use crate::scene::{FloatTex, ParamSpec, ParamValues, SpectrumTex};
use glam::Vec3;

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::spectrum_opt("sigma_a", "absorption coefficient inside the hair"),
    ParamSpec::spectrum_opt(
        "color",
        "the hair's colour: sigma_a from pbrt-v3's SigmaAFromReflectance (when sigma_a is absent)",
    ),
    ParamSpec::float_tex_opt(
        "eumelanin",
        "eumelanin concentration (when sigma_a and color are absent)",
    ),
    ParamSpec::float_tex_opt(
        "pheomelanin",
        "pheomelanin concentration (when sigma_a and color are absent)",
    ),
    ParamSpec::float_tex("eta", 1.55, "index of refraction"),
    ParamSpec::float_tex("beta_m", 0.3, "longitudinal roughness in [0, 1]"),
    ParamSpec::float_tex("beta_n", 0.3, "azimuthal roughness in [0, 1]"),
    ParamSpec::float_tex(
        "alpha",
        2.0,
        "tilt of the scales in degrees (converted to radians twice, as pbrt-v3)",
    ),
];

pub const KIND: MaterialKind = MaterialKind {
    name: "hair",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "pbrt-v3's hair scattering model (R, TT, TRT and the rest) for curves, absorption from sigma_a, color or melanin concentrations",
    build: |p| Material::Hair(Hair::new(p)),
};

/// Where the hair's absorption comes from.
#[derive(Clone, Debug)]
pub enum Absorption {
    SigmaA(SpectrumTex),
    Color(SpectrumTex),
    Melanin {
        eumelanin: Option<FloatTex>,
        pheomelanin: Option<FloatTex>,
    },
}

#[derive(Clone, Debug)]
pub struct Hair {
    pub absorption: Absorption,
    pub eta: FloatTex,
    pub beta_m: FloatTex,
    pub beta_n: FloatTex,
    pub alpha: FloatTex,
}

impl Hair {
    pub fn new(p: &ParamValues) -> Hair {
        let absorption = if let Some(s) = p.spectrum_tex("sigma_a") {
            Absorption::SigmaA(s)
        } else if let Some(c) = p.spectrum_tex("color") {
            Absorption::Color(c)
        } else if p.has("eumelanin") || p.has("pheomelanin") {
            Absorption::Melanin {
                eumelanin: p.float_tex("eumelanin"),
                pheomelanin: p.float_tex("pheomelanin"),
            }
        } else {
            Absorption::SigmaA(SpectrumTex::Constant(sigma_a_from_concentration(1.3, 0.0)))
        };
        Hair {
            absorption,
            eta: p.float_tex("eta").expect("default"),
            beta_m: p.float_tex("beta_m").expect("default"),
            beta_n: p.float_tex("beta_n").expect("default"),
            alpha: p.float_tex("alpha").expect("default"),
        }
    }

    /// pbrt-v3's warnings about the absorption parameters it ignores.
    pub fn load_warnings(p: &ParamValues) -> Vec<String> {
        let given = |n: &str| p.has(n);
        let ignored = |n: &str, since: &str| {
            format!("ignoring \"{n}\" parameter since \"{since}\" was provided (as pbrt-v3)")
        };
        let mut out = Vec::new();
        if given("sigma_a") {
            for n in ["color", "eumelanin", "pheomelanin"] {
                if given(n) {
                    out.push(ignored(n, "sigma_a"));
                }
            }
        } else if given("color") {
            for n in ["eumelanin", "pheomelanin"] {
                if given(n) {
                    out.push(ignored(n, "color"));
                }
            }
        }
        out
    }

    /// The hair's frame follows the curve's dp/du and `h` its v: both need
    /// the differential geometry.
    pub fn needs_geom(&self) -> bool {
        true
    }

    pub fn max_lobes(&self) -> usize {
        1
    }

    pub fn scatter(&self, sc: &ShadingContext, bsdf: &mut Bsdf) {
        let bm = self.beta_m.eval(sc).clamp(0.0, 1.0);
        let bn = self.beta_n.eval(sc).clamp(0.0, 1.0);
        let a = self.alpha.eval(sc).to_radians();
        let e = self.eta.eval(sc);
        bsdf.eta = e;
        let sigma_a = match &self.absorption {
            Absorption::SigmaA(s) => s.eval(sc).max(Vec3::ZERO),
            Absorption::Color(c) => sigma_a_from_reflectance(c.eval(sc).max(Vec3::ZERO), bn),
            Absorption::Melanin {
                eumelanin,
                pheomelanin,
            } => sigma_a_from_concentration(
                eumelanin.as_ref().map_or(0.0, |t| t.eval(sc)).max(0.0),
                pheomelanin.as_ref().map_or(0.0, |t| t.eval(sc)).max(0.0),
            ),
        };
        let h = (-1.0 + 2.0 * sc.geom.uv.y).clamp(-1.0, 1.0);
        bsdf.add(HairBsdf::new(h, e, sigma_a, bm, bn, a));
    }
}
