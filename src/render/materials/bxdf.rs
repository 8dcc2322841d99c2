use crate::render::geometry::Frame;
use crate::render::sampling::cosine_sample_hemisphere;
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

/// The lobes of a BSDF (pbrt-v3's BxDFs that pbrs has).
#[derive(Clone, Copy, Debug)]
pub enum Lobes {
    /// No lobes: a black surface (e.g. an emitter with Kd 0).
    Empty,
    Lambertian {
        r: Vec3,
    },
    OrenNayar {
        r: Vec3,
        a: f32,
        b: f32,
    },
    /// Specular reflection with no Fresnel term (pbrt's FresnelNoOp).
    Mirror {
        r: Vec3,
    },
    /// One lobe choosing reflection or transmission by the Fresnel term.
    FresnelSpecular {
        r: Vec3,
        t: Vec3,
        eta: f32,
    },
    /// SpecularReflection (dielectric Fresnel) + SpecularTransmission as two
    /// lobes; either is absent when its colour is black.
    SplitGlass {
        r: Vec3,
        t: Vec3,
        eta: f32,
    },
}

/// Which lobes a query may use (pbrt's BxDFType masks that pbrs needs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LobeFilter {
    All,
    NonSpecular,
    SpecularReflection,
    SpecularTransmission,
}

#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    /// BSDF value (not multiplied by the cosine).
    pub f: Vec3,
    pub wi: Vec3,
    pub pdf: f32,
    pub specular: bool,
    pub transmission: bool,
}

/// A BSDF at a surface point: lobes in the shading frame, plus the geometric
/// normal that decides reflection versus transmission, as in pbrt-v3.
#[derive(Clone, Copy, Debug)]
pub struct Bsdf {
    pub frame: Frame,
    pub ng: Vec3,
    pub lobes: Lobes,
    /// Relative index of refraction (1 for opaque materials).
    pub eta: f32,
}

#[inline]
fn cos_theta(w: Vec3) -> f32 {
    w.z
}

/// Fresnel reflectance of a dielectric interface (pbrt-v3's FrDielectric).
#[inline]
pub fn fr_dielectric(cos_theta_i: f32, eta_i: f32, eta_t: f32) -> f32 {
    let mut cos_i = cos_theta_i.clamp(-1.0, 1.0);
    let (mut ei, mut et) = (eta_i, eta_t);
    if cos_i <= 0.0 {
        std::mem::swap(&mut ei, &mut et);
        cos_i = cos_i.abs();
    }
    let sin_i = (1.0 - cos_i * cos_i).max(0.0).sqrt();
    let sin_t = ei / et * sin_i;
    if sin_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin_t * sin_t).max(0.0).sqrt();
    let r_parl = (et * cos_i - ei * cos_t) / (et * cos_i + ei * cos_t);
    let r_perp = (ei * cos_i - et * cos_t) / (ei * cos_i + et * cos_t);
    0.5 * (r_parl * r_parl + r_perp * r_perp)
}

/// Refraction of `wi` about `n` (same side as `wi`) with relative index
/// `eta` = η_i/η_t; None on total internal reflection.
#[inline]
pub fn refract(wi: Vec3, n: Vec3, eta: f32) -> Option<Vec3> {
    let cos_i = n.dot(wi);
    let sin2_i = (1.0 - cos_i * cos_i).max(0.0);
    let sin2_t = eta * eta * sin2_i;
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some(eta * -wi + (eta * cos_i - cos_t) * n)
}

/// Specular transmission through a smooth dielectric in local coordinates:
/// (wi, η_i, η_t), or None on total internal reflection.
#[inline]
fn transmit(wo: Vec3, eta: f32) -> Option<(Vec3, f32, f32)> {
    let entering = cos_theta(wo) > 0.0;
    let (ei, et) = if entering { (1.0, eta) } else { (eta, 1.0) };
    let n = if entering { Vec3::Z } else { -Vec3::Z };
    refract(wo, n, ei / et).map(|wi| (wi, ei, et))
}

impl Lobes {
    fn f_local(&self, wo: Vec3, wi: Vec3, reflect: bool) -> Vec3 {
        if !reflect {
            return Vec3::ZERO; // pbrs has no non-specular transmission
        }
        match *self {
            Lobes::Lambertian { r } => r * FRAC_1_PI,
            Lobes::OrenNayar { r, a, b } => {
                let sin_i = (1.0 - wi.z * wi.z).max(0.0).sqrt();
                let sin_o = (1.0 - wo.z * wo.z).max(0.0).sqrt();
                let mut max_cos = 0.0;
                if sin_i > 1e-4 && sin_o > 1e-4 {
                    let (ci, si) = (wi.x / sin_i, wi.y / sin_i);
                    let (co, so) = (wo.x / sin_o, wo.y / sin_o);
                    max_cos = (ci.clamp(-1.0, 1.0) * co.clamp(-1.0, 1.0)
                        + si.clamp(-1.0, 1.0) * so.clamp(-1.0, 1.0))
                    .max(0.0);
                }
                let (sin_alpha, tan_beta) = if wi.z.abs() > wo.z.abs() {
                    (sin_o, sin_i / wi.z.abs())
                } else {
                    (sin_i, sin_o / wo.z.abs())
                };
                r * FRAC_1_PI * (a + b * max_cos * sin_alpha * tan_beta)
            }
            _ => Vec3::ZERO,
        }
    }

    fn pdf_local(&self, wo: Vec3, wi: Vec3) -> f32 {
        match self {
            Lobes::Lambertian { .. } | Lobes::OrenNayar { .. } if wo.z * wi.z > 0.0 => {
                wi.z.abs() * FRAC_1_PI
            }
            _ => 0.0,
        }
    }
}

impl Bsdf {
    /// True if the BSDF has a lobe that light sampling can use.
    #[inline]
    pub fn has_non_specular(&self) -> bool {
        matches!(
            self.lobes,
            Lobes::Lambertian { .. } | Lobes::OrenNayar { .. }
        )
    }

    /// True if the BSDF has a specular lobe.
    #[inline]
    pub fn has_specular(&self) -> bool {
        matches!(
            self.lobes,
            Lobes::Mirror { .. } | Lobes::FresnelSpecular { .. } | Lobes::SplitGlass { .. }
        )
    }

    /// True if the BSDF has no lobes at all.
    #[inline]
    pub fn is_empty(&self) -> bool {
        matches!(self.lobes, Lobes::Empty)
    }

    /// Value for a pair of world directions (non-specular lobes only, since
    /// specular lobes are zero for any given pair).
    #[inline]
    pub fn f(&self, wo_w: Vec3, wi_w: Vec3) -> Vec3 {
        self.f_pdf(wo_w, wi_w).0
    }

    /// `(f(wo_w, wi_w), pdf(wo_w, wi_w))` in one pass (the local directions
    /// are computed once).
    #[inline]
    pub fn f_pdf(&self, wo_w: Vec3, wi_w: Vec3) -> (Vec3, f32) {
        let wo = self.frame.to_local(wo_w);
        if wo.z == 0.0 {
            return (Vec3::ZERO, 0.0);
        }
        let wi = self.frame.to_local(wi_w);
        let reflect = wi_w.dot(self.ng) * wo_w.dot(self.ng) > 0.0;
        (
            self.lobes.f_local(wo, wi, reflect),
            self.lobes.pdf_local(wo, wi),
        )
    }

    /// Density of `sample` with filter NonSpecular (= All for the
    /// non-specular part) producing `wi_w`, by solid angle.
    #[inline]
    pub fn pdf(&self, wo_w: Vec3, wi_w: Vec3) -> f32 {
        let wo = self.frame.to_local(wo_w);
        if wo.z == 0.0 {
            return 0.0;
        }
        self.lobes.pdf_local(wo, self.frame.to_local(wi_w))
    }

    /// Sample an incident direction (pbrt-v3's BSDF::Sample_f for pbrs's lobe
    /// sets). `u.x` chooses among matching lobes and is then remapped.
    pub fn sample(&self, wo_w: Vec3, u: Vec2, filter: LobeFilter) -> Option<BsdfSample> {
        let wo = self.frame.to_local(wo_w);
        if wo.z == 0.0 {
            return None;
        }
        let want_diffuse = matches!(filter, LobeFilter::All | LobeFilter::NonSpecular);
        let want_refl = matches!(filter, LobeFilter::All | LobeFilter::SpecularReflection);
        let want_trans = matches!(filter, LobeFilter::All | LobeFilter::SpecularTransmission);
        let local = match self.lobes {
            Lobes::Empty => return None,
            Lobes::Lambertian { .. } | Lobes::OrenNayar { .. } => {
                if !want_diffuse {
                    return None;
                }
                let mut wi = cosine_sample_hemisphere(u);
                if wo.z < 0.0 {
                    wi.z = -wi.z;
                }
                let pdf = self.lobes.pdf_local(wo, wi);
                if pdf == 0.0 {
                    return None;
                }
                let wi_w = self.frame.from_local(wi);
                let reflect = wi_w.dot(self.ng) * wo_w.dot(self.ng) > 0.0;
                return Some(BsdfSample {
                    f: self.lobes.f_local(wo, wi, reflect),
                    wi: wi_w,
                    pdf,
                    specular: false,
                    transmission: false,
                });
            }
            Lobes::Mirror { r } => {
                if !want_refl {
                    return None;
                }
                let wi = Vec3::new(-wo.x, -wo.y, wo.z);
                (r / wi.z.abs(), wi, 1.0, false)
            }
            Lobes::FresnelSpecular { r, t, eta } => {
                if filter != LobeFilter::All {
                    // The single lobe is both reflection and transmission.
                    return None;
                }
                let f = fr_dielectric(cos_theta(wo), 1.0, eta);
                if u.x < f {
                    let wi = Vec3::new(-wo.x, -wo.y, wo.z);
                    (f * r / wi.z.abs(), wi, f, false)
                } else {
                    let (wi, ei, et) = transmit(wo, eta)?;
                    let ft = t * (1.0 - f) * (ei * ei) / (et * et);
                    (ft / wi.z.abs(), wi, 1.0 - f, true)
                }
            }
            Lobes::SplitGlass { r, t, eta } => {
                let has_r = want_refl && r != Vec3::ZERO;
                let has_t = want_trans && t != Vec3::ZERO;
                let n = has_r as u32 + has_t as u32;
                if n == 0 {
                    return None;
                }
                // With both lobes, u.x picks one uniformly (pdf 1/2 each).
                let pick_t = if n == 2 { u.x >= 0.5 } else { has_t };
                let pdf = 1.0 / n as f32;
                if !pick_t {
                    let wi = Vec3::new(-wo.x, -wo.y, wo.z);
                    let fr = fr_dielectric(cos_theta(wi), 1.0, eta);
                    (fr * r / wi.z.abs(), wi, pdf, false)
                } else {
                    let (wi, ei, et) = transmit(wo, eta)?;
                    let ft =
                        t * (1.0 - fr_dielectric(cos_theta(wi), 1.0, eta)) * (ei * ei) / (et * et);
                    (ft / wi.z.abs(), wi, pdf, true)
                }
            }
        };
        let (f, wi, pdf, transmission) = local;
        if pdf == 0.0 || !f.is_finite() {
            return None;
        }
        Some(BsdfSample {
            f,
            wi: self.frame.from_local(wi),
            pdf,
            specular: true,
            transmission,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fresnel_at_normal_incidence_is_four_percent() {
        assert!((fr_dielectric(1.0, 1.0, 1.5) - 0.04).abs() < 1e-6);
        assert!((fr_dielectric(-1.0, 1.0, 1.5) - 0.04).abs() < 1e-6);
        // Total internal reflection from inside beyond the critical angle.
        assert_eq!(fr_dielectric(-0.2, 1.0, 1.5), 1.0);
        assert!(fr_dielectric(0.3, 1.0, 1.0).abs() < 1e-6);
    }

    #[test]
    fn refraction_obeys_snell() {
        let wo = Vec3::new(0.6, 0.0, 0.8);
        let wi = refract(wo, Vec3::Z, 1.0 / 1.5).unwrap();
        let sin_o = 0.6;
        let sin_i = (wi.x * wi.x + wi.y * wi.y).sqrt();
        assert!((sin_o - 1.5 * sin_i).abs() < 1e-6);
        assert!(wi.z < 0.0 && (wi.length() - 1.0).abs() < 1e-6);
    }
}
