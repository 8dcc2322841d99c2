//! Materials and their BSDFs. A closed set, so an enum: matte (Lambertian or
//! Oren–Nayar), mirror, glass (one FresnelSpecular lobe, or separate specular
//! reflection and transmission lobes when the integrator asks for them, as
//! pbrt-v3's `allowMultipleLobes`), and "none" (no BSDF).

mod bxdf;

pub use bxdf::{fr_dielectric, refract, Bsdf, BsdfSample, LobeFilter, Lobes};

use crate::render::geometry::Frame;
use crate::scene::MaterialDesc;
use glam::Vec3;

/// A material ready to build BSDFs at hit points.
#[derive(Clone, Copy, Debug)]
pub enum Material {
    Matte {
        kd: Vec3,
        a: f32,
        b: f32,
        oren_nayar: bool,
    },
    Mirror {
        kr: Vec3,
    },
    Glass {
        kr: Vec3,
        kt: Vec3,
        eta: f32,
    },
    None,
}

impl Material {
    pub fn new(desc: &MaterialDesc) -> Material {
        let clamp = |c: Vec3| c.max(Vec3::ZERO);
        match *desc {
            MaterialDesc::Matte { kd, sigma } => {
                let s = sigma.clamp(0.0, 90.0).to_radians();
                let s2 = s * s;
                Material::Matte {
                    kd: clamp(kd),
                    a: 1.0 - s2 / (2.0 * (s2 + 0.33)),
                    b: 0.45 * s2 / (s2 + 0.09),
                    oren_nayar: sigma != 0.0,
                }
            }
            MaterialDesc::Mirror { kr } => Material::Mirror { kr: clamp(kr) },
            MaterialDesc::Glass { kr, kt, eta } => Material::Glass {
                kr: clamp(kr),
                kt: clamp(kt),
                eta,
            },
            MaterialDesc::None => Material::None,
        }
    }

    /// True for `Material "none"`: rays pass through without a bounce.
    pub fn is_none(&self) -> bool {
        matches!(self, Material::None)
    }

    /// The BSDF at a point with shading normal `ns` and geometric normal `ng`.
    /// `multiple_lobes`: glass becomes one FresnelSpecular lobe (path) rather
    /// than separate reflection and transmission (directlighting, whitted).
    #[inline]
    pub fn bsdf(&self, ns: Vec3, ng: Vec3, multiple_lobes: bool) -> Bsdf {
        let lobes = match *self {
            Material::Matte {
                kd,
                a,
                b,
                oren_nayar,
            } => {
                if kd == Vec3::ZERO {
                    Lobes::Empty
                } else if oren_nayar {
                    Lobes::OrenNayar { r: kd, a, b }
                } else {
                    Lobes::Lambertian { r: kd }
                }
            }
            Material::Mirror { kr } => {
                if kr == Vec3::ZERO {
                    Lobes::Empty
                } else {
                    Lobes::Mirror { r: kr }
                }
            }
            Material::Glass { kr, kt, eta } => {
                if kr == Vec3::ZERO && kt == Vec3::ZERO {
                    Lobes::Empty
                } else if multiple_lobes {
                    Lobes::FresnelSpecular { r: kr, t: kt, eta }
                } else {
                    Lobes::SplitGlass { r: kr, t: kt, eta }
                }
            }
            Material::None => Lobes::Empty,
        };
        let eta = match *self {
            Material::Glass { eta, .. } => eta,
            _ => 1.0,
        };
        Bsdf {
            frame: Frame::from_normal(ns),
            ng,
            lobes,
            eta,
        }
    }
}
