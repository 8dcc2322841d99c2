//! pbrt-v3's `TabulatedBSSRDF` radial profile and the separable BSSRDF's
//! directional term (core/bssrdf.{h,cpp}): the profile `Sr` interpolated
//! from a [`BssrdfTable`] at the hit's albedo and scaled to its extinction,
//! sampling a radius per channel (`Sample_Sr`) and its density (`Pdf_Sr`),
//! and `Sw`, the normalised Fresnel transmittance of the exit direction.
//!
//! Parameters (per hit): `sigma_a`, `sigma_s` (RGB, ≥ 0, scene units⁻¹),
//! `eta` (the boundary's index), and the material's table (built for its
//! `g` and `eta`). A channel with σt = 0 has no profile (Sr 0, no sample).
//!
//! Nothing here allocates: a `TabulatedBssrdf` borrows the table and lives
//! on the stack of the integrator's bounce.

use super::table::{fresnel_moment1, BssrdfTable};
use crate::bxdf::fr_dielectric;
use crate::sampling::interpolation::{catmull_rom_weights, sample_catmull_rom_2d};
use glam::Vec3;
use std::f32::consts::PI;

/// The radial part of pbrt-v3's separable, tabulated BSSRDF at one hit.
#[derive(Clone, Copy, Debug)]
pub struct TabulatedBssrdf<'a> {
    pub table: &'a BssrdfTable,
    /// Extinction σa + σs per channel.
    pub sigma_t: Vec3,
    /// Single-scattering albedo σs / σt per channel (0 where σt is 0).
    pub rho: Vec3,
    /// Index of refraction of the boundary.
    pub eta: f32,
}

impl<'a> TabulatedBssrdf<'a> {
    pub fn new(table: &'a BssrdfTable, sigma_a: Vec3, sigma_s: Vec3, eta: f32) -> Self {
        let sigma_t = sigma_a + sigma_s;
        let mut rho = Vec3::ZERO;
        for c in 0..3 {
            if sigma_t[c] != 0.0 {
                rho[c] = sigma_s[c] / sigma_t[c];
            }
        }
        TabulatedBssrdf {
            table,
            sigma_t,
            rho,
            eta,
        }
    }

    /// Tensor-spline interpolation of the table at albedo `rho` and optical
    /// radius `r_optical`: (`2π r S`, effective albedo); `None` outside the
    /// table.
    #[inline]
    fn interpolate(&self, rho: f32, r_optical: f32) -> Option<(f32, f32)> {
        let t = self.table;
        let (rho_off, rho_w) = catmull_rom_weights(&t.rho_samples, rho)?;
        let (r_off, r_w) = catmull_rom_weights(&t.radius_samples, r_optical)?;
        let (mut sr, mut rho_eff) = (0.0f32, 0.0f32);
        for (i, &wi) in rho_w.iter().enumerate() {
            if wi == 0.0 {
                continue;
            }
            let ri = (rho_off + i as isize) as usize;
            rho_eff += t.rho_eff[ri] * wi;
            for (j, &wj) in r_w.iter().enumerate() {
                if wj != 0.0 {
                    sr += wi * wj * t.eval_profile(ri, (r_off + j as isize) as usize);
                }
            }
        }
        Some((sr, rho_eff))
    }

    /// pbrt-v3's `TabulatedBSSRDF::Sr`: the radial profile at distance `r`
    /// (scene units), per channel, clamped to ≥ 0.
    pub fn sr(&self, r: f32) -> Vec3 {
        let mut out = Vec3::ZERO;
        for c in 0..3 {
            let r_optical = r * self.sigma_t[c];
            let Some((mut sr, _)) = self.interpolate(self.rho[c], r_optical) else {
                continue;
            };
            // Cancel the 2π r of the tabulated density.
            if r_optical != 0.0 {
                sr /= 2.0 * PI * r_optical;
            }
            out[c] = sr * self.sigma_t[c] * self.sigma_t[c];
        }
        out.max(Vec3::ZERO)
    }

    /// pbrt-v3's `Sample_Sr`: a radius (scene units) for channel `ch` from
    /// the tabulated profile; `None` where σt is 0 (pbrt-v3 returns −1).
    pub fn sample_sr(&self, ch: usize, u: f32) -> Option<f32> {
        if self.sigma_t[ch] == 0.0 {
            return None;
        }
        let t = self.table;
        let s = sample_catmull_rom_2d(
            &t.rho_samples,
            &t.radius_samples,
            &t.profile,
            &t.profile_cdf,
            self.rho[ch],
            u,
        )?;
        Some(s.x / self.sigma_t[ch])
    }

    /// pbrt-v3's `Pdf_Sr`: the planar density (per unit area, scene units)
    /// of [`Self::sample_sr`] with a uniform angle, at radius `r`.
    pub fn pdf_sr(&self, ch: usize, r: f32) -> f32 {
        let r_optical = r * self.sigma_t[ch];
        let Some((mut sr, rho_eff)) = self.interpolate(self.rho[ch], r_optical) else {
            return 0.0;
        };
        if r_optical != 0.0 {
            sr /= 2.0 * PI * r_optical;
        }
        let pdf = sr * self.sigma_t[ch] * self.sigma_t[ch] / rho_eff;
        // rho_eff is 0 at albedo 0 (NaN then): no density.
        if pdf.is_finite() {
            pdf.max(0.0)
        } else {
            0.0
        }
    }

    /// pbrt-v3's `SeparableBSSRDF::Sw`: the directional factor of the exit
    /// direction `cos_theta` (to the shading normal), normalised so that
    /// its cosine-weighted hemispherical integral is 1.
    #[inline]
    pub fn sw(&self, cos_theta: f32) -> f32 {
        sw(self.eta, cos_theta)
    }
}

/// `Sw` for a boundary of index `eta` (see [`TabulatedBssrdf::sw`]).
#[inline]
pub fn sw(eta: f32, cos_theta: f32) -> f32 {
    let c = 1.0 - 2.0 * fresnel_moment1(1.0 / eta);
    (1.0 - fr_dielectric(cos_theta, 1.0, eta)) / (c * PI)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::OnceLock;

    fn table() -> &'static BssrdfTable {
        static T: OnceLock<BssrdfTable> = OnceLock::new();
        T.get_or_init(|| BssrdfTable::beam_diffusion(0.0, 1.33))
    }

    /// ∫₀^rmax f(r) 2πr dr by the midpoint rule on a log grid.
    fn planar(f: impl Fn(f32) -> f64, r_min: f64, r_max: f64) -> f64 {
        let n = 40_000;
        let (a, b) = (r_min.ln(), r_max.ln());
        let h = (b - a) / n as f64;
        (0..n)
            .map(|k| {
                let r = (a + (k as f64 + 0.5) * h).exp();
                f(r as f32) * 2.0 * std::f64::consts::PI * r * r * h
            })
            .sum()
    }

    #[test]
    fn pdf_sr_integrates_to_one_and_sr_to_rho_eff() {
        let t = table();
        let b = TabulatedBssrdf::new(t, Vec3::new(0.01, 0.5, 2.0), Vec3::new(1.0, 2.0, 2.0), 1.33);
        let r_max_opt = *t.radius_samples.last().unwrap() as f64;
        for ch in 0..3 {
            let st = b.sigma_t[ch] as f64;
            let total = planar(|r| b.pdf_sr(ch, r) as f64, 1e-6 / st, r_max_opt / st);
            assert!((total - 1.0).abs() < 0.01, "ch {ch}: {total}");
            let sr = planar(|r| b.sr(r)[ch] as f64, 1e-6 / st, r_max_opt / st);
            let (_, rho_eff) = b.interpolate(b.rho[ch], 0.0).unwrap();
            assert!(
                (sr - rho_eff as f64).abs() < 0.01 * rho_eff as f64,
                "ch {ch}: {sr} vs {rho_eff}"
            );
        }
    }

    #[test]
    fn sample_sr_follows_pdf_sr() {
        let t = table();
        let b = TabulatedBssrdf::new(t, Vec3::splat(0.05), Vec3::splat(0.95), 1.33);
        let n = 20_000;
        let radii = [0.05f32, 0.3, 1.0, 3.0, 10.0];
        let mut below = [0usize; 5];
        for k in 0..n {
            let r = b.sample_sr(0, (k as f32 + 0.5) / n as f32).unwrap();
            assert!(r >= 0.0 && r.is_finite());
            for (i, &rr) in radii.iter().enumerate() {
                if r < rr {
                    below[i] += 1;
                }
            }
        }
        for (i, &rr) in radii.iter().enumerate() {
            let want = planar(|r| b.pdf_sr(0, r) as f64, 1e-7, rr as f64);
            let got = below[i] as f64 / n as f64;
            assert!((got - want).abs() < 0.01, "P(r < {rr}): {got} vs {want}");
        }
        // No extinction: no profile, no sample.
        let none = TabulatedBssrdf::new(t, Vec3::ZERO, Vec3::ZERO, 1.33);
        assert_eq!(none.sample_sr(1, 0.5), None);
        assert_eq!(none.sr(0.1), Vec3::ZERO);
        assert_eq!(none.pdf_sr(1, 0.1), 0.0);
    }

    #[test]
    fn sw_is_normalised() {
        let t = table();
        for &eta in &[1.33f32, 1.5] {
            let b = TabulatedBssrdf::new(t, Vec3::ONE, Vec3::ONE, eta);
            // ∫ Sw(ω) cosθ dω over the hemisphere.
            let n = 100_000;
            let total: f64 = (0..n)
                .map(|k| {
                    let mu = (k as f64 + 0.5) / n as f64;
                    b.sw(mu as f32) as f64 * mu * 2.0 * std::f64::consts::PI / n as f64
                })
                .sum();
            assert!((total - 1.0).abs() < 0.02, "{eta}: {total}");
        }
    }
}
