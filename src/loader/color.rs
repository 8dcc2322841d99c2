//! Colours to linear RGB as pbrt-v3's default `RGBSpectrum` build does.
//!
//! `xyz` uses pbrt-v3's `XYZToRGB` matrix. Sampled spectra (`spectrum` pairs,
//! spectrum files and `blackbody`) are integrated against the tabulated CIE
//! 1931 2° colour-matching functions ([`super::cie1931`]) at every nm from 360
//! to 830 as `RGBSpectrum::FromSampled` does: the spectrum is interpolated
//! linearly at each table wavelength (constant beyond its ends) and the sums
//! are scaled by pbrt-v3's `CIE_Y_integral` normalisation, which makes a flat
//! spectrum of 1 come out with Y = 470/471 (pbrt-v3 divides by the sample
//! count, not by the 470 one-nm intervals).

use super::cie1931::{CIE_1931_2DEG, CIE_LAMBDA_MAX, CIE_LAMBDA_MIN};
use glam::Vec3;

/// pbrt-v3 `XYZToRGB` (spectrum.h).
pub fn xyz_to_rgb(x: f64, y: f64, z: f64) -> Vec3 {
    Vec3::new(
        (3.240479 * x - 1.537150 * y - 0.498535 * z) as f32,
        (-0.969256 * x + 1.875991 * y + 0.041556 * z) as f32,
        (0.055648 * x - 0.204043 * y + 1.057311 * z) as f32,
    )
}

/// CIE 1931 x̄, ȳ, z̄ at a whole wavelength `l` in nm (0 outside 360–830).
pub fn cie_xyz(l: i32) -> [f64; 3] {
    if (CIE_LAMBDA_MIN..=CIE_LAMBDA_MAX).contains(&l) {
        CIE_1931_2DEG[(l - CIE_LAMBDA_MIN) as usize]
    } else {
        [0.0; 3]
    }
}

/// pbrt-v3's `CIE_Y_integral` (spectrum.h).
const CIE_Y_INTEGRAL: f64 = 106.856895;

/// Piecewise-linear value of sorted samples at `l`, clamped at the ends
/// (pbrt-v3 `InterpolateSpectrumSamples`).
fn interpolate(samples: &[(f64, f64)], l: f64) -> f64 {
    let (first, last) = (samples[0], samples[samples.len() - 1]);
    if l <= first.0 {
        return first.1;
    }
    if l >= last.0 {
        return last.1;
    }
    let i = samples
        .partition_point(|s| s.0 <= l)
        .clamp(1, samples.len() - 1);
    let (a, b) = (samples[i - 1], samples[i]);
    let t = (l - a.0) / (b.0 - a.0);
    a.1 + t * (b.1 - a.1)
}

/// `RGBSpectrum::FromSampled`: (λ nm, value) pairs to linear RGB. Pairs in
/// any order are sorted first, as pbrt-v3 does; no pair gives black.
pub fn sampled_to_rgb(pairs: &[f64]) -> Vec3 {
    let mut samples: Vec<(f64, f64)> = pairs.chunks_exact(2).map(|c| (c[0], c[1])).collect();
    if samples.is_empty() {
        return Vec3::ZERO;
    }
    samples.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    integrate(|l| interpolate(&samples, l))
}

/// The first wavelength that appears more than once among (λ, value) pairs.
/// pbrt-v3 stops on a failed check for such a spectrum; pbrs warns and reads
/// it as a step.
pub fn repeated_wavelength(pairs: &[f64]) -> Option<f64> {
    let mut l: Vec<f64> = pairs.chunks_exact(2).map(|c| c[0]).collect();
    l.sort_by(f64::total_cmp);
    l.windows(2).find(|w| w[0] == w[1]).map(|w| w[0])
}

/// The XYZ integral of `f` sampled at the table's wavelengths, to RGB.
fn integrate(f: impl Fn(f64) -> f64) -> Vec3 {
    let mut xyz = [0.0f64; 3];
    for (i, c) in CIE_1931_2DEG.iter().enumerate() {
        let v = f((CIE_LAMBDA_MIN + i as i32) as f64);
        for k in 0..3 {
            xyz[k] += v * c[k];
        }
    }
    let n = CIE_1931_2DEG.len() as f64;
    let scale = (CIE_LAMBDA_MAX - CIE_LAMBDA_MIN) as f64 / (CIE_Y_INTEGRAL * n);
    xyz_to_rgb(xyz[0] * scale, xyz[1] * scale, xyz[2] * scale)
}

/// Planck's law, emitted radiance at `l` nm and temperature `t` K (pbrt-v3 `Blackbody`).
fn planck(l: f64, t: f64) -> f64 {
    const C: f64 = 299792458.0;
    const H: f64 = 6.62606957e-34;
    const KB: f64 = 1.3806488e-23;
    let l = l * 1e-9;
    (2.0 * H * C * C) / (l.powi(5) * (((H * C) / (l * KB * t)).exp() - 1.0))
}

/// pbrt-v3's normalised blackbody (peak 1) at temperature `t`, as RGB, times `scale`.
pub fn blackbody_to_rgb(t: f64, scale: f64) -> Vec3 {
    if t.is_nan() || t <= 0.0 {
        return Vec3::ZERO;
    }
    let peak = planck(2.8977721e-3 / t * 1e9, t);
    integrate(|l| planck(l, t) / peak) * scale as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flat_spectrum_has_pbrt_v3_luminance() {
        // Y of a flat 1 is ∑ȳ · 470 / (CIE_Y_INTEGRAL · 471): 470/471 up to the
        // table's sum, pbrt-v3's normalisation. Y from RGB with sRGB's row.
        let c = sampled_to_rgb(&[300.0, 1.0, 900.0, 1.0]);
        let y = 0.2126729 * c.x + 0.7151522 * c.y + 0.0721750 * c.z;
        let sum: f64 = CIE_1931_2DEG.iter().map(|c| c[1]).sum();
        let want = sum * 470.0 / (CIE_Y_INTEGRAL * 471.0);
        assert!((want - 470.0 / 471.0).abs() < 1e-6, "{want}");
        assert!((y as f64 - want).abs() < 1e-4, "{y} vs {want}");
        // Illuminant E is pink in sRGB.
        assert!(c.x > c.y && c.y > c.z, "{c}");
        assert_eq!(sampled_to_rgb(&[]), Vec3::ZERO);
    }

    #[test]
    fn one_pair_is_constant_and_repeats_are_found() {
        assert_eq!(
            sampled_to_rgb(&[550.0, 0.5]),
            sampled_to_rgb(&[300.0, 0.5, 900.0, 0.5])
        );
        assert_eq!(
            repeated_wavelength(&[500.0, 1.0, 400.0, 2.0, 500.0, 3.0]),
            Some(500.0)
        );
        assert_eq!(repeated_wavelength(&[500.0, 1.0, 400.0, 1.0]), None);
    }

    #[test]
    fn blackbody_colours() {
        let warm = blackbody_to_rgb(2700.0, 1.0);
        let cold = blackbody_to_rgb(10000.0, 1.0);
        assert!(warm.x > warm.z && cold.z > cold.x, "{warm} {cold}");
        assert_eq!(
            blackbody_to_rgb(6500.0, 2.0),
            blackbody_to_rgb(6500.0, 1.0) * 2.0
        );
    }

    #[test]
    fn xyz_white() {
        let c = xyz_to_rgb(0.9505, 1.0, 1.089);
        assert!((c - Vec3::ONE).abs().max_element() < 0.01, "{c}");
    }
}
