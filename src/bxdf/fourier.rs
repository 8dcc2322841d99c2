//! `FourierBsdf`: a tabulated isotropic BSDF in pbrt-v3's Fourier
//! representation (pbrt-v3's `FourierBSDF`, from Jakob et al. 2014, "A
//! Comprehensive Framework for Rendering Layered Materials").
//!
//! The table stores, for pairs of zenith cosines (μi, μo) on a node grid, the
//! coefficients of a cosine series in the azimuth difference φ of
//! `f·|μi|`. A query interpolates the coefficients of the 4×4 nearest pairs
//! with Catmull-Rom weights in μi and μo, sums the series (in f64) and
//! divides by |μi|; in the table's convention μi is the cosine of `-wi`, so
//! reflection is μi·μo < 0 and transmission μi·μo > 0. Transmitted values
//! get the η² factor of radiance transport (pbrs traces radiance only:
//! pbrt-v3's `TransportMode::Radiance`). Three-channel tables hold luminance,
//! red and blue; green follows from them. Sampling picks μi from the
//! luminance a0 terms' spline (`sample_catmull_rom_2d`) and φ from the
//! luminance series (`sample_fourier`); `pdf` is the luminance series over
//! its integral. One lobe, reflection | transmission | glossy, as pbrt-v3.
//!
//! The density is normalised by the file's CDF rows, as pbrt-v3 does, not
//! by the integral of the coefficients: where a file's two disagree (the
//! collection's rough glass, within about 16° of the normal above the
//! surface, by up to 1.6×), `pdf` and `sample_f`'s density agree with each
//! other and with pbrt-v3 but not with where the samples go.
//!
//! The lobe holds a plain reference to its table. A table is megabytes,
//! owned by the material (an `Arc` shared between the materials that read
//! the same file), and the lobe is `Copy` and built per hit, so the reference
//! is what it can carry for free: this is why `Bxdf` and `Bsdf` have a
//! lifetime, the material's. An index into a scene-owned table list would
//! need that list at every `f`/`pdf`/`sample_f` call, which the lobe
//! interface does not take (and a BSDF is evaluated far from where the
//! material context is); an `Arc` clone per hit would put an atomic
//! increment on a shared cache line in every shading call.
//!
//! No allocation: the interpolated coefficients go into fixed arrays of
//! [`MAX_FOURIER_ORDER`] per channel on the stack, which the loader bounds
//! the table's order by; they are not zero-filled, only written up to the
//! order in use.
//!
//! For `wo` exactly along the normal, pbrt-v3's sampler has no azimuth to
//! rotate from and returns every `wi` on the axis (with the density of the
//! sampled μi, φ); pbrs does the same (a set of measure zero).
//!
//! pbrt-v3's `FourierBSDF::Sample_f` uses the sampled luminance unclamped,
//! but its `BSDF::Sample_f` then replaces a non-specular sample's value by
//! `f(wo, wi)`, which clamps it at zero; clamping here gives that value
//! without a second interpolation (equal up to rounding: `f` recomputes
//! cos φ from the normalised `wi`).

use super::{sin2_theta, BxdfFlags, BxdfModel, BxdfSample};
use crate::sampling::interpolation::{
    catmull_rom_weights, fourier, sample_catmull_rom_2d, sample_fourier,
};
use crate::scene::{FourierTable, MAX_FOURIER_ORDER};
use arrayvec::ArrayVec;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

#[derive(Clone, Copy, Debug)]
pub struct FourierBsdf<'a> {
    pub table: &'a FourierTable,
}

/// Catmull-Rom node offset and weights of one zenith cosine.
type Weights = (isize, [f32; 4]);

/// Interpolated coefficients, one series per channel.
type Coeffs = [ArrayVec<f32, MAX_FOURIER_ORDER>; 3];

/// pbrt-v3's `CosDPhi`: cosine of the azimuth between two directions (1 if
/// either is along the normal).
#[inline]
fn cos_dphi(wa: Vec3, wb: Vec3) -> f32 {
    let waxy = wa.x * wa.x + wa.y * wa.y;
    let wbxy = wb.x * wb.x + wb.y * wb.y;
    if waxy == 0.0 || wbxy == 0.0 {
        return 1.0;
    }
    ((wa.x * wb.x + wa.y * wb.y) / (waxy * wbxy).sqrt()).clamp(-1.0, 1.0)
}

impl<'a> FourierBsdf<'a> {
    pub fn new(table: &'a FourierTable) -> FourierBsdf<'a> {
        FourierBsdf { table }
    }

    #[inline]
    fn weights(&self, mu: f32) -> Option<Weights> {
        catmull_rom_weights(self.table.mu(), mu)
    }

    /// Sums the weighted coefficients of the 4×4 neighbouring pairs into
    /// `ak` for the first `channels` channels (pbrt-v3's loop order, so the
    /// same roundings). Each series ends at the longest order that took part.
    #[inline]
    fn accumulate(&self, wi: Weights, wo: Weights, channels: usize, ak: &mut Coeffs) {
        let (offset_i, weights_i) = wi;
        let (offset_o, weights_o) = wo;
        for (b, &w_o) in weights_o.iter().enumerate() {
            for (a, &w_i) in weights_i.iter().enumerate() {
                let weight = w_i * w_o;
                if weight == 0.0 {
                    continue;
                }
                // Non-zero weights are only on valid nodes.
                let (ap, m) = self.table.ak(
                    (offset_i + a as isize) as usize,
                    (offset_o + b as isize) as usize,
                );
                for (c, series) in ak.iter_mut().enumerate().take(channels) {
                    let coeffs = &ap[c * m..(c + 1) * m];
                    let shared = series.len().min(m);
                    for (s, &x) in series.iter_mut().zip(&coeffs[..shared]) {
                        *s += weight * x;
                    }
                    // Terms beyond what is there start from zero.
                    for &x in &coeffs[shared..] {
                        series.push(weight * x);
                    }
                }
            }
        }
    }

    /// 1/|μi| with the radiance-transport η² factor on transmission.
    #[inline]
    fn scale(&self, mu_i: f32, mu_o: f32) -> f32 {
        let mut scale = if mu_i != 0.0 { 1.0 / mu_i.abs() } else { 0.0 };
        if mu_i * mu_o > 0.0 {
            let eta = if mu_i > 0.0 {
                1.0 / self.table.eta()
            } else {
                self.table.eta()
            };
            scale *= eta * eta;
        }
        scale
    }

    /// The value from the luminance `y` and the other channels at cos φ.
    #[inline]
    fn value(&self, ak: &Coeffs, y: f32, cos_phi: f32, scale: f32) -> Vec3 {
        if self.table.n_channels() == 1 {
            return Vec3::splat((y * scale).max(0.0));
        }
        let r = fourier(&ak[1], cos_phi as f64);
        let b = fourier(&ak[2], cos_phi as f64);
        let g = 1.39829 * y - 0.100913 * b - 0.297375 * r;
        (Vec3::new(r, g, b) * scale).max(Vec3::ZERO)
    }

    /// The luminance series' integral over the hemisphere pair at μo
    /// (pbrt-v3's ρ in `Pdf`).
    #[inline]
    fn rho(&self, wo: Weights) -> f32 {
        let (offset_o, weights_o) = wo;
        let n_mu = self.table.n_mu();
        let cdf = self.table.cdf();
        let mut rho = 0.0f32;
        for (o, &w) in weights_o.iter().enumerate() {
            if w != 0.0 {
                let row = (offset_o + o as isize) as usize;
                rho += w * cdf[row * n_mu + n_mu - 1] * (2.0 * PI);
            }
        }
        rho
    }

    /// pbrt-v3's `Pdf` from the luminance series' value `y` at the pair.
    #[inline]
    fn pdf_from(&self, y: f32, wo: Weights) -> f32 {
        let rho = self.rho(wo);
        if rho > 0.0 && y > 0.0 {
            y / rho
        } else {
            0.0
        }
    }

    /// `f`, and `pdf` when `with_pdf`, from one interpolation (the pdf's
    /// luminance series is the same sum as the value's first channel).
    #[inline]
    fn evaluate(&self, wo: Vec3, wi: Vec3, with_pdf: bool) -> (Vec3, f32) {
        let (mu_i, mu_o) = (-wi.z, wo.z);
        let cos_phi = cos_dphi(-wi, wo);
        let (Some(w_i), Some(w_o)) = (self.weights(mu_i), self.weights(mu_o)) else {
            return (Vec3::ZERO, 0.0);
        };
        let mut ak = coeffs();
        self.accumulate(w_i, w_o, self.table.n_channels(), &mut ak);
        let y = fourier(&ak[0], cos_phi as f64);
        let f = self.value(&ak, y.max(0.0), cos_phi, self.scale(mu_i, mu_o));
        let pdf = if with_pdf { self.pdf_from(y, w_o) } else { 0.0 };
        (f, pdf)
    }
}

fn coeffs() -> Coeffs {
    [ArrayVec::new(), ArrayVec::new(), ArrayVec::new()]
}

impl BxdfModel for FourierBsdf<'_> {
    #[inline]
    fn flags(&self) -> BxdfFlags {
        BxdfFlags::REFLECTION | BxdfFlags::TRANSMISSION | BxdfFlags::GLOSSY
    }

    fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        self.evaluate(wo, wi, false).0
    }

    /// Only the luminance channel is interpolated.
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let (mu_i, mu_o) = (-wi.z, wo.z);
        let (Some(w_i), Some(w_o)) = (self.weights(mu_i), self.weights(mu_o)) else {
            return 0.0;
        };
        let mut ak = coeffs();
        self.accumulate(w_i, w_o, 1, &mut ak);
        let y = fourier(&ak[0], cos_dphi(-wi, wo) as f64);
        self.pdf_from(y, w_o)
    }

    fn f_pdf(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        self.evaluate(wo, wi, true)
    }

    fn sample_f(&self, wo: Vec3, u: Vec2) -> Option<BxdfSample> {
        let t = self.table;
        let mu_o = wo.z;
        let s = sample_catmull_rom_2d(t.mu(), t.mu(), t.a0(), t.cdf(), mu_o, u.y)?;
        let mu_i = s.x;
        let w_i = self.weights(mu_i)?;
        let w_o = self.weights(mu_o)?;
        let mut ak = coeffs();
        self.accumulate(w_i, w_o, t.n_channels(), &mut ak);
        let phi = sample_fourier(&ak[0], t.recip(), u.x);
        let pdf = (phi.pdf * s.pdf).max(0.0);
        // wi from wo: rotate wo's azimuth by φ, set its zenith cosine to
        // -μi, and renormalise (rounding would otherwise accumulate along a
        // path, as pbrt-v3 notes).
        let sin2_theta_i = (1.0 - mu_i * mu_i).max(0.0);
        let mut norm = (sin2_theta_i / sin2_theta(wo)).sqrt();
        if !norm.is_finite() {
            norm = 0.0;
        }
        let (sin_phi, cos_phi) = phi.phi.sin_cos();
        let wi = -Vec3::new(
            norm * (cos_phi * wo.x - sin_phi * wo.y),
            norm * (sin_phi * wo.x + cos_phi * wo.y),
            mu_i,
        );
        let len2 = wi.length_squared();
        if len2.is_nan() || len2 <= 0.0 {
            return None;
        }
        let wi = wi / len2.sqrt();
        let f = self.value(&ak, phi.value.max(0.0), cos_phi, self.scale(mu_i, mu_o));
        Some(BxdfSample {
            f,
            wi,
            pdf,
            flags: self.flags(),
        })
    }
}
