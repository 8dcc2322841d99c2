//! The Henyey–Greenstein phase function, as pbrt-v3's `HenyeyGreenstein`
//! (core/medium.{h,cpp}).
//!
//! pbrt-v3's sign convention: both directions point away from the
//! scattering point (`wo` back along the incoming ray), and the phase
//! function is `PhaseHG(wo·wi, g)` with `1 + g² + 2g cosθ` in the
//! denominator, so `g > 0` scatters forward (`wi` close to `-wo`).
//!
//! Parameter (of the medium): `g` in (-1, 1), 0 is isotropic.

use crate::geometry::Frame;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

const INV_4PI: f32 = 1.0 / (4.0 * PI);

/// pbrt-v3's `PhaseHG(cosTheta, g)`: the density for `cos_theta = wo·wi`.
#[inline]
pub fn phase_hg(cos_theta: f32, g: f32) -> f32 {
    let denom = 1.0 + g * g + 2.0 * g * cos_theta;
    INV_4PI * (1.0 - g * g) / (denom * denom.max(0.0).sqrt())
}

/// A Henyey–Greenstein phase function with asymmetry `g`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HenyeyGreenstein {
    pub g: f32,
}

impl HenyeyGreenstein {
    /// The phase function's value (also its solid-angle density) for the
    /// pair of directions, both pointing away from the point.
    #[inline]
    pub fn p(&self, wo: Vec3, wi: Vec3) -> f32 {
        phase_hg(wo.dot(wi), self.g)
    }

    /// pbrt-v3's `Sample_p`: a direction `wi` with density `p(wo, wi)`
    /// (returned with it). `wo` must be unit length.
    #[inline]
    pub fn sample(&self, wo: Vec3, u: Vec2) -> (Vec3, f32) {
        let g = self.g;
        let cos_theta = if g.abs() < 1e-3 {
            1.0 - 2.0 * u.x
        } else {
            let sqr = (1.0 - g * g) / (1.0 + g - 2.0 * g * u.x);
            -(1.0 + g * g - sqr * sqr) / (2.0 * g)
        };
        let cos_theta = cos_theta.clamp(-1.0, 1.0);
        let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        let phi = 2.0 * PI * u.y;
        let frame = Frame::from_normal(wo);
        let local = Vec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta);
        (frame.from_local(local), phase_hg(cos_theta, g))
    }
}
