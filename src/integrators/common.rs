//! What the integrators share, written once: shading a hit, emission
//! (with and without MIS weights), building the light distribution,
//! choosing and sampling a light (the light strategy of MIS, for a BSDF or
//! a phase function, with shadow rays blocked by surfaces or attenuated by
//! media), the BSDF strategy's weight, pbrt-v3's Russian roulette and its
//! `etaScale`.

use super::Scratch;
use crate::accel::{Hit, SurfaceHit};
use crate::geometry::{Ray, RayDiff};
use crate::integrators::RenderScene;
use crate::lights::{LightSampler, LightSamplerKind};
use crate::materials::{Bsdf, BsdfContext, BsdfSample, BxdfFlags, Material, ShadingContext};
use crate::media::HenyeyGreenstein;
use crate::samplers::Sampler;
use crate::sampling::power_heuristic;
use crate::scene::LightSampleStrategy;
use crate::shapes::{DiffGeom, SurfacePoint};
use glam::{Vec2, Vec3};
use std::cell::Cell;

/// The differential geometry of `hit` at `s`, with the screen-space
/// derivatives of ray differentials `d`.
#[inline]
pub(super) fn with_diff(scene: &RenderScene, hit: &Hit, s: &SurfaceHit, d: &RayDiff) -> DiffGeom {
    let mut g = scene.aggregate.diff_geom(hit, s);
    g.compute_differentials(s.point.p, s.point.n, d);
    g
}

/// The BSDF of `material` at a hit, built into `bsdf`, with the hit's
/// differential geometry (and its screen-space derivatives when the ray
/// has differentials) computed only if the material uses it.
#[inline(always)]
pub(super) fn shade<'a>(
    scene: &'a RenderScene,
    hit: &Hit,
    s: &mut SurfaceHit,
    material: &'a Material,
    multiple_lobes: bool,
    diff: Option<&RayDiff>,
    bsdf: &mut Bsdf<'a>,
) {
    let geom = match diff {
        Some(d) if scene.material_needs_geom[s.material as usize] => {
            let mut g = scene.aggregate.diff_geom(hit, s);
            g.compute_differentials(s.point.p, s.point.n, d);
            Some(g)
        }
        _ => None,
    };
    shade_geom(scene, hit, s, material, multiple_lobes, geom.as_ref(), bsdf);
}

/// `shade` with the hit's differential geometry, if already computed. The
/// hit's shading normal becomes the BSDF's (a bump map changes it; pbrt-v3's
/// integrators then use the bumped `shading.n`).
#[inline(always)]
pub(super) fn shade_geom<'a>(
    scene: &'a RenderScene,
    hit: &Hit,
    s: &mut SurfaceHit,
    material: &'a Material,
    multiple_lobes: bool,
    geom: Option<&DiffGeom>,
    bsdf: &mut Bsdf<'a>,
) {
    let ctx = BsdfContext {
        materials: &scene.materials,
        multiple_lobes,
    };
    let needs_geom = scene.material_needs_geom[s.material as usize];
    if let Some(geom) = geom.filter(|_| needs_geom) {
        material.bsdf_into(&ShadingContext { hit: s, geom }, &ctx, bsdf);
    } else if needs_geom {
        let geom = scene.aggregate.diff_geom(hit, s);
        material.bsdf_into(
            &ShadingContext {
                hit: s,
                geom: &geom,
            },
            &ctx,
            bsdf,
        );
    } else {
        let sc = ShadingContext {
            hit: s,
            geom: &DiffGeom::ZERO,
        };
        material.bsdf_into(&sc, &ctx, bsdf);
    }
    s.point.ns = bsdf.frame.n;
}

/// Emission of the surface towards `wo` (zero unless it is an area light).
#[inline]
pub(super) fn emitted(scene: &RenderScene, s: &SurfaceHit, wo: Vec3) -> Vec3 {
    match s.light {
        Some(i) => scene.lights[i as usize].emitted(s.point.n, wo),
        None => Vec3::ZERO,
    }
}

/// Radiance of rays with direction `d` that leave the scene.
#[inline]
pub(super) fn escaped(scene: &RenderScene, d: Vec3) -> Vec3 {
    scene
        .infinite_lights
        .iter()
        .map(|&i| scene.lights[i as usize].le(d))
        .sum()
}

/// Adds to `l` the radiance of the infinite lights along an escaped ray
/// `d`, times the path throughput `beta`, each weighted against next-event
/// estimation from `from` (the last scattering vertex, `None` after a
/// specular bounce or for the camera ray: weight 1), whose sampled direction
/// had density `pdf`.
#[inline]
pub(super) fn add_escaped_mis(
    l: &mut Vec3,
    scene: &RenderScene,
    lights: &LightSampler,
    beta: Vec3,
    from: Option<&SurfacePoint>,
    d: Vec3,
    pdf: f32,
) {
    for &i in &scene.infinite_lights {
        let le = scene.lights[i as usize].le(d);
        let w = match from {
            Some(r) => bsdf_mis_weight(scene, lights, r, i, d, pdf),
            None => 1.0,
        };
        *l += beta * le * w;
    }
}

/// Emission of the area light at `s` (if any) towards the ray's origin
/// along `d`, times `beta`, weighted as in [`add_escaped_mis`].
#[inline]
#[allow(clippy::too_many_arguments)]
pub(super) fn emitted_mis(
    scene: &RenderScene,
    lights: &LightSampler,
    beta: Vec3,
    s: &SurfaceHit,
    from: Option<&SurfacePoint>,
    d: Vec3,
    pdf: f32,
) -> Vec3 {
    let Some(light_index) = s.light else {
        return Vec3::ZERO;
    };
    let le = scene.lights[light_index as usize].emitted(s.point.n, -d);
    if le == Vec3::ZERO {
        return Vec3::ZERO;
    }
    let w = match from {
        Some(r) => bsdf_mis_weight(scene, lights, r, light_index, d, pdf),
        None => 1.0,
    };
    beta * le * w
}

/// The factor of pbrt-v3's `etaScale` for a sampled direction: η² or 1/η²
/// through a specular transmission (by the side `wo` is on), else 1.
#[inline]
pub(super) fn eta_scale_change(bsdf: &Bsdf, bs: &BsdfSample, wo: Vec3, n: Vec3) -> f32 {
    if bs.is_specular() && bs.is_transmission() {
        let eta2 = bsdf.eta * bsdf.eta;
        if wo.dot(n) > 0.0 {
            eta2
        } else {
            1.0 / eta2
        }
    } else {
        1.0
    }
}

/// pbrt-v3's Russian roulette after bounce 3 on max(β·etaScale): true if
/// the path ends (else β is divided by the survival probability).
#[inline]
pub(super) fn roulette(
    beta: &mut Vec3,
    eta_scale: f32,
    rr_threshold: f32,
    bounces: u32,
    sampler: &mut Sampler,
) -> bool {
    let rr = (*beta * eta_scale).max_element();
    if rr < rr_threshold && bounces > 3 {
        let q = (1.0 - rr).max(0.05);
        if sampler.get_1d() < q {
            return true;
        }
        *beta /= 1.0 - q;
    }
    false
}

/// Power-heuristic weight of emission from light `light` reached by a BSDF
/// sample in direction `wi` (density `bsdf_pdf`) from `r`, against
/// next-event estimation at `r` choosing that light and sampling `wi`.
#[inline(never)]
pub(super) fn bsdf_mis_weight(
    scene: &RenderScene,
    lights: &LightSampler,
    r: &SurfacePoint,
    light: u32,
    wi: Vec3,
    bsdf_pdf: f32,
) -> f32 {
    // The context of the vertex the BSDF sample left (pbrt-v4's
    // PMF(prevIntrCtx, light)).
    let pmf = lights.pmf(r.p, r.n, light, &scene.lights, &scene.aggregate);
    if pmf == 0.0 {
        return 1.0;
    }
    let light_pdf = pmf * scene.lights[light as usize].pdf_li(r, wi, &scene.aggregate);
    power_heuristic(1, bsdf_pdf, 1, light_pdf)
}

/// Whether [`choose_light`] draws the light's 2D sample before choosing
/// the light (`path`, `volpath`: drawn even when no light is chosen) or
/// after (pbrt-v3's UniformSampleOneLight).
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum LightSampleFirst {
    Yes,
    No,
}

/// The light choice of next-event estimation at `point`: none without
/// lights; else one 1D sample chooses a light by `lights`, and the light's
/// 2D sample is drawn before or after the choice as `first` says. The
/// light, its probability and its 2D sample; `None` when no light is
/// chosen.
#[inline(always)]
pub(super) fn choose_light(
    scene: &RenderScene,
    point: &SurfacePoint,
    sampler: &mut Sampler,
    lights: &LightSampler,
    first: LightSampleFirst,
) -> Option<(u32, f32, Vec2)> {
    if scene.lights.is_empty() {
        return None;
    }
    let u = sampler.get_1d();
    let early = (first == LightSampleFirst::Yes).then(|| sampler.get_2d());
    let (light, pmf) = lights.sample(point.p, point.n, u, &scene.lights, &scene.aggregate)?;
    let u_light = match early {
        Some(u_light) => u_light,
        None => sampler.get_2d(),
    };
    Some((light, pmf, u_light))
}

/// What scatters light at a vertex, as the light strategy of MIS reads it:
/// the value (with the cosine, for a surface) and the density of
/// scattering from `wi` to `wo`.
pub(super) trait Scatter {
    /// The value and density; the density is read only where the value is
    /// not zero.
    fn f_pdf(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32);
}

/// A surface's BSDF, restricted to the lobes `flags`, with the shading
/// normal `ns` for the cosine.
pub(super) struct SurfaceScatter<'b, 'a> {
    pub bsdf: &'b Bsdf<'a>,
    pub ns: Vec3,
    pub flags: BxdfFlags,
}

impl Scatter for SurfaceScatter<'_, '_> {
    #[inline(always)]
    fn f_pdf(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        // No lobe on `wi`'s side (light behind a reflecting surface): the
        // value is zero without evaluating the lobes.
        let (f, pdf) = if self.bsdf.reaches(wo, wi, self.flags) {
            self.bsdf.f_pdf(wo, wi, self.flags)
        } else {
            (Vec3::ZERO, 0.0)
        };
        (f * wi.dot(self.ns).abs(), pdf)
    }
}

/// A medium's phase function (its value is its density).
impl Scatter for HenyeyGreenstein {
    #[inline(always)]
    fn f_pdf(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        let p = self.p(wo, wi);
        (Vec3::splat(p), p)
    }
}

/// How light reaches a vertex along a shadow ray: blocked by any surface
/// ([`Unoccluded`]: `path`, `directlighting`), or attenuated by media and
/// passing through material-less surfaces (`volpath`).
pub(super) trait ShadowRay {
    /// `f` times the transmittance along `shadow` (leaving the vertex in
    /// direction `wi`), traced and counted; `None` when it is blocked.
    #[allow(clippy::too_many_arguments)]
    fn through(
        &self,
        scene: &RenderScene,
        shadow: &Ray,
        time: f32,
        wi: Vec3,
        f: Vec3,
        sampler: &mut Sampler,
        scratch: &mut Scratch,
    ) -> Option<Vec3>;
}

/// A shadow ray that any surface blocks (pbrt-v3's `Unoccluded`).
#[derive(Clone, Copy)]
pub(super) struct Unoccluded;

impl ShadowRay for Unoccluded {
    #[inline(always)]
    fn through(
        &self,
        scene: &RenderScene,
        shadow: &Ray,
        time: f32,
        _wi: Vec3,
        f: Vec3,
        _sampler: &mut Sampler,
        scratch: &mut Scratch,
    ) -> Option<Vec3> {
        scratch.counts.shadow += 1;
        (!scene.aggregate.occluded_at(shadow, time)).then_some(f)
    }
}

/// A shadow ray that is not traced here: it is written to `ray` and
/// `kept` is set, and the sample's value is what it is if nothing blocks
/// the ray (the caller traces it, side by side with others, and keeps the
/// value only if it is clear).
#[derive(Clone, Copy)]
pub(super) struct KeepShadow<'c> {
    pub(super) ray: &'c Cell<Ray>,
    pub(super) kept: &'c Cell<bool>,
}

impl ShadowRay for KeepShadow<'_> {
    #[inline(always)]
    fn through(
        &self,
        _: &RenderScene,
        shadow: &Ray,
        _: f32,
        _: Vec3,
        f: Vec3,
        _: &mut Sampler,
        _: &mut Scratch,
    ) -> Option<Vec3> {
        self.ray.set(*shadow);
        self.kept.set(true);
        Some(f)
    }
}

/// Next-event estimation of `path` and `volpath` at `point` (a surface or
/// a medium point) at scene time `time`: choose a light, sample it, trace
/// the shadow ray, weight against the scattering strategy (whose sample is
/// the path's continuation, see `path_li`).
#[allow(clippy::too_many_arguments)]
#[inline]
pub(super) fn sample_light_mis(
    scene: &RenderScene,
    point: &SurfacePoint,
    time: f32,
    scatter: &impl Scatter,
    wo: Vec3,
    shadow: impl ShadowRay,
    sampler: &mut Sampler,
    scratch: &mut Scratch,
    lights: &LightSampler,
) -> Vec3 {
    let Some((light_index, pmf, u_light)) =
        choose_light(scene, point, sampler, lights, LightSampleFirst::Yes)
    else {
        return Vec3::ZERO;
    };
    light_strategy(
        scene,
        point,
        time,
        scatter,
        wo,
        light_index,
        u_light,
        pmf,
        shadow,
        sampler,
        scratch,
    )
}

/// The light-sampling strategy of MIS at `point`: sample light
/// `light_index`, trace the shadow ray, and weight the sample by the power
/// heuristic against the scattering density. `pmf` is the light's
/// selection probability as the weights should see it: the path tracer's
/// weights include it; pbrt-v3's EstimateDirect passes 1 and divides by the
/// selection probability afterwards. `scatter`: the strategy it is weighted
/// against (all of a BSDF's lobes for the path tracer, whose continuation
/// is that strategy; the non-specular ones for EstimateDirect, as pbrt-v3;
/// a phase function).
#[allow(clippy::too_many_arguments)]
#[inline]
pub(super) fn light_strategy(
    scene: &RenderScene,
    point: &SurfacePoint,
    time: f32,
    scatter: &impl Scatter,
    wo: Vec3,
    light_index: u32,
    u_light: Vec2,
    pmf: f32,
    shadow: impl ShadowRay,
    sampler: &mut Sampler,
    scratch: &mut Scratch,
) -> Vec3 {
    let light = &scene.lights[light_index as usize];
    // Read in place: moved out of the option, the sample was copied by
    // wide loads that stalled on the narrower stores that had just made it.
    let sample = light.sample_li(point, u_light, &scene.aggregate);
    let Some(ls) = sample.as_ref() else {
        return Vec3::ZERO;
    };
    if ls.pdf.is_nan() || ls.pdf <= 0.0 || ls.li == Vec3::ZERO {
        return Vec3::ZERO;
    }
    let (f, scattering_pdf) = scatter.f_pdf(wo, ls.wi);
    if f == Vec3::ZERO {
        return Vec3::ZERO;
    }
    let Some(f) = shadow.through(scene, &ls.shadow, time, ls.wi, f, sampler, scratch) else {
        return Vec3::ZERO;
    };
    let light_pdf = pmf * ls.pdf;
    if light.is_delta() {
        return f * ls.li / light_pdf;
    }
    f * ls.li * power_heuristic(1, light_pdf, 1, scattering_pdf) / light_pdf
}

/// The radiance of light `light_index` along `ray` (direction `wi`, at
/// scene time `time`): its emission if the ray's first hit is on it, its
/// radiance towards `wi` if the ray escapes (the BSDF strategy of pbrt-v3's
/// EstimateDirect, scalar and four-lane). The ray is traced and counted.
#[inline(always)]
pub(super) fn light_along(
    scene: &RenderScene,
    ray: &Ray,
    wi: Vec3,
    time: f32,
    light_index: u32,
    scratch: &mut Scratch,
) -> Vec3 {
    scratch.counts.closest += 1;
    let light = &scene.lights[light_index as usize];
    match scene.aggregate.intersect_at(ray, time) {
        Some(h) => {
            let hs = scene.aggregate.surface_at(&h, time);
            if hs.light == Some(light_index) {
                light.emitted(hs.point.n, -wi)
            } else {
                Vec3::ZERO
            }
        }
        None => light.le(wi),
    }
}

/// The light distribution a `lightsamplestrategy` names, built over the
/// scene's lights.
pub(super) fn light_sampler(strategy: LightSampleStrategy, scene: &RenderScene) -> LightSampler {
    let kind = match strategy {
        LightSampleStrategy::Uniform => LightSamplerKind::Uniform,
        LightSampleStrategy::Power => LightSamplerKind::Power,
        LightSampleStrategy::Spatial => LightSamplerKind::Spatial,
        LightSampleStrategy::Bvh => LightSamplerKind::Bvh,
    };
    LightSampler::new(kind, &scene.lights, &scene.aggregate)
}
