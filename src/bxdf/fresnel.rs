//! Fresnel reflectance: dielectric (pbrt-v3 `FrDielectric`), conductor
//! (`FrConductor`, per RGB channel), and the `Fresnel` choices lobes hold.

use super::DisneyFresnel;
use glam::Vec3;

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

/// Fresnel reflectance of a conductor (pbrt-v3's FrConductor): `eta` and
/// `k` are the conductor's index and absorption over the outside index.
#[inline]
pub fn fr_conductor(cos_theta_i: f32, eta_i: Vec3, eta_t: Vec3, k: Vec3) -> Vec3 {
    let cos_i = cos_theta_i.clamp(-1.0, 1.0);
    let eta = eta_t / eta_i;
    let eta_k = k / eta_i;
    let cos2 = cos_i * cos_i;
    let sin2 = 1.0 - cos2;
    let eta2 = eta * eta;
    let eta_k2 = eta_k * eta_k;
    let t0 = eta2 - eta_k2 - Vec3::splat(sin2);
    let a2_plus_b2 = (t0 * t0 + 4.0 * eta2 * eta_k2).max(Vec3::ZERO);
    let a2_plus_b2 = Vec3::new(
        a2_plus_b2.x.sqrt(),
        a2_plus_b2.y.sqrt(),
        a2_plus_b2.z.sqrt(),
    );
    let t1 = a2_plus_b2 + Vec3::splat(cos2);
    let a = (0.5 * (a2_plus_b2 + t0)).max(Vec3::ZERO);
    let a = Vec3::new(a.x.sqrt(), a.y.sqrt(), a.z.sqrt());
    let t2 = 2.0 * cos_i * a;
    let rs = (t1 - t2) / (t1 + t2);
    let t3 = cos2 * a2_plus_b2 + Vec3::splat(sin2 * sin2);
    let t4 = t2 * sin2;
    let rp = rs * (t3 - t4) / (t3 + t4);
    0.5 * (rp + rs)
}

/// The Fresnel term of a reflection lobe (pbrt-v3's `Fresnel` classes).
#[derive(Clone, Copy, Debug)]
pub enum Fresnel {
    /// Reflects everything (pbrt-v3's `FresnelNoOp`).
    NoOp,
    /// `FresnelDielectric(eta_i, eta_t)`.
    Dielectric { eta_i: f32, eta_t: f32 },
    /// `FresnelConductor(eta_i, eta_t, k)`.
    Conductor { eta_i: Vec3, eta_t: Vec3, k: Vec3 },
    /// The Disney material's specular Fresnel (`DisneyFresnel`).
    Disney(DisneyFresnel),
}

impl Fresnel {
    #[inline]
    pub fn evaluate(&self, cos_theta_i: f32) -> Vec3 {
        match *self {
            Fresnel::NoOp => Vec3::ONE,
            Fresnel::Dielectric { eta_i, eta_t } => {
                Vec3::splat(fr_dielectric(cos_theta_i, eta_i, eta_t))
            }
            Fresnel::Conductor { eta_i, eta_t, k } => {
                fr_conductor(cos_theta_i.abs(), eta_i, eta_t, k)
            }
            Fresnel::Disney(d) => d.evaluate(cos_theta_i),
        }
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
    fn conductor_at_normal_incidence() {
        // ((n-1)^2 + k^2) / ((n+1)^2 + k^2) at normal incidence.
        let (n, k) = (0.2f32, 3.9f32);
        let want = ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k);
        let got = fr_conductor(1.0, Vec3::ONE, Vec3::splat(n), Vec3::splat(k));
        assert!((got.x - want).abs() < 1e-5, "{got} vs {want}");
        // Grazing incidence reflects everything.
        let g = fr_conductor(0.0, Vec3::ONE, Vec3::splat(n), Vec3::splat(k));
        assert!((g.x - 1.0).abs() < 1e-5);
        // A conductor with k = 0 is a dielectric.
        let d = fr_conductor(0.6, Vec3::ONE, Vec3::splat(1.5), Vec3::ZERO);
        assert!((d.x - fr_dielectric(0.6, 1.0, 1.5)).abs() < 1e-5);
    }
}
