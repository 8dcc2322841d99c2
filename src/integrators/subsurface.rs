//! pbrt-v3's subsurface step, shared by `path` and `volpath`: after a
//! BSDF sample that transmits into a material with a BSSRDF, an exit point
//! is found by probe rays and the path continues from it.

use super::Scratch;
use crate::accel::{Hit, SurfaceHit};
use crate::bssrdf::probe::{find_exit, pdf_sp, probe_segment};
use crate::bxdf::SwAdapter;
use crate::geometry::Frame;
use crate::integrators::RenderScene;
use crate::materials::{Bsdf, BsdfSample, BxdfFlags, Material, ShadingContext};
use crate::samplers::Sampler;
use crate::shapes::DiffGeom;
use glam::Vec3;

/// pbrt-v3's BSSRDF step (`SeparableBSSRDF::Sample_S`), taken by `path`
/// and `volpath` after a BSDF sample that transmits through the boundary
/// of a subsurface material at `s` (with shading frame `frame`): samples an
/// exit point by a probe ray, and returns it with the weight Sp / pdf and
/// the BSDF there (the Sw adapter lobe, wo along the exit's shading
/// normal). `None` ends the path (no profile, no exit found, zero weight),
/// as pbrt-v3's `break`.
#[inline(never)]
#[allow(clippy::too_many_arguments)]
pub(super) fn subsurface_exit<'a>(
    scene: &RenderScene,
    hit: &Hit,
    s: &SurfaceHit,
    material: &Material,
    frame: &Frame,
    time: f32,
    sampler: &mut Sampler,
    scratch: &mut Scratch,
) -> Option<(SurfaceHit, Vec3, Bsdf<'a>)> {
    let u1 = sampler.get_1d();
    let u2 = sampler.get_2d();
    let geom = if scene.material_needs_geom[s.material as usize] {
        scene.aggregate.diff_geom(hit, s)
    } else {
        DiffGeom::ZERO
    };
    let b = material.bssrdf(&ShadingContext {
        hit: s,
        geom: &geom,
    })?;
    let seg = probe_segment(&b, s.point.p, frame, u1, u2)?;
    let (pi, found) = find_exit(
        &scene.aggregate,
        &seg,
        s.material,
        time,
        &mut scratch.counts.closest,
    )?;
    let sp = b.sr((s.point.p - pi.point.p).length());
    let pdf = pdf_sp(&b, s.point.p, frame, pi.point.p, pi.point.n) / found as f32;
    if sp == Vec3::ZERO || pdf.is_nan() || pdf <= 0.0 {
        return None;
    }
    let mut bsdf = Bsdf::new(Frame::from_normal(pi.point.ns), pi.point.n, b.eta);
    bsdf.add(SwAdapter {
        eta: b.eta,
        radiance: true,
    });
    Some((pi, sp / pdf, bsdf))
}

/// The continuation from a BSSRDF exit point `pi`: a sample of its Sw lobe
/// `exit` (wo along the exit's shading normal); `None` ends the path (no
/// sample, zero value or density), as in pbrt-v3.
#[inline]
pub(super) fn sample_exit(
    pi: &SurfaceHit,
    exit: &Bsdf,
    sampler: &mut Sampler,
) -> Option<BsdfSample> {
    let bs = exit.sample(pi.point.ns, sampler.get_2d(), BxdfFlags::ALL)?;
    (bs.f != Vec3::ZERO && bs.pdf != 0.0).then_some(bs)
}
