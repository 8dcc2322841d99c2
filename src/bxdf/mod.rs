//! BxDFs: the scattering lobes a BSDF is made of, one struct per pbrt-v3
//! BxDF, each in its own file, all in the local shading frame (z is the
//! shading normal, x the shading `dpdu`).
//!
//! Every lobe implements [`BxdfModel`]: its [`BxdfFlags`] (reflection or
//! transmission × diffuse, glossy or specular, as pbrt-v3's `BxDFType`),
//! `f`, `sample_f` and `pdf`. [`Bxdf`] is the closed set of lobes; it only
//! delegates to the structs (no maths in its match arms). [`Bsdf`] holds up to
//! [`MAX_BXDFS`] of them in a fixed array with the shading frame, pbrt-v3's
//! `BSDF` with `Add` and no allocation per hit.

mod bsdf;
mod disney;
mod fourier;
mod fresnel;
mod fresnel_blend;
mod glossy_lanes;
pub mod hair;
mod lambertian;
pub(crate) mod microfacet;
mod microfacet_lanes;
mod microfacet_lobes;
mod oren_nayar;
mod specular;
mod sw_adapter;

pub use bsdf::{Bsdf, BsdfHead, BsdfSample, Lobe, MAX_BXDFS};
pub use disney::{
    fr_schlick, gtr1, schlick_r0_from_eta, schlick_weight, DisneyClearcoat, DisneyDiffuse,
    DisneyFakeSS, DisneyFresnel, DisneyMicrofacet, DisneyRetro, DisneySheen,
};
pub use fourier::FourierBsdf;
pub use fresnel::{fr_conductor, fr_dielectric, Fresnel};
pub use fresnel_blend::FresnelBlend;
pub use glossy_lanes::{GlossyPair, GLOSSY_LANES};
pub use hair::HairBsdf;
pub use lambertian::{LambertianReflection, LambertianTransmission};
pub use microfacet::{
    roughness_to_alpha, Beckmann, MicrofacetDistribution, MicrofacetModel, TrowbridgeReitz,
};
pub use microfacet_lobes::{MicrofacetReflection, MicrofacetTransmission};
pub use oren_nayar::OrenNayar;
pub use specular::{refract, FresnelSpecular, SpecularReflection, SpecularTransmission};
pub use sw_adapter::SwAdapter;

use crate::sampling::cosine_sample_hemisphere;
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

/// pbrt-v3's `BxDFType`: which hemisphere a lobe scatters into and how.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub struct BxdfFlags(pub u8);

impl BxdfFlags {
    pub const NONE: BxdfFlags = BxdfFlags(0);
    pub const REFLECTION: BxdfFlags = BxdfFlags(1);
    pub const TRANSMISSION: BxdfFlags = BxdfFlags(2);
    pub const DIFFUSE: BxdfFlags = BxdfFlags(4);
    pub const GLOSSY: BxdfFlags = BxdfFlags(8);
    pub const SPECULAR: BxdfFlags = BxdfFlags(16);
    /// Every lobe (pbrt-v3's `BSDF_ALL`).
    pub const ALL: BxdfFlags = BxdfFlags(31);
    /// Every lobe but the specular ones (`BSDF_ALL & ~BSDF_SPECULAR`).
    pub const NON_SPECULAR: BxdfFlags = BxdfFlags(31 & !16);
    pub const SPECULAR_REFLECTION: BxdfFlags = BxdfFlags(1 | 16);
    pub const SPECULAR_TRANSMISSION: BxdfFlags = BxdfFlags(2 | 16);

    /// True if any flag of `o` is set.
    #[inline]
    pub const fn intersects(self, o: BxdfFlags) -> bool {
        self.0 & o.0 != 0
    }
    /// pbrt-v3's `MatchesFlags`: every flag of `self` is in the mask `t`.
    #[inline]
    pub const fn matches(self, t: BxdfFlags) -> bool {
        self.0 & t.0 == self.0
    }
    #[inline]
    pub const fn is_specular(self) -> bool {
        self.intersects(BxdfFlags::SPECULAR)
    }
    #[inline]
    pub const fn is_transmission(self) -> bool {
        self.intersects(BxdfFlags::TRANSMISSION)
    }
    #[inline]
    pub const fn is_reflection(self) -> bool {
        self.intersects(BxdfFlags::REFLECTION)
    }
}

impl std::ops::BitOr for BxdfFlags {
    type Output = BxdfFlags;
    fn bitor(self, o: BxdfFlags) -> BxdfFlags {
        BxdfFlags(self.0 | o.0)
    }
}

/// A sampled direction of one lobe (local frame).
#[derive(Clone, Copy, Debug)]
pub struct BxdfSample {
    /// The lobe's value (not multiplied by the cosine).
    pub f: Vec3,
    pub wi: Vec3,
    pub pdf: f32,
    /// What was sampled (FresnelSpecular reports reflection or transmission).
    pub flags: BxdfFlags,
}

/// One lobe in the local shading frame (pbrt-v3's `BxDF` interface).
pub trait BxdfModel {
    fn flags(&self) -> BxdfFlags;
    /// Value for a pair of directions (zero for specular lobes).
    fn f(&self, wo: Vec3, wi: Vec3) -> Vec3;
    /// Samples `wi` given `wo`; the default is pbrt-v3's cosine-weighted
    /// hemisphere on `wo`'s side.
    #[inline(always)]
    fn sample_f(&self, wo: Vec3, u: Vec2) -> Option<BxdfSample> {
        let mut wi = cosine_sample_hemisphere(u);
        if wo.z < 0.0 {
            wi.z = -wi.z;
        }
        let pdf = self.pdf(wo, wi);
        Some(BxdfSample {
            f: self.f(wo, wi),
            wi,
            pdf,
            flags: self.flags(),
        })
    }
    /// `sample_f`'s direction, density and flags, its value left to the
    /// lobe (zero or the value): for callers that evaluate the value again
    /// (a BSDF of several lobes sums every lobe's `f` at the direction).
    #[inline(always)]
    fn sample_wi(&self, wo: Vec3, u: Vec2) -> Option<BxdfSample> {
        self.sample_f(wo, u)
    }
    /// Density of `sample_f` by solid angle (zero for specular lobes).
    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if same_hemisphere(wo, wi) {
            abs_cos_theta(wi) * FRAC_1_PI
        } else {
            0.0
        }
    }
    /// `(f, pdf)` together (lobes may share work between them).
    #[inline]
    fn f_pdf(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        (self.f(wo, wi), self.pdf(wo, wi))
    }
}

/// Generates the closed enum of lobes and its delegating impl.
macro_rules! bxdfs {
    ($($(#[$doc:meta])* $variant:ident($ty:ty),)*) => {
        /// The closed set of lobes; each variant is one struct of this
        /// module. `'a` is the lifetime of tabulated data a lobe refers to
        /// (the material's: see `FourierBsdf`).
        #[derive(Clone, Copy, Debug)]
        pub enum Bxdf<'a> {
            $($(#[$doc])* $variant($ty),)*
        }
        $(impl<'a> From<$ty> for Bxdf<'a> {
            #[inline]
            fn from(b: $ty) -> Bxdf<'a> {
                Bxdf::$variant(b)
            }
        })*
        impl BxdfModel for Bxdf<'_> {
            #[inline]
            fn flags(&self) -> BxdfFlags {
                match self { $(Bxdf::$variant(b) => b.flags(),)* }
            }
            #[inline]
            fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
                match self { $(Bxdf::$variant(b) => b.f(wo, wi),)* }
            }
            #[inline]
            fn sample_f(&self, wo: Vec3, u: Vec2) -> Option<BxdfSample> {
                match self { $(Bxdf::$variant(b) => b.sample_f(wo, u),)* }
            }
            #[inline]
            fn sample_wi(&self, wo: Vec3, u: Vec2) -> Option<BxdfSample> {
                match self { $(Bxdf::$variant(b) => b.sample_wi(wo, u),)* }
            }
            #[inline]
            fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
                match self { $(Bxdf::$variant(b) => b.pdf(wo, wi),)* }
            }
            #[inline]
            fn f_pdf(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
                match self { $(Bxdf::$variant(b) => b.f_pdf(wo, wi),)* }
            }
        }
    };
}

bxdfs! {
    LambertianReflection(LambertianReflection),
    LambertianTransmission(LambertianTransmission),
    OrenNayar(OrenNayar),
    SpecularReflection(SpecularReflection),
    SpecularTransmission(SpecularTransmission),
    FresnelSpecular(FresnelSpecular),
    MicrofacetReflection(MicrofacetReflection),
    MicrofacetTransmission(MicrofacetTransmission),
    FresnelBlend(FresnelBlend),
    DisneyDiffuse(DisneyDiffuse),
    DisneyFakeSS(DisneyFakeSS),
    DisneyRetro(DisneyRetro),
    DisneySheen(DisneySheen),
    DisneyClearcoat(DisneyClearcoat),
    Fourier(FourierBsdf<'a>),
    SwAdapter(SwAdapter),
    Hair(HairBsdf),
}

// ---------------------------------------------------------- local-frame trigonometry

#[inline]
pub fn cos_theta(w: Vec3) -> f32 {
    w.z
}
#[inline]
pub fn cos2_theta(w: Vec3) -> f32 {
    w.z * w.z
}
#[inline]
pub fn abs_cos_theta(w: Vec3) -> f32 {
    w.z.abs()
}
#[inline]
pub fn sin2_theta(w: Vec3) -> f32 {
    (1.0 - cos2_theta(w)).max(0.0)
}
#[inline]
pub fn sin_theta(w: Vec3) -> f32 {
    sin2_theta(w).sqrt()
}
#[inline]
pub fn tan_theta(w: Vec3) -> f32 {
    sin_theta(w) / cos_theta(w)
}
#[inline]
pub fn tan2_theta(w: Vec3) -> f32 {
    sin2_theta(w) / cos2_theta(w)
}
#[inline]
pub fn cos_phi(w: Vec3) -> f32 {
    let s = sin_theta(w);
    if s == 0.0 {
        1.0
    } else {
        (w.x / s).clamp(-1.0, 1.0)
    }
}
#[inline]
pub fn sin_phi(w: Vec3) -> f32 {
    let s = sin_theta(w);
    if s == 0.0 {
        0.0
    } else {
        (w.y / s).clamp(-1.0, 1.0)
    }
}
#[inline]
pub fn cos2_phi(w: Vec3) -> f32 {
    cos_phi(w) * cos_phi(w)
}
#[inline]
pub fn sin2_phi(w: Vec3) -> f32 {
    sin_phi(w) * sin_phi(w)
}
#[inline]
pub fn same_hemisphere(w: Vec3, wp: Vec3) -> bool {
    w.z * wp.z > 0.0
}
/// Mirror direction of `wo` about `n`.
#[inline]
pub fn reflect(wo: Vec3, n: Vec3) -> Vec3 {
    -wo + 2.0 * wo.dot(n) * n
}
