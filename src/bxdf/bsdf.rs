//! The BSDF at a surface point: up to [`MAX_BXDFS`] lobes in the shading
//! frame, plus the geometric normal that decides reflection versus
//! transmission (pbrt-v3's `BSDF`). Lobe choice, densities and values follow
//! pbrt-v3's `BSDF::Sample_f`, `f` and `Pdf` exactly: a lobe is chosen
//! uniformly among those matching the flags, and for a non-specular sample
//! the density is the average of the matching lobes' densities and the value
//! their sum.

use super::{Bxdf, BxdfFlags, BxdfModel};
use crate::geometry::Frame;
use crate::sampling::ONE_MINUS_EPSILON;
use arrayvec::ArrayVec;
use glam::{Vec2, Vec3};

/// Lobes per BSDF (pbrt-v3's `MaxBxDFs`). Materials check at load time that
/// they stay within it (a `mix` adds the lobes of both its materials).
pub const MAX_BXDFS: usize = 8;

/// One lobe with its weight (pbrt-v3's `ScaledBxDF` when not one).
#[derive(Clone, Copy, Debug)]
pub struct Lobe<'a> {
    pub bxdf: Bxdf<'a>,
    pub scale: Vec3,
    /// `bxdf.flags()`, cached.
    pub flags: BxdfFlags,
}

/// A sampled incident direction (world space).
#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    /// BSDF value (not multiplied by the cosine).
    pub f: Vec3,
    pub wi: Vec3,
    pub pdf: f32,
    /// The lobe type that was sampled.
    pub flags: BxdfFlags,
}

impl BsdfSample {
    #[inline]
    pub fn is_specular(&self) -> bool {
        self.flags.is_specular()
    }
    #[inline]
    pub fn is_transmission(&self) -> bool {
        self.flags.is_transmission()
    }
}

/// `'a`: the lifetime of the material the lobes may refer to.
#[derive(Clone, Debug)]
pub struct Bsdf<'a> {
    pub frame: Frame,
    pub ng: Vec3,
    /// Relative index of refraction (1 for opaque materials), for the path
    /// tracer's Russian roulette (pbrt-v3's `BSDF::eta`).
    pub eta: f32,
    lobes: ArrayVec<Lobe<'a>, MAX_BXDFS>,
}

impl<'a> Bsdf<'a> {
    #[inline]
    pub fn new(frame: Frame, ng: Vec3, eta: f32) -> Bsdf<'a> {
        Bsdf {
            frame,
            ng,
            eta,
            lobes: ArrayVec::new(),
        }
    }

    /// A BSDF with no lobes and a z-up frame, to be [`Bsdf::reset`].
    #[inline]
    pub fn empty() -> Bsdf<'a> {
        let mut b = std::mem::MaybeUninit::uninit();
        // SAFETY: `write_empty` writes every field.
        unsafe {
            Self::write_empty(b.as_mut_ptr());
            b.assume_init()
        }
    }

    /// Writes [`Bsdf::empty`] into `dst` one field at a time, so that a
    /// vertex that holds one need not assemble it on the stack and copy it
    /// (a copy whose wide loads span the narrow stores that built it
    /// stalls on store forwarding).
    ///
    /// # Safety
    /// `dst` must be valid for writes and aligned; what it held is
    /// overwritten without being dropped.
    #[inline(always)]
    pub unsafe fn write_empty(dst: *mut Bsdf<'a>) {
        use std::ptr::addr_of_mut;
        // SAFETY: the caller's contract; each field is written once.
        unsafe {
            addr_of_mut!((*dst).frame.s).write(Vec3::X);
            addr_of_mut!((*dst).frame.t).write(Vec3::Y);
            addr_of_mut!((*dst).frame.n).write(Vec3::Z);
            addr_of_mut!((*dst).ng).write(Vec3::Z);
            addr_of_mut!((*dst).eta).write(1.0);
            addr_of_mut!((*dst).lobes).write(ArrayVec::new());
        }
    }

    /// Empties the BSDF for a new hit (eta 1).
    #[inline]
    pub fn reset(&mut self, frame: Frame, ng: Vec3) {
        self.frame = frame;
        self.ng = ng;
        self.eta = 1.0;
        self.lobes.clear();
    }

    /// Adds a lobe (pbrt-v3's `BSDF::Add`). Beyond [`MAX_BXDFS`] lobes are
    /// dropped; materials are checked at load time never to get there.
    #[inline]
    pub fn add(&mut self, b: impl Into<Bxdf<'a>>) {
        self.add_scaled(b, Vec3::ONE);
    }

    #[inline]
    pub fn add_scaled(&mut self, b: impl Into<Bxdf<'a>>, scale: Vec3) {
        if self.lobes.is_full() {
            return;
        }
        let len = self.lobes.len();
        let bxdf = b.into();
        let flags = bxdf.flags();
        // The lobe's fields are written straight into its slot: a lobe
        // built on the stack and pushed was copied with wide loads that
        // stalled on the narrower stores that had just built it (store
        // forwarding fails), at every shaded vertex.
        // SAFETY: the array is not full, so slot `len` is inside the
        // array; its three fields are written before the length covers
        // it, and `Lobe` has no other fields.
        unsafe {
            let slot = self.lobes.as_mut_ptr().add(len);
            std::ptr::addr_of_mut!((*slot).bxdf).write(bxdf);
            std::ptr::addr_of_mut!((*slot).scale).write(scale);
            std::ptr::addr_of_mut!((*slot).flags).write(flags);
            self.lobes.set_len(len + 1);
        }
    }

    /// Multiplies the weights of lobes `from..` by `s` (for `mix`).
    #[inline]
    pub fn scale_from(&mut self, from: usize, s: Vec3) {
        for l in self.lobes.iter_mut().skip(from) {
            l.scale *= s;
        }
    }

    #[inline]
    pub fn lobes(&self) -> &[Lobe<'a>] {
        &self.lobes
    }

    /// pbrt-v3's `NumComponents(flags)`.
    #[inline]
    pub fn num_components(&self, flags: BxdfFlags) -> usize {
        self.lobes.iter().filter(|l| l.flags.matches(flags)).count()
    }

    /// Whether `num_components(flags) > 0`, stopping at the first lobe that
    /// matches.
    #[inline]
    pub fn has_component(&self, flags: BxdfFlags) -> bool {
        self.lobes.iter().any(|l| l.flags.matches(flags))
    }

    /// True if the BSDF has a lobe that light sampling can use.
    #[inline]
    pub fn has_non_specular(&self) -> bool {
        self.lobes.iter().any(|l| !l.flags.is_specular())
    }

    /// True if the BSDF has a specular lobe.
    #[inline]
    pub fn has_specular(&self) -> bool {
        self.lobes.iter().any(|l| l.flags.is_specular())
    }

    /// True if the BSDF has no lobes at all.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.lobes.is_empty()
    }

    /// The reflectance if the BSDF is exactly one unscaled Lambertian
    /// reflection lobe (the four-lane light estimate handles those).
    #[inline]
    pub fn single_lambertian(&self) -> Option<Vec3> {
        match self.lobes.as_slice() {
            [Lobe {
                bxdf: Bxdf::LambertianReflection(l),
                scale,
                ..
            }] if *scale == Vec3::ONE => Some(l.r),
            _ => None,
        }
    }

    /// Value for a pair of world directions, summed over the lobes matching
    /// `flags` whose hemisphere (by the geometric normal) matches.
    #[inline]
    pub fn f(&self, wo_w: Vec3, wi_w: Vec3, flags: BxdfFlags) -> Vec3 {
        self.f_pdf(wo_w, wi_w, flags).0
    }

    /// Whether a lobe matching `flags` is on `wi_w`'s side of the surface
    /// (by the geometric normal, as [`Bsdf::f_pdf`] decides it): if not,
    /// `f_pdf`'s value is exactly zero.
    #[inline]
    pub fn reaches(&self, wo_w: Vec3, wi_w: Vec3, flags: BxdfFlags) -> bool {
        let reflect = wi_w.dot(self.ng) * wo_w.dot(self.ng) > 0.0;
        self.lobes.iter().any(|l| {
            l.flags.matches(flags)
                && ((reflect && l.flags.is_reflection()) || (!reflect && l.flags.is_transmission()))
        })
    }

    /// Whether every lobe matching `flags` reflects only (and one does).
    #[inline]
    pub fn reflects_only(&self, flags: BxdfFlags) -> bool {
        let mut any = false;
        for l in self.lobes.iter().filter(|l| l.flags.matches(flags)) {
            if l.flags.is_transmission() {
                return false;
            }
            any = true;
        }
        any
    }

    /// `(f, pdf)` for a pair of world directions in one pass.
    #[inline]
    pub fn f_pdf(&self, wo_w: Vec3, wi_w: Vec3, flags: BxdfFlags) -> (Vec3, f32) {
        f_pdf_of(&self.frame, self.ng, &self.lobes, wo_w, wi_w, flags)
    }

    /// The BSDF's frame and geometric normal, for callers that keep its
    /// lobes elsewhere (see [`BsdfHead`]).
    #[inline]
    pub fn head(&self) -> BsdfHead {
        BsdfHead {
            frame: self.frame,
            ng: self.ng,
        }
    }

    /// pbrt-v3's `BSDF::Pdf(wo, wi, flags)`.
    #[inline]
    pub fn pdf(&self, wo_w: Vec3, wi_w: Vec3, flags: BxdfFlags) -> f32 {
        let wo_z = wo_w.dot(self.frame.n);
        if wo_z == 0.0 || self.lobes.is_empty() {
            return 0.0;
        }
        if let [l] = self.lobes.as_slice() {
            // One lobe (the common case): the same value as the sum.
            if !l.flags.matches(flags) {
                return 0.0;
            }
            return match &l.bxdf {
                Bxdf::LambertianReflection(b) => {
                    b.pdf(cosine(wo_z), cosine(wi_w.dot(self.frame.n)))
                }
                b => b.pdf(self.frame.to_local(wo_w), self.frame.to_local(wi_w)),
            };
        }
        let (wo, wi) = (self.frame.to_local(wo_w), self.frame.to_local(wi_w));
        let mut pdf = 0.0;
        let mut matching = 0u32;
        for l in &self.lobes {
            if l.flags.matches(flags) {
                matching += 1;
                pdf += l.bxdf.pdf(wo, wi);
            }
        }
        match matching {
            0 => 0.0,
            1 => pdf,
            n => pdf / n as f32,
        }
    }

    /// Samples an incident direction (pbrt-v3's `BSDF::Sample_f`): `u.x`
    /// chooses among the lobes matching `flags` and is then remapped.
    #[inline]
    pub fn sample(&self, wo_w: Vec3, u: Vec2, flags: BxdfFlags) -> Option<BsdfSample> {
        self.sample_if(wo_w, u, flags, |_| true)
    }

    /// [`Bsdf::sample`], `None` as soon as the sampled direction (world
    /// space) is one `keep` refuses, before the lobes' values and densities
    /// there are computed.
    pub fn sample_if(
        &self,
        wo_w: Vec3,
        u: Vec2,
        flags: BxdfFlags,
        keep: impl Fn(Vec3) -> bool,
    ) -> Option<BsdfSample> {
        if let [lobe] = self.lobes.as_slice() {
            return self.sample_one(lobe, wo_w, u, flags, keep);
        }
        let matching = self.num_components(flags);
        if matching == 0 {
            return None;
        }
        let comp = ((u.x * matching as f32) as usize).min(matching - 1);
        let (index, lobe) = self
            .lobes
            .iter()
            .enumerate()
            .filter(|(_, l)| l.flags.matches(flags))
            .nth(comp)?;
        let u_remapped = if matching == 1 {
            u
        } else {
            Vec2::new(
                (u.x * matching as f32 - comp as f32).min(ONE_MINUS_EPSILON),
                u.y,
            )
        };
        let wo = self.frame.to_local(wo_w);
        if wo.z == 0.0 {
            return None;
        }
        // A non-specular lobe's value is summed again below with the
        // others' at the direction: only its density is needed here.
        let s = if lobe.flags.is_specular() {
            lobe.bxdf.sample_f(wo, u_remapped)?
        } else {
            lobe.bxdf.sample_wi(wo, u_remapped)?
        };
        if s.pdf == 0.0 || s.pdf.is_nan() {
            return None;
        }
        let wi_w = self.frame.from_local(s.wi);
        if !keep(wi_w) {
            return None;
        }
        let lobe_flags = lobe.flags;
        let mut pdf = s.pdf;
        let mut f = s.f * lobe.scale;
        if !lobe_flags.is_specular() {
            // The other lobes' densities and every lobe's value on the
            // side `wi` is on, each summed in the lobes' order; a lobe
            // that contributes both gives them from one `f_pdf` (its terms
            // computed once, the same values as `f` and `pdf`).
            let reflect = wi_w.dot(self.ng) * wo_w.dot(self.ng) > 0.0;
            f = Vec3::ZERO;
            for (i, l) in self.lobes.iter().enumerate() {
                let lf = l.flags;
                if !lf.matches(flags) {
                    continue;
                }
                let side = (reflect && lf.is_reflection()) || (!reflect && lf.is_transmission());
                if i == index {
                    if side {
                        f += l.bxdf.f(wo, s.wi) * l.scale;
                    }
                } else if side {
                    let (lobe_f, lobe_pdf) = l.bxdf.f_pdf(wo, s.wi);
                    pdf += lobe_pdf;
                    f += lobe_f * l.scale;
                } else {
                    pdf += l.bxdf.pdf(wo, s.wi);
                }
            }
        }
        if matching > 1 {
            pdf /= matching as f32;
        }
        if !f.is_finite() {
            return None;
        }
        Some(BsdfSample {
            f,
            wi: wi_w,
            pdf,
            flags: s.flags,
        })
    }

    /// `sample` for a BSDF of one lobe (the common case): no lobe choice,
    /// `u` used as it is, the value recomputed only for the hemisphere test.
    #[inline]
    fn sample_one(
        &self,
        lobe: &Lobe<'a>,
        wo_w: Vec3,
        u: Vec2,
        flags: BxdfFlags,
        keep: impl Fn(Vec3) -> bool,
    ) -> Option<BsdfSample> {
        if !lobe.flags.matches(flags) {
            return None;
        }
        let wo_z = wo_w.dot(self.frame.n);
        if wo_z == 0.0 {
            return None;
        }
        let s = match &lobe.bxdf {
            Bxdf::LambertianReflection(l) => l.sample_f(cosine(wo_z), u),
            b => b.sample_f(self.frame.to_local(wo_w), u),
        }?;
        if s.pdf == 0.0 || s.pdf.is_nan() {
            return None;
        }
        let wi_w = self.frame.from_local(s.wi);
        if !keep(wi_w) {
            return None;
        }
        let f = if lobe.flags.is_specular() {
            s.f * lobe.scale
        } else {
            let reflect = wi_w.dot(self.ng) * wo_w.dot(self.ng) > 0.0;
            if (reflect && lobe.flags.is_reflection()) || (!reflect && lobe.flags.is_transmission())
            {
                s.f * lobe.scale
            } else {
                Vec3::ZERO
            }
        };
        if !f.is_finite() {
            return None;
        }
        Some(BsdfSample {
            f,
            wi: wi_w,
            pdf: s.pdf,
            flags: s.flags,
        })
    }
}

/// A BSDF whose lobes are stored elsewhere (sppm keeps its visible points'
/// lobes packed in one array per row of pixels, not in a slot for the most
/// lobes a BSDF can have).
#[derive(Clone, Copy, Debug)]
pub struct BsdfHead {
    pub frame: Frame,
    pub ng: Vec3,
}

impl BsdfHead {
    /// [`Bsdf::f_pdf`] of the BSDF with this head and `lobes`: the same
    /// values.
    #[inline]
    pub fn f_pdf(&self, lobes: &[Lobe], wo_w: Vec3, wi_w: Vec3, flags: BxdfFlags) -> (Vec3, f32) {
        f_pdf_of(&self.frame, self.ng, lobes, wo_w, wi_w, flags)
    }
}

/// `(f, pdf)` of the BSDF with this frame, geometric normal and lobes.
#[inline(always)]
fn f_pdf_of(
    frame: &Frame,
    ng: Vec3,
    lobes: &[Lobe],
    wo_w: Vec3,
    wi_w: Vec3,
    flags: BxdfFlags,
) -> (Vec3, f32) {
    // One Lambertian reflection lobe (the common case) inline, from the
    // cosines; everything else out of line, so that callers stay small.
    let [l @ Lobe {
        bxdf: Bxdf::LambertianReflection(b),
        ..
    }] = lobes
    else {
        return f_pdf_lobes(frame, ng, lobes, wo_w, wi_w, flags);
    };
    let wo_z = wo_w.dot(frame.n);
    if wo_z == 0.0 || !l.flags.matches(flags) {
        return (Vec3::ZERO, 0.0);
    }
    let reflect = wi_w.dot(ng) * wo_w.dot(ng) > 0.0;
    let (lobe_f, lobe_pdf) = b.f_pdf(cosine(wo_z), cosine(wi_w.dot(frame.n)));
    let side = (reflect && l.flags.is_reflection()) || (!reflect && l.flags.is_transmission());
    (if side { lobe_f * l.scale } else { Vec3::ZERO }, lobe_pdf)
}

/// [`f_pdf_of`] for any lobes.
#[inline(never)]
fn f_pdf_lobes(
    frame: &Frame,
    ng: Vec3,
    lobes: &[Lobe],
    wo_w: Vec3,
    wi_w: Vec3,
    flags: BxdfFlags,
) -> (Vec3, f32) {
    let wo = frame.to_local(wo_w);
    if wo.z == 0.0 {
        return (Vec3::ZERO, 0.0);
    }
    let wi = frame.to_local(wi_w);
    let reflect = wi_w.dot(ng) * wo_w.dot(ng) > 0.0;
    if let [l] = lobes {
        // One lobe: no sums, the same values.
        if !l.flags.matches(flags) {
            return (Vec3::ZERO, 0.0);
        }
        let (lobe_f, lobe_pdf) = l.bxdf.f_pdf(wo, wi);
        let side = (reflect && l.flags.is_reflection()) || (!reflect && l.flags.is_transmission());
        return (if side { lobe_f * l.scale } else { Vec3::ZERO }, lobe_pdf);
    }
    let mut f = Vec3::ZERO;
    let mut pdf = 0.0;
    let mut matching = 0u32;
    for l in lobes {
        let lf = l.flags;
        if !lf.matches(flags) {
            continue;
        }
        matching += 1;
        let (lobe_f, lobe_pdf) = l.bxdf.f_pdf(wo, wi);
        pdf += lobe_pdf;
        if (reflect && lf.is_reflection()) || (!reflect && lf.is_transmission()) {
            f += lobe_f * l.scale;
        }
    }
    let pdf = if matching > 1 {
        pdf / matching as f32
    } else {
        pdf
    };
    (f, pdf)
}

/// A local direction standing for one whose cosine (`to_local`'s z) is
/// `z`: Lambertian reflection, the most common lobe, reads nothing else,
/// so its calls skip the rest of the local frame (and stay inline).
#[inline(always)]
fn cosine(z: f32) -> Vec3 {
    Vec3::new(0.0, 0.0, z)
}
