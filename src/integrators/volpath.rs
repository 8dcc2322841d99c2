//! The volumetric path tracer: pbrt-v3's `VolPathIntegrator`
//! (src/integrators/volpath.cpp) with the MIS structure of pbrs's `path`.
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `maxdepth` | integer | 5 | maximum number of bounces (≥ 0) |
//! | `rrthreshold` | float | 1 | Russian roulette once max(β·etaScale) is below it (after bounce 3) |
//! | `lightsamplestrategy` | string | `spatial` | light choice: `uniform`, `power`, `spatial` or `bvh` |
//! | `pixelbounds` | | | ignored, with a warning |
//!
//! Along each segment the ray's medium (the camera's to start with; after a
//! surface, the side of the surface's `MediumInterface` the new direction
//! points to, or the same medium where the surface is no transition) is
//! sampled first (pbrt-v3's `Medium::Sample`): if the path scatters in the
//! medium, the vertex is a medium point whose phase function plays the
//! BSDF's part (next-event estimation, then a phase-function sample to
//! continue); otherwise the surface is shaded as `path` does, and
//! `Material "none"` surfaces are crossed without a bounce, changing the
//! medium. Shadow rays carry the transmittance of the media they cross and
//! pass through material-less surfaces (pbrt-v3's `VisibilityTester::Tr`).
//!
//! As in `path`, the sample that continues the path is also the BSDF (or
//! phase) strategy of MIS: emission it reaches, after any number of
//! medium-sampling steps that did not scatter (whose weights estimate the
//! transmittance) and material-less surfaces, is weighted against the
//! light strategy at the last scattering vertex. pbrt-v3 instead traces one
//! more ray per vertex for its BSDF strategy and adds emission only after
//! specular bounces; both are unbiased estimators of the same integral.

use super::common::{
    add_escaped_mis, choose_light, emitted_mis, eta_scale_change, roulette, shade, LightSampleFirst,
};
use super::subsurface::{sample_exit, subsurface_exit};
use super::{IntegratorKind, IntegratorSettings, Scratch, MAX_PASS_THROUGH};
use crate::accel::{Hit, SurfaceHit};
use crate::geometry::{offset_ray_origin, spawn_ray, Ray, RayDiff, SHADOW_EPSILON};
use crate::integrators::RenderScene;
use crate::lights::LightSampler;
use crate::materials::{Bsdf, BxdfFlags, Material};
use crate::media::HenyeyGreenstein;
use crate::samplers::Sampler;
use crate::sampling::power_heuristic;
use crate::scene::kind::Support;
use crate::scene::ParamSpec;
use crate::shapes::SurfacePoint;
use glam::Vec3;

/// The same parameters as `path`.
pub const PARAMS: &[ParamSpec] = super::path::PARAMS;

pub const KIND: IntegratorKind = IntegratorKind {
    name: "volpath",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "path tracing with participating media (see Media)",
    build: |p, r| IntegratorSettings::VolPath(VolPathSettings::read(p, r)),
};

/// `volpath` renders participating media and samples subsurface scattering.
pub const RENDERS_MEDIA: bool = true;
pub const SAMPLES_SUBSURFACE: bool = true;

/// `volpath`'s settings: `path`'s.
pub type VolPathSettings = super::path::PathSettings;

/// What scatters at a path vertex.
#[derive(Clone, Copy)]
enum Scatter<'a, 'b> {
    /// A surface's BSDF, with the shading normal for the cosine.
    Surface(&'b Bsdf<'a>, Vec3),
    /// A medium's phase function.
    Medium(HenyeyGreenstein),
}

/// The medium a ray leaving surface `s` in direction `w` is in: the side of
/// a transition `w` points to (by the geometric normal, as pbrt-v3's
/// `GetMedium`), else the medium it arrived in.
#[inline]
pub(super) fn medium_after(
    scene: &RenderScene,
    s: &SurfaceHit,
    w: Vec3,
    current: Option<u32>,
) -> Option<u32> {
    match scene
        .surface_media
        .get(s.material as usize)
        .copied()
        .flatten()
    {
        Some(m) if w.dot(s.point.n) > 0.0 => m.outside,
        Some(m) => m.inside,
        None => current,
    }
}

/// Transmittance along a shadow ray that starts in `medium`: 0 if a
/// surface with a material is in the way, else the product of the media's
/// transmittances over the segments between material-less surfaces
/// (pbrt-v3's `VisibilityTester::Tr`). Without material-less surfaces one
/// occlusion query decides, as in `path`.
pub(super) fn transmittance(
    scene: &RenderScene,
    shadow: &Ray,
    time: f32,
    medium: Option<u32>,
    sampler: &mut Sampler,
    scratch: &mut Scratch,
) -> Vec3 {
    if !scene.has_pass_through {
        scratch.counts.shadow += 1;
        if scene.geometry.occluded_at(shadow, time) {
            return Vec3::ZERO;
        }
        return match medium {
            Some(m) => scene.media[m as usize].tr(shadow, sampler),
            None => Vec3::ONE,
        };
    }
    // The far end (already off its surface) for rays to a point; rays to
    // an infinitely distant light keep their direction.
    let target = shadow.t_max.is_finite().then(|| shadow.o + shadow.d);
    let mut ray = *shadow;
    let mut medium = medium;
    let mut tr = Vec3::ONE;
    for _ in 0..=MAX_PASS_THROUGH {
        scratch.counts.shadow += 1;
        let Some(hit) = scene.geometry.intersect_at(&ray, time) else {
            if let Some(m) = medium {
                tr *= scene.media[m as usize].tr(&ray, sampler);
            }
            return tr;
        };
        let s = scene.geometry.surface_at(&hit, time);
        if !scene.materials[s.material as usize].is_none() {
            return Vec3::ZERO;
        }
        if let Some(m) = medium {
            tr *= scene.media[m as usize].tr(
                &Ray {
                    t_max: hit.t,
                    ..ray
                },
                sampler,
            );
            if tr == Vec3::ZERO {
                return tr;
            }
        }
        medium = medium_after(scene, &s, ray.d, medium);
        ray = match target {
            Some(t) => {
                let o = offset_ray_origin(s.point.p, s.point.p_error, s.point.n, t - s.point.p);
                Ray {
                    o,
                    d: t - o,
                    t_max: 1.0 - SHADOW_EPSILON,
                }
            }
            None => spawn_ray(s.point.p, s.point.p_error, s.point.n, ray.d),
        };
    }
    Vec3::ZERO
}

/// Next-event estimation at a surface or medium vertex: one light chosen
/// and sampled, its transmittance traced, weighted by the power heuristic
/// against the BSDF/phase strategy (the path's continuation).
#[allow(clippy::too_many_arguments)]
#[inline]
fn sample_light(
    scene: &RenderScene,
    point: &SurfacePoint,
    time: f32,
    scatter: Scatter,
    wo: Vec3,
    medium: impl Fn(Vec3) -> Option<u32>,
    sampler: &mut Sampler,
    scratch: &mut Scratch,
    lights: &LightSampler,
) -> Vec3 {
    let Some((light_index, pmf, u_light)) =
        choose_light(scene, point, sampler, lights, LightSampleFirst::Yes)
    else {
        return Vec3::ZERO;
    };
    let light = &scene.lights[light_index as usize];
    let Some(ls) = light.sample_li(point, u_light, &scene.geometry) else {
        return Vec3::ZERO;
    };
    if ls.pdf.is_nan() || ls.pdf <= 0.0 || ls.li == Vec3::ZERO {
        return Vec3::ZERO;
    }
    let (f, scatter_pdf) = match scatter {
        Scatter::Surface(bsdf, ns) => {
            let (f, pdf) = bsdf.f_pdf(wo, ls.wi, BxdfFlags::ALL);
            (f * ls.wi.dot(ns).abs(), pdf)
        }
        Scatter::Medium(phase) => {
            let p = phase.p(wo, ls.wi);
            (Vec3::splat(p), p)
        }
    };
    if f == Vec3::ZERO {
        return Vec3::ZERO;
    }
    let tr = transmittance(scene, &ls.shadow, time, medium(ls.wi), sampler, scratch);
    if tr == Vec3::ZERO {
        return Vec3::ZERO;
    }
    let light_pdf = pmf * ls.pdf;
    if light.is_delta() {
        return f * tr * ls.li / light_pdf;
    }
    f * tr * ls.li * power_heuristic(1, light_pdf, 1, scatter_pdf) / light_pdf
}

/// A volpath path between two vertices: what one step of the loop of
/// [`volpath_li`] carries to the next.
struct VolState {
    /// The ray to trace next, and its differentials (the camera ray's).
    ray: Ray,
    diff: Option<RayDiff>,
    /// The medium the ray is in.
    medium: Option<u32>,
    /// Radiance gathered so far.
    l: Vec3,
    beta: Vec3,
    specular_bounce: bool,
    eta_scale: f32,
    bounces: u32,
    pass: u32,
    /// The last scattering vertex (a medium point has no normal and no
    /// error bound) and the density of the direction sampled there.
    prev: Option<SurfacePoint>,
    scatter_pdf: f32,
}

impl VolState {
    fn new(ray: Ray, diff: Option<RayDiff>, medium: Option<u32>) -> VolState {
        VolState {
            ray,
            diff,
            medium,
            l: Vec3::ZERO,
            beta: Vec3::ONE,
            specular_bounce: false,
            eta_scale: 1.0,
            bounces: 0,
            pass: 0,
            prev: None,
            scatter_pdf: 0.0,
        }
    }
}

/// What every step of a `volpath` render shares.
struct VolParams<'a> {
    scene: &'a RenderScene,
    time: f32,
    max_depth: u32,
    rr_threshold: f32,
    lights: &'a LightSampler,
    /// The scene has media (else every ray's medium stays none).
    media_on: bool,
}

/// The volumetric path tracer's radiance along a camera ray.
#[allow(clippy::too_many_arguments)]
pub(super) fn volpath_li(
    ray: Ray,
    time: f32,
    diff: Option<RayDiff>,
    scene: &RenderScene,
    sampler: &mut Sampler,
    scratch: &mut Scratch,
    max_depth: u32,
    rr_threshold: f32,
    lights: &LightSampler,
) -> Vec3 {
    let media_on = !scene.media.is_empty();
    let p = VolParams {
        scene,
        time,
        max_depth,
        rr_threshold,
        lights,
        media_on,
    };
    let medium = if media_on { scene.camera_medium } else { None };
    let mut st = VolState::new(ray, diff, medium);
    let mut bsdf = Bsdf::empty();
    loop {
        scratch.counts.closest += 1;
        let hit = scene.geometry.intersect_at(&st.ray, time);
        if let Some(m) = st.medium {
            let med = &scene.media[m as usize];
            let segment = Ray {
                t_max: hit.map_or(f32::INFINITY, |h| h.t),
                ..st.ray
            };
            let (w, scattered) = med.sample(&segment, sampler);
            st.beta *= w;
            if st.beta == Vec3::ZERO {
                break;
            }
            if let Some(t) = scattered {
                let phase = med.phase;
                if scatter_in_medium(&mut st, t, phase, &p, sampler, scratch) {
                    continue;
                }
                break;
            }
        }
        let from = st.prev.filter(|_| !st.specular_bounce);
        let Some(hit) = hit else {
            add_escaped_mis(
                &mut st.l,
                scene,
                lights,
                st.beta,
                from.as_ref(),
                st.ray.d,
                st.scatter_pdf,
            );
            break;
        };
        let mut s = scene.geometry.surface_at(&hit, time);
        let wo = -st.ray.d;
        st.l += emitted_mis(
            scene,
            lights,
            st.beta,
            &s,
            from.as_ref(),
            st.ray.d,
            st.scatter_pdf,
        );
        if st.bounces >= max_depth {
            break;
        }
        let material = &scene.materials[s.material as usize];
        if material.is_none() {
            if cross_boundary(&mut st, &s, &p) {
                continue;
            }
            break;
        }
        shade(
            scene,
            &hit,
            &mut s,
            material,
            true,
            st.diff.as_ref(),
            &mut bsdf,
        );
        st.diff = None;
        if bsdf.has_non_specular() {
            let current = st.medium;
            st.l += st.beta
                * sample_light(
                    scene,
                    &s.point,
                    time,
                    Scatter::Surface(&bsdf, s.point.ns),
                    wo,
                    |wi| {
                        if media_on {
                            medium_after(scene, &s, wi, current)
                        } else {
                            None
                        }
                    },
                    sampler,
                    scratch,
                    lights,
                );
        }
        let u = sampler.get_2d();
        let Some(bs) = bsdf.sample(wo, u, BxdfFlags::ALL) else {
            break;
        };
        if bs.f == Vec3::ZERO || bs.pdf == 0.0 {
            break;
        }
        st.beta *= bs.f * bs.wi.dot(s.point.ns).abs() / bs.pdf;
        st.specular_bounce = bs.is_specular();
        st.scatter_pdf = bs.pdf;
        st.prev = Some(s.point);
        st.eta_scale *= eta_scale_change(&bsdf, &bs, wo, s.point.n);
        if media_on {
            st.medium = medium_after(scene, &s, bs.wi, st.medium);
        }
        st.ray = spawn_ray(s.point.p, s.point.p_error, s.point.n, bs.wi);
        if bs.is_transmission()
            && material.has_bssrdf()
            && !subsurface_step(&mut st, &hit, &s, material, &bsdf, &p, sampler, scratch)
        {
            break;
        }
        if roulette(
            &mut st.beta,
            st.eta_scale,
            rr_threshold,
            st.bounces,
            sampler,
        ) {
            break;
        }
        st.bounces += 1;
    }
    st.l
}

/// A surface without a material is a medium boundary only: the path
/// crosses it without a bounce, into the medium on the other side. False
/// past `MAX_PASS_THROUGH` such surfaces in a row (the path ends).
#[inline(always)]
fn cross_boundary(st: &mut VolState, s: &SurfaceHit, p: &VolParams) -> bool {
    st.pass += 1;
    if st.pass > MAX_PASS_THROUGH {
        return false;
    }
    if p.media_on {
        st.medium = medium_after(p.scene, s, st.ray.d, st.medium);
    }
    st.ray = spawn_ray(s.point.p, s.point.p_error, s.point.n, st.ray.d);
    st.diff = None;
    true
}

/// The path scatters in its medium at distance `t` along `st.ray`: a
/// medium vertex whose phase function plays the BSDF's part (next-event
/// estimation, then a phase-function sample to continue). False when the
/// path ends.
#[inline(always)]
fn scatter_in_medium(
    st: &mut VolState,
    t: f32,
    phase: HenyeyGreenstein,
    p: &VolParams,
    sampler: &mut Sampler,
    scratch: &mut Scratch,
) -> bool {
    let (scene, time, lights) = (p.scene, p.time, p.lights);
    if st.bounces >= p.max_depth {
        return false;
    }
    let point = SurfacePoint {
        p: st.ray.at(t),
        p_error: Vec3::ZERO,
        n: Vec3::ZERO,
        ns: Vec3::ZERO,
    };
    let wo = (-st.ray.d).normalize();
    st.l += st.beta
        * sample_light(
            scene,
            &point,
            time,
            Scatter::Medium(phase),
            wo,
            |_| st.medium,
            sampler,
            scratch,
            lights,
        );
    let (wi, pdf) = phase.sample(wo, sampler.get_2d());
    // The phase function's value equals its density: β stays.
    st.specular_bounce = false;
    st.scatter_pdf = pdf;
    st.prev = Some(point);
    st.ray = Ray::new(point.p, wi);
    st.diff = None;
    if roulette(
        &mut st.beta,
        st.eta_scale,
        p.rr_threshold,
        st.bounces,
        sampler,
    ) {
        return false;
    }
    st.bounces += 1;
    true
}

/// pbrt-v3's subsurface step (as in `path`) after a BSDF sample that
/// transmits into `material` at `s` (`bsdf`'s frame): continue from a
/// sampled exit point, with light sampled there (through media), not
/// counted as a bounce. As in pbrt-v3, the exit point is found by probe
/// rays that carry no medium, so unless its shape has a medium transition
/// the rays leaving it start in vacuum (pbrt-v3's
/// `GeometricPrimitive::Intersect` gives a hit of a non-transition shape
/// the probe ray's medium, none). False when the path ends.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn subsurface_step(
    st: &mut VolState,
    hit: &Hit,
    s: &SurfaceHit,
    material: &Material,
    bsdf: &Bsdf,
    p: &VolParams,
    sampler: &mut Sampler,
    scratch: &mut Scratch,
) -> bool {
    let (scene, time, lights, media_on) = (p.scene, p.time, p.lights, p.media_on);
    // pbrt-v3's subsurface step (as in `path`): continue from a
    // sampled exit point, with light sampled there (through media),
    // not counted as a bounce. As in pbrt-v3, the exit point is
    // found by probe rays that carry no medium, so unless its shape
    // has a medium transition the rays leaving it start in vacuum
    // (pbrt-v3's `GeometricPrimitive::Intersect` gives a hit of a
    // non-transition shape the probe ray's medium, none).
    let frame = bsdf.frame;
    let Some((pi, w, exit)) =
        subsurface_exit(scene, hit, s, material, &frame, time, sampler, scratch)
    else {
        return false;
    };
    st.beta *= w;
    let wo = pi.point.ns;
    st.l += st.beta
        * sample_light(
            scene,
            &pi.point,
            time,
            Scatter::Surface(&exit, pi.point.ns),
            wo,
            |wi| {
                if media_on {
                    medium_after(scene, &pi, wi, None)
                } else {
                    None
                }
            },
            sampler,
            scratch,
            lights,
        );
    let Some(bs) = sample_exit(&pi, &exit, sampler) else {
        return false;
    };
    st.beta *= bs.f * bs.wi.dot(pi.point.ns).abs() / bs.pdf;
    st.specular_bounce = false;
    st.scatter_pdf = bs.pdf;
    st.prev = Some(pi.point);
    if media_on {
        st.medium = medium_after(scene, &pi, bs.wi, None);
    }
    st.ray = spawn_ray(pi.point.p, pi.point.p_error, pi.point.n, bs.wi);
    true
}
