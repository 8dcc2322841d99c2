//! `MakeNamedMedium "name" "string type" "homogeneous"`: pbrt-v3's
//! `HomogeneousMedium` (src/media/homogeneous.cpp), constant coefficients
//! everywhere.
//!
//! Parameters (read by `loader::medium` through [`KIND`]'s table):
//! - `spectrum sigma_a` absorption, per unit length; default pbrt-v3's
//!   (.0011, .0024, .014) (whole milk, mm⁻¹)
//! - `spectrum sigma_s` scattering; default (2.55, 3.21, 3.77)
//! - `string preset` a measured medium ([`super::presets`]) giving both
//! - `float scale` multiplies both (default 1)
//! - `float g` Henyey–Greenstein asymmetry (default 0)
//!
//! Transmittance `exp(-σt d)`; distances are sampled as pbrt-v3 does: a
//! channel chosen uniformly, an exponential step in its σt, and the
//! weight divided by the density averaged over the channels.

use super::{Coefficients, Density, Medium, MediumType, Support, COMMON};
use crate::geometry::Ray;
use crate::samplers::Sampler;
use glam::Vec3;

pub const KIND: MediumType = MediumType {
    name: "homogeneous",
    aliases: &[],
    support: Support::Supported,
    params: &[COMMON[0], COMMON[1], COMMON[2], COMMON[3], COMMON[4]],
    doc: "constant coefficients everywhere (pbrt-v3's HomogeneousMedium)",
    build: |p, input, r| {
        let what = format!("MakeNamedMedium \"{}\"", input.name);
        let c = Coefficients::read(p, &what, r);
        let density = Density::Homogeneous(Homogeneous::new(c.sigma_a, c.sigma_s));
        Some(Medium::new(input.name, c, density))
    },
};

#[derive(Clone, Debug)]
pub struct Homogeneous {
    pub sigma_s: Vec3,
    pub sigma_t: Vec3,
}

impl Homogeneous {
    pub fn new(sigma_a: Vec3, sigma_s: Vec3) -> Homogeneous {
        Homogeneous {
            sigma_s,
            sigma_t: sigma_a + sigma_s,
        }
    }

    /// Transmittance along `ray` from 0 to `ray.t_max`.
    #[inline]
    pub fn tr(&self, ray: &Ray) -> Vec3 {
        let d = (ray.t_max * ray.d.length()).min(f32::MAX);
        exp(-self.sigma_t * d)
    }

    /// pbrt-v3's `Sample`: the path weight and, if the ray scatters before
    /// `ray.t_max`, the ray parameter where it does.
    #[inline]
    pub fn sample(&self, ray: &Ray, sampler: &mut Sampler) -> (Vec3, Option<f32>) {
        let channel = ((sampler.get_1d() * 3.0) as usize).min(2);
        let u = sampler.get_1d();
        let len = ray.d.length();
        let dist = -(1.0 - u).ln() / self.sigma_t[channel];
        // f32::min ignores a NaN (0/0 for a channel with σt = 0).
        let t = (dist / len).min(ray.t_max);
        let sampled = t < ray.t_max;
        let tr = exp(-self.sigma_t * (t.min(f32::MAX) * len));
        let density = if sampled { self.sigma_t * tr } else { tr };
        let mut pdf = (density.x + density.y + density.z) / 3.0;
        if pdf == 0.0 {
            pdf = 1.0;
        }
        if sampled {
            (tr * self.sigma_s / pdf, Some(t))
        } else {
            (tr / pdf, None)
        }
    }
}

/// Per-channel exp, with 0·∞ (a channel of σt = 0 over an infinite
/// distance) taken as 0 optical depth.
#[inline]
fn exp(v: Vec3) -> Vec3 {
    let e = |x: f32| if x.is_nan() { 1.0 } else { x.exp() };
    Vec3::new(e(v.x), e(v.y), e(v.z))
}
