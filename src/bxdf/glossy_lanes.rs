//! Speed only: the value of a plastic-like BSDF (the lobes that match the
//! flags are a Lambertian reflection followed by a Trowbridge–Reitz
//! microfacet reflection with a dielectric or no Fresnel term: pbrt-v3's
//! `plastic`, and `uber` without its specular lobes) for up to four
//! incident directions at once, one direction per lane of an SSE vector:
//! the directions into the shading frame, the half vectors, D, Λ and G,
//! the Fresnel term and the lobes' sum, with the shading cosine, as
//! `SurfaceScatter`'s value ([`Bsdf::f_pdf`]'s value times |wi·ns|).
//!
//! The lights of a `directlighting` vertex are all evaluated at once this
//! way: one pass instead of one call chain per light (the chain through
//! the lobe list, the lobes' dispatch and `d_g_pdf` is about 500
//! instructions for this BSDF). Every lane performs the scalar code's
//! operations on its direction in the same order (a clamp as `f32::clamp`
//! with its NaN, `f32::max` with 0 as `max(x, 0)`, a select where the
//! scalar code branches), so each value is the scalar value bit for bit
//! (`tests::lanes_are_the_scalar_values`).

use super::bsdf::Bsdf;
use super::fresnel::Fresnel;
use super::microfacet::MicrofacetDistribution;
use super::{Bxdf, BxdfFlags};
use glam::Vec3;
use std::f32::consts::FRAC_1_PI;

/// The most directions one call evaluates.
pub const GLOSSY_LANES: usize = 4;

/// A BSDF of that shape, read from its lobes.
#[derive(Clone, Copy, Debug)]
pub struct GlossyPair {
    /// The Lambertian lobe's value times its scale.
    diffuse: Vec3,
    /// The microfacet lobe's reflectance and scale.
    spec_r: Vec3,
    spec_scale: Vec3,
    ax: f32,
    ay: f32,
    /// `(eta_i, eta_t)` of the dielectric Fresnel term; `None` for none.
    eta: Option<(f32, f32)>,
    /// The flags the pair was read with (the scalar code's, which the
    /// lanes need not read: the pair's lobes are the ones they match).
    #[cfg_attr(all(target_arch = "x86_64", not(test)), allow(dead_code))]
    flags: BxdfFlags,
}

impl GlossyPair {
    /// The pair of `bsdf`'s lobes that match `flags`, if they have this
    /// shape (lobes that do not match are left out, as the scalar code
    /// leaves them).
    pub fn of(bsdf: &Bsdf, flags: BxdfFlags) -> Option<GlossyPair> {
        let mut matching = bsdf.lobes().iter().filter(|l| l.flags.matches(flags));
        let (diffuse, spec) = (matching.next()?, matching.next()?);
        if matching.next().is_some() {
            return None;
        }
        let Bxdf::LambertianReflection(d) = diffuse.bxdf else {
            return None;
        };
        let Bxdf::MicrofacetReflection(m) = spec.bxdf else {
            return None;
        };
        let MicrofacetDistribution::TrowbridgeReitz(tr) = m.distribution else {
            return None;
        };
        let eta = match m.fresnel {
            Fresnel::NoOp => None,
            Fresnel::Dielectric { eta_i, eta_t } => Some((eta_i, eta_t)),
            _ => return None,
        };
        Some(GlossyPair {
            diffuse: d.r * FRAC_1_PI * diffuse.scale,
            spec_r: m.r,
            spec_scale: spec.scale,
            ax: tr.alpha_x,
            ay: tr.alpha_y,
            eta,
            flags,
        })
    }

    /// `SurfaceScatter { bsdf, ns, flags }`'s value for `wo` and each of
    /// `wi[..n]` (`n` at most [`GLOSSY_LANES`]), where `bsdf` is the BSDF
    /// this pair was read from with `flags`.
    #[inline]
    pub fn f(&self, bsdf: &Bsdf, ns: Vec3, wo: Vec3, wi: &[Vec3], out: &mut [Vec3]) {
        #[cfg(target_arch = "x86_64")]
        {
            // SAFETY: SSE and SSE2 are part of x86_64.
            unsafe { self.f_sse(bsdf, ns, wo, wi, out) }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            for (o, &w) in out.iter_mut().zip(wi) {
                *o = self.f_plain(bsdf, ns, wo, w);
            }
        }
    }

    /// One direction's value by the scalar code: `SurfaceScatter`'s (other
    /// architectures, and the tests' reference).
    #[cfg(any(test, not(target_arch = "x86_64")))]
    fn f_plain(&self, bsdf: &Bsdf, ns: Vec3, wo: Vec3, wi: Vec3) -> Vec3 {
        let f = if bsdf.reaches(wo, wi, self.flags) {
            bsdf.f_pdf(wo, wi, self.flags).0
        } else {
            Vec3::ZERO
        };
        f * wi.dot(ns).abs()
    }

    #[cfg(target_arch = "x86_64")]
    #[inline]
    unsafe fn f_sse(&self, bsdf: &Bsdf, ns: Vec3, wo_w: Vec3, wi: &[Vec3], out: &mut [Vec3]) {
        use std::arch::x86_64::*;
        let n = wi.len().min(out.len()).min(GLOSSY_LANES);
        let lane = |k: usize| wi[k.min(n.max(1) - 1)];
        let (w0, w1, w2, w3) = (lane(0), lane(1), lane(2), lane(3));
        let wx = _mm_setr_ps(w0.x, w1.x, w2.x, w3.x);
        let wy = _mm_setr_ps(w0.y, w1.y, w2.y, w3.y);
        let wz = _mm_setr_ps(w0.z, w1.z, w2.z, w3.z);
        let s = _mm_set1_ps;
        let (add, sub, mul, div) = (_mm_add_ps, _mm_sub_ps, _mm_mul_ps, _mm_div_ps);
        let select =
            |m: __m128, a: __m128, b: __m128| _mm_or_ps(_mm_and_ps(m, a), _mm_andnot_ps(m, b));
        let abs = |v: __m128| _mm_andnot_ps(s(-0.0), v);
        // v·a in glam's order, (x·a.x + y·a.y) + z·a.z.
        let dot =
            |x: __m128, y: __m128, z: __m128, a: Vec3| dot_lanes(x, y, z, s(a.x), s(a.y), s(a.z));
        let (zero, one) = (_mm_setzero_ps(), s(1.0));
        let frame = &bsdf.frame;
        // Scalar parts, once: wo in the frame, wo·ng.
        let wo = frame.to_local(wo_w);
        let wo_ng = wo_w.dot(bsdf.ng);
        // reflect = wi·ng · wo·ng > 0 (the lobes are reflections: with
        // `reaches` false the value is zero either way); with wo.z = 0 no
        // lobe has a value either.
        let reflect = _mm_cmpgt_ps(mul(dot(wx, wy, wz, bsdf.ng), s(wo_ng)), zero);
        let valued = if wo.z == 0.0 { zero } else { reflect };
        let cos_ns = abs(dot(wx, wy, wz, ns));
        let (ix, iy, iz) = (
            dot(wx, wy, wz, frame.s),
            dot(wx, wy, wz, frame.t),
            dot(wx, wy, wz, frame.n),
        );
        // The half vector, normalised as glam does: v · (1 / √(v·v)).
        let (hx, hy, hz) = (add(s(wo.x), ix), add(s(wo.y), iy), add(s(wo.z), iz));
        let sum_zero = _mm_and_ps(
            _mm_and_ps(_mm_cmpeq_ps(hx, zero), _mm_cmpeq_ps(hy, zero)),
            _mm_cmpeq_ps(hz, zero),
        );
        let len = _mm_sqrt_ps(add(add(mul(hx, hx), mul(hy, hy)), mul(hz, hz)));
        let r = div(one, len);
        let (hx, hy, hz) = (mul(hx, r), mul(hy, r), mul(hz, r));
        // cos²θ, sin²θ, sin θ, cos²φ, sin²φ of a direction (d_g_pdf's).
        let clamp1 = |v: __m128| _mm_min_ps(one, _mm_max_ps(s(-1.0), v));
        let angles = |x: __m128, y: __m128, z: __m128| {
            let cos2 = mul(z, z);
            let sin2 = _mm_max_ps(sub(one, cos2), zero);
            let sin = _mm_sqrt_ps(sin2);
            let pole = _mm_cmpeq_ps(sin, zero);
            let cos_phi = select(pole, one, clamp1(div(x, sin)));
            let sin_phi = select(pole, zero, clamp1(div(y, sin)));
            (
                cos2,
                sin2,
                sin,
                mul(cos_phi, cos_phi),
                mul(sin_phi, sin_phi),
            )
        };
        let (ax, ay) = (self.ax, self.ay);
        let lambda = |x: __m128, y: __m128, z: __m128| {
            let (_, _, sin, cos2_phi, sin2_phi) = angles(x, y, z);
            let alpha = _mm_sqrt_ps(add(
                mul(mul(cos2_phi, s(ax)), s(ax)),
                mul(mul(sin2_phi, s(ay)), s(ay)),
            ));
            let tan = abs(div(sin, z));
            let at = mul(alpha, tan);
            let l = mul(s(0.5), sub(_mm_sqrt_ps(add(one, mul(at, at))), one));
            select(_mm_cmpeq_ps(tan, s(f32::INFINITY)), zero, l)
        };
        // D(wh).
        let (cos2, sin2, _, cos2_phi, sin2_phi) = angles(hx, hy, hz);
        let inv_alpha2 = add(div(cos2_phi, s(ax * ax)), div(sin2_phi, s(ay * ay)));
        let e = add(cos2, mul(sin2, inv_alpha2));
        let d = div(one, mul(mul(s(std::f32::consts::PI * ax * ay), e), e));
        let d = select(_mm_cmpeq_ps(cos2, zero), zero, d);
        // G(wo, wi) = 1 / (1 + Λ(wo) + Λ(wi)).
        let lambda_o = lambda(s(wo.x), s(wo.y), s(wo.z));
        let lambda_i = lambda(ix, iy, iz);
        let g = div(one, add(add(one, lambda_o), lambda_i));
        // The Fresnel term at wi·wh (wh turned to the upper side).
        let up = _mm_cmplt_ps(hz, zero);
        let flip = _mm_and_ps(up, s(-0.0));
        let c = dot_lanes(
            ix,
            iy,
            iz,
            _mm_xor_ps(hx, flip),
            _mm_xor_ps(hy, flip),
            _mm_xor_ps(hz, flip),
        );
        let fr = match self.eta {
            None => one,
            Some((eta_i, eta_t)) => {
                let cos_i = clamp1(c);
                let inside = _mm_cmple_ps(cos_i, zero);
                let ei = select(inside, s(eta_t), s(eta_i));
                let et = select(inside, s(eta_i), s(eta_t));
                let cos_i = select(inside, abs(cos_i), cos_i);
                let sin_i = _mm_sqrt_ps(_mm_max_ps(sub(one, mul(cos_i, cos_i)), zero));
                let ratio = select(inside, s(eta_t / eta_i), s(eta_i / eta_t));
                let sin_t = mul(ratio, sin_i);
                let cos_t = _mm_sqrt_ps(_mm_max_ps(sub(one, mul(sin_t, sin_t)), zero));
                let r_parl = div(
                    sub(mul(et, cos_i), mul(ei, cos_t)),
                    add(mul(et, cos_i), mul(ei, cos_t)),
                );
                let r_perp = div(
                    sub(mul(ei, cos_i), mul(et, cos_t)),
                    add(mul(ei, cos_i), mul(et, cos_t)),
                );
                let fr = mul(s(0.5), add(mul(r_parl, r_parl), mul(r_perp, r_perp)));
                // Total internal reflection: 1 (NaN sin_t compares false).
                select(_mm_cmpge_ps(sin_t, one), one, fr)
            }
        };
        // d·g / (4·cos_i·cos_o), and the lobe's value per channel; zero
        // where wi is grazing or wo + wi vanishes.
        let k = div(mul(d, g), mul(mul(s(4.0), abs(iz)), s(wo.z.abs())));
        let spec_off = _mm_or_ps(_mm_cmpeq_ps(iz, zero), sum_zero);
        let channel = |r: f32, scale: f32, diffuse: f32| {
            let lobe = select(spec_off, zero, mul(mul(fr, s(r)), k));
            // (0 + diffuse) + lobe·scale where wi is on wo's side.
            let f = add(add(zero, s(diffuse)), mul(lobe, s(scale)));
            mul(select(valued, f, zero), cos_ns)
        };
        let fx = channel(self.spec_r.x, self.spec_scale.x, self.diffuse.x);
        let fy = channel(self.spec_r.y, self.spec_scale.y, self.diffuse.y);
        let fz = channel(self.spec_r.z, self.spec_scale.z, self.diffuse.z);
        let (mut x, mut y, mut z) = ([0f32; 4], [0f32; 4], [0f32; 4]);
        _mm_storeu_ps(x.as_mut_ptr(), fx);
        _mm_storeu_ps(y.as_mut_ptr(), fy);
        _mm_storeu_ps(z.as_mut_ptr(), fz);
        for (k, o) in out[..n].iter_mut().enumerate() {
            *o = Vec3::new(x[k], y[k], z[k]);
        }
    }
}

/// `a·b` of lanes in glam's order.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn dot_lanes(
    ax: std::arch::x86_64::__m128,
    ay: std::arch::x86_64::__m128,
    az: std::arch::x86_64::__m128,
    bx: std::arch::x86_64::__m128,
    by: std::arch::x86_64::__m128,
    bz: std::arch::x86_64::__m128,
) -> std::arch::x86_64::__m128 {
    use std::arch::x86_64::*;
    _mm_add_ps(
        _mm_add_ps(_mm_mul_ps(ax, bx), _mm_mul_ps(ay, by)),
        _mm_mul_ps(az, bz),
    )
}

#[cfg(test)]
mod tests {
    use super::super::{
        LambertianReflection, MicrofacetReflection, SpecularReflection, TrowbridgeReitz,
    };
    use super::*;
    use crate::geometry::Frame;
    use crate::sampling::rng::Pcg32;

    fn bits(v: Vec3) -> [u32; 3] {
        [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()]
    }

    /// Plastic and uber-like BSDFs (isotropic, anisotropic and extreme
    /// roughness; dielectric Fresnel terms entering and leaving, none; a
    /// specular lobe that the flags leave out; scaled lobes), random frames
    /// with shading normals apart from the geometric one, and directions on
    /// both sides, grazing (z = 0 in the frame), opposite (wo + wi = 0),
    /// unnormalised and NaN: every lane is the scalar value bit for bit,
    /// for one to four directions a call.
    #[test]
    fn lanes_are_the_scalar_values() {
        let mut rng = Pcg32::with_sequence(29);
        let mut r = move || rng.uniform_f32();
        let mut checked = 0;
        for k in 0..20_000 {
            let v = |r: &mut dyn FnMut() -> f32| Vec3::new(r() - 0.5, r() - 0.5, r() - 0.5);
            let n = v(&mut r).normalize_or(Vec3::Z);
            let frame = Frame::from_normal(n);
            let ng = (n + 0.3 * v(&mut r)).normalize_or(n);
            let mut bsdf = Bsdf::new(frame, ng, 1.0);
            let alphas = [1e-3f32, 0.05, 0.3, 0.8, 2.0];
            let ax = alphas[k % 5] * (0.5 + r());
            let ay = if k % 3 == 0 { alphas[(k / 5) % 5] } else { ax };
            let fresnel = match k % 4 {
                0 => Fresnel::NoOp,
                1 => Fresnel::Dielectric {
                    eta_i: 1.5,
                    eta_t: 1.0,
                },
                2 => Fresnel::Dielectric {
                    eta_i: 1.0,
                    eta_t: 1.33 + r(),
                },
                _ => Fresnel::Dielectric {
                    eta_i: 1.0,
                    eta_t: 0.7,
                },
            };
            let scale = if k % 7 == 0 {
                Vec3::new(0.5, 2.0, 0.0)
            } else {
                Vec3::ONE
            };
            bsdf.add_scaled(
                LambertianReflection {
                    r: v(&mut r) + Vec3::splat(0.5),
                },
                scale,
            );
            bsdf.add_scaled(
                MicrofacetReflection {
                    r: v(&mut r) + Vec3::splat(0.5),
                    distribution: MicrofacetDistribution::TrowbridgeReitz(
                        TrowbridgeReitz::new(ax, ay).with_visible_sampling(k % 2 == 0),
                    ),
                    fresnel,
                },
                Vec3::ONE / scale.max(Vec3::splat(0.25)),
            );
            if k % 5 == 0 {
                bsdf.add(SpecularReflection {
                    r: Vec3::ONE,
                    fresnel: Fresnel::NoOp,
                });
            }
            let pair = GlossyPair::of(&bsdf, BxdfFlags::NON_SPECULAR).expect("a glossy pair");
            let ns = (n + 0.2 * v(&mut r)).normalize_or(n);
            let dir = |r: &mut dyn FnMut() -> f32, k: usize| -> Vec3 {
                match k % 13 {
                    0 => frame.s * (r() - 0.5) + frame.t * (r() - 0.5),
                    1 => Vec3::new(f32::NAN, 0.5, 0.5),
                    2 => ng * (r() - 0.5),
                    3 => v(r) * 3.0,
                    _ => v(r).normalize_or(Vec3::X),
                }
            };
            let wo = if k % 17 == 0 {
                frame.s
            } else {
                dir(&mut r, k / 13)
            };
            let count = 1 + k % GLOSSY_LANES;
            let mut wi = [Vec3::ZERO; GLOSSY_LANES];
            for (j, w) in wi[..count].iter_mut().enumerate() {
                *w = if (k + j) % 11 == 0 {
                    -wo
                } else {
                    dir(&mut r, k + 3 * j)
                };
            }
            let mut out = [Vec3::splat(-7.0); GLOSSY_LANES];
            pair.f(&bsdf, ns, wo, &wi[..count], &mut out[..count]);
            for j in 0..count {
                let want = pair.f_plain(&bsdf, ns, wo, wi[j]);
                let got = out[j];
                let same = bits(got) == bits(want)
                    || (0..3).all(|c| {
                        got[c].is_nan() && want[c].is_nan() || got[c].to_bits() == want[c].to_bits()
                    });
                assert!(
                    same,
                    "{bsdf:?} ns {ns} wo {wo} wi {}: {got} against {want}",
                    wi[j]
                );
                checked += 1;
            }
        }
        assert!(checked > 40_000);
    }

    /// Only that shape is taken: one lobe, a Beckmann or conductor
    /// microfacet lobe, the lobes the other way round.
    #[test]
    fn other_bsdfs_are_not_glossy_pairs() {
        let frame = Frame::from_normal(Vec3::Z);
        let spec = |distribution, fresnel| MicrofacetReflection {
            r: Vec3::ONE,
            distribution,
            fresnel,
        };
        let tr = MicrofacetDistribution::TrowbridgeReitz(TrowbridgeReitz::new(0.2, 0.2));
        let beckmann = MicrofacetDistribution::Beckmann(super::super::Beckmann::new(0.2, 0.2));
        let dielectric = Fresnel::Dielectric {
            eta_i: 1.5,
            eta_t: 1.0,
        };
        let conductor = Fresnel::Conductor {
            eta_i: Vec3::ONE,
            eta_t: Vec3::splat(0.2),
            k: Vec3::splat(3.0),
        };
        let lambert = LambertianReflection { r: Vec3::ONE };
        let make = |lobes: &[Bxdf<'static>]| {
            let mut b = Bsdf::new(frame, Vec3::Z, 1.0);
            for &l in lobes {
                b.add(l);
            }
            GlossyPair::of(&b, BxdfFlags::NON_SPECULAR).is_some()
        };
        assert!(make(&[lambert.into(), spec(tr, dielectric).into()]));
        assert!(!make(&[lambert.into()]));
        assert!(!make(&[spec(tr, dielectric).into(), lambert.into()]));
        assert!(!make(&[lambert.into(), spec(beckmann, dielectric).into()]));
        assert!(!make(&[lambert.into(), spec(tr, conductor).into()]));
        assert!(!make(&[
            lambert.into(),
            spec(tr, dielectric).into(),
            lambert.into()
        ]));
    }
}
