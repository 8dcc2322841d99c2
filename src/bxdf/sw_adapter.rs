//! pbrt-v3's `SeparableBSSRDFAdapter`: the lobe of the BSDF at a BSSRDF's
//! sampled exit point, `f(wo, wi) = Sw(wi)` (the normalised Fresnel
//! transmittance of the exit direction), times η² when radiance is
//! transported (pbrt-v3's `TransportMode::Radiance`, the only mode the path
//! tracers use), cosine-sampled as a diffuse reflection.
//!
//! Parameters: `eta`, the boundary's index; `radiance`, whether to apply
//! the η² of radiance transport.

use super::{BxdfFlags, BxdfModel};
use crate::bssrdf::tabulated::sw;
use glam::Vec3;

#[derive(Clone, Copy, Debug)]
pub struct SwAdapter {
    pub eta: f32,
    pub radiance: bool,
}

impl BxdfModel for SwAdapter {
    #[inline]
    fn flags(&self) -> BxdfFlags {
        BxdfFlags::REFLECTION | BxdfFlags::DIFFUSE
    }
    #[inline]
    fn f(&self, _wo: Vec3, wi: Vec3) -> Vec3 {
        let f = sw(self.eta, wi.z);
        Vec3::splat(if self.radiance {
            f * self.eta * self.eta
        } else {
            f
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radiance_transport_scales_sw_by_eta_squared() {
        let wi = Vec3::new(0.6, 0.0, 0.8);
        let a = SwAdapter {
            eta: 1.5,
            radiance: true,
        };
        let i = SwAdapter {
            eta: 1.5,
            radiance: false,
        };
        assert_eq!(i.f(Vec3::Z, wi), Vec3::splat(sw(1.5, 0.8)));
        assert!((a.f(Vec3::Z, wi).x - 2.25 * sw(1.5, 0.8)).abs() < 1e-6);
        // Cosine-sampled on wo's side, a diffuse reflection.
        assert_eq!(a.flags(), BxdfFlags::REFLECTION | BxdfFlags::DIFFUSE);
        assert!((a.pdf(Vec3::Z, wi) - 0.8 / std::f32::consts::PI).abs() < 1e-6);
    }
}
