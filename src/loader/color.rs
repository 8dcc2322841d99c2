//! Colours to linear RGB as pbrt-v3's default `RGBSpectrum` build does.
//!
//! `xyz` uses pbrt-v3's `XYZToRGB` matrix. Sampled spectra (`spectrum` pairs and
//! `blackbody`) are integrated against the CIE 1931 2° colour matching functions
//! over 360–830 nm at 1 nm as `RGBSpectrum::FromSampled` does; pbrs evaluates the
//! matching functions with the multi-lobe Gaussian fit of Wyman, Sloan and Shirley
//! (JCGT 2013) instead of the tabulated data, which agrees to about 1%.

use glam::Vec3;

/// pbrt-v3 `XYZToRGB` (spectrum.h).
pub fn xyz_to_rgb(x: f64, y: f64, z: f64) -> Vec3 {
    Vec3::new(
        (3.240479 * x - 1.537150 * y - 0.498535 * z) as f32,
        (-0.969256 * x + 1.875991 * y + 0.041556 * z) as f32,
        (0.055648 * x - 0.204043 * y + 1.057311 * z) as f32,
    )
}

fn lobe(l: f64, mu: f64, s1: f64, s2: f64) -> f64 {
    let t = (l - mu) / if l < mu { s1 } else { s2 };
    (-0.5 * t * t).exp()
}

/// CIE 1931 x̄, ȳ, z̄ at wavelength `l` (nm), multi-lobe fit.
pub fn cie_xyz(l: f64) -> [f64; 3] {
    [
        1.056 * lobe(l, 599.8, 37.9, 31.0) + 0.362 * lobe(l, 442.0, 16.0, 26.7)
            - 0.065 * lobe(l, 501.1, 20.4, 26.2),
        0.821 * lobe(l, 568.8, 46.9, 40.5) + 0.286 * lobe(l, 530.9, 16.3, 31.1),
        1.217 * lobe(l, 437.0, 11.8, 36.0) + 0.681 * lobe(l, 459.0, 26.0, 13.8),
    ]
}

const CIE_Y_INTEGRAL: f64 = 106.856895;
const LAMBDA_MIN: i32 = 360;
const LAMBDA_MAX: i32 = 830;

/// Piecewise-linear value of sorted samples at `l`, clamped at the ends.
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

/// `RGBSpectrum::FromSampled`: (λ nm, value) pairs to linear RGB.
pub fn sampled_to_rgb(pairs: &[f64]) -> Vec3 {
    let mut samples: Vec<(f64, f64)> = pairs.chunks_exact(2).map(|c| (c[0], c[1])).collect();
    if samples.is_empty() {
        return Vec3::ZERO;
    }
    samples.sort_by(|a, b| a.0.total_cmp(&b.0));
    integrate(|l| interpolate(&samples, l))
}

fn integrate(f: impl Fn(f64) -> f64) -> Vec3 {
    let mut xyz = [0.0f64; 3];
    for l in LAMBDA_MIN..=LAMBDA_MAX {
        let l = l as f64;
        let v = f(l);
        let c = cie_xyz(l);
        for k in 0..3 {
            xyz[k] += v * c[k];
        }
    }
    let n = (LAMBDA_MAX - LAMBDA_MIN + 1) as f64;
    let scale = (LAMBDA_MAX - LAMBDA_MIN) as f64 / (CIE_Y_INTEGRAL * n);
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
    fn constant_spectrum_is_about_white() {
        // A flat spectrum of 1 has Y = 1 and, in sRGB, roughly equal components
        // (illuminant E is slightly pink in sRGB).
        let c = sampled_to_rgb(&[300.0, 1.0, 900.0, 1.0]);
        assert!(
            (c.x - 1.2).abs() < 0.1 && (c.y - 0.95).abs() < 0.1 && (c.z - 0.9).abs() < 0.12,
            "{c}"
        );
        let y = 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
        assert!((y - 1.0).abs() < 0.03, "{y}");
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
