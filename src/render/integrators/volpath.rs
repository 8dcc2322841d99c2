//! The volumetric path tracer: pbrt-v3's `VolPathIntegrator`
//! (src/integrators/volpath.cpp) with the MIS structure of pbrs's `path`.
//!
//! Parameters (pbrt-v3's): `integer maxdepth` (5), `float rrthreshold`
//! (1), `string lightsamplestrategy` (`spatial`).
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

use super::{
    add_escaped_mis, emitted_mis, eta_scale_change, roulette, sample_exit, shade, subsurface_exit,
    Scratch, MAX_PASS_THROUGH,
};
use crate::render::accel::SurfaceHit;
use crate::render::geometry::{offset_ray_origin, spawn_ray, Ray, RayDiff, SHADOW_EPSILON};
use crate::render::lights::LightSampler;
use crate::render::materials::{Bsdf, BxdfFlags};
use crate::render::media::HenyeyGreenstein;
use crate::render::samplers::Sampler;
use crate::render::sampling::power_heuristic;
use crate::render::scene::RenderScene;
use crate::render::shapes::SurfacePoint;
use glam::Vec3;

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
    if scene.lights.is_empty() {
        return Vec3::ZERO;
    }
    let u = sampler.get_1d();
    let u_light = sampler.get_2d();
    let Some((light_index, pmf)) =
        lights.sample(point.p, point.n, u, &scene.lights, &scene.geometry)
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

/// The volumetric path tracer's radiance along a camera ray.
#[allow(clippy::too_many_arguments)]
pub(super) fn volpath_li(
    mut ray: Ray,
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
    let mut medium = if media_on { scene.camera_medium } else { None };
    let mut l = Vec3::ZERO;
    let mut bsdf = Bsdf::empty();
    let mut beta = Vec3::ONE;
    let mut diff = diff;
    let mut specular_bounce = false;
    let mut eta_scale = 1.0f32;
    let mut bounces = 0u32;
    let mut pass = 0u32;
    // The last scattering vertex (a medium point has no normal and no
    // error bound) and the density of the direction sampled there.
    let mut prev: Option<SurfacePoint> = None;
    let mut scatter_pdf = 0.0f32;
    loop {
        scratch.counts.closest += 1;
        let hit = scene.geometry.intersect_at(&ray, time);
        if let Some(m) = medium {
            let med = &scene.media[m as usize];
            let segment = Ray {
                t_max: hit.map_or(f32::INFINITY, |h| h.t),
                ..ray
            };
            let (w, scattered) = med.sample(&segment, sampler);
            beta *= w;
            if beta == Vec3::ZERO {
                break;
            }
            if let Some(t) = scattered {
                if bounces >= max_depth {
                    break;
                }
                let point = SurfacePoint {
                    p: ray.at(t),
                    p_error: Vec3::ZERO,
                    n: Vec3::ZERO,
                    ns: Vec3::ZERO,
                };
                let wo = (-ray.d).normalize();
                let phase = med.phase;
                l += beta
                    * sample_light(
                        scene,
                        &point,
                        time,
                        Scatter::Medium(phase),
                        wo,
                        |_| medium,
                        sampler,
                        scratch,
                        lights,
                    );
                let (wi, pdf) = phase.sample(wo, sampler.get_2d());
                // The phase function's value equals its density: β stays.
                specular_bounce = false;
                scatter_pdf = pdf;
                prev = Some(point);
                ray = Ray::new(point.p, wi);
                diff = None;
                if roulette(&mut beta, eta_scale, rr_threshold, bounces, sampler) {
                    break;
                }
                bounces += 1;
                continue;
            }
        }
        let from = prev.filter(|_| !specular_bounce);
        let Some(hit) = hit else {
            add_escaped_mis(
                &mut l,
                scene,
                lights,
                beta,
                from.as_ref(),
                ray.d,
                scatter_pdf,
            );
            break;
        };
        let mut s = scene.geometry.surface_at(&hit, time);
        let wo = -ray.d;
        l += emitted_mis(scene, lights, beta, &s, from.as_ref(), ray.d, scatter_pdf);
        if bounces >= max_depth {
            break;
        }
        let material = &scene.materials[s.material as usize];
        if material.is_none() {
            // A medium boundary only: cross it without a bounce.
            pass += 1;
            if pass > MAX_PASS_THROUGH {
                break;
            }
            if media_on {
                medium = medium_after(scene, &s, ray.d, medium);
            }
            ray = spawn_ray(s.point.p, s.point.p_error, s.point.n, ray.d);
            diff = None;
            continue;
        }
        shade(
            scene,
            &hit,
            &mut s,
            material,
            true,
            diff.as_ref(),
            &mut bsdf,
        );
        diff = None;
        if bsdf.has_non_specular() {
            let current = medium;
            l += beta
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
        beta *= bs.f * bs.wi.dot(s.point.ns).abs() / bs.pdf;
        specular_bounce = bs.is_specular();
        scatter_pdf = bs.pdf;
        prev = Some(s.point);
        eta_scale *= eta_scale_change(&bsdf, &bs, wo, s.point.n);
        if media_on {
            medium = medium_after(scene, &s, bs.wi, medium);
        }
        ray = spawn_ray(s.point.p, s.point.p_error, s.point.n, bs.wi);
        if bs.is_transmission() && material.has_bssrdf() {
            // pbrt-v3's subsurface step (as in `path`): continue from a
            // sampled exit point, with light sampled there (through media),
            // not counted as a bounce. As in pbrt-v3, the exit point is
            // found by probe rays that carry no medium, so unless its shape
            // has a medium transition the rays leaving it start in vacuum
            // (pbrt-v3's `GeometricPrimitive::Intersect` gives a hit of a
            // non-transition shape the probe ray's medium, none).
            let frame = bsdf.frame;
            let Some((pi, w, exit)) =
                subsurface_exit(scene, &hit, &s, material, &frame, time, sampler, scratch)
            else {
                break;
            };
            beta *= w;
            let wo = pi.point.ns;
            l += beta
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
                break;
            };
            beta *= bs.f * bs.wi.dot(pi.point.ns).abs() / bs.pdf;
            specular_bounce = false;
            scatter_pdf = bs.pdf;
            prev = Some(pi.point);
            if media_on {
                medium = medium_after(scene, &pi, bs.wi, None);
            }
            ray = spawn_ray(pi.point.p, pi.point.p_error, pi.point.n, bs.wi);
        }
        if roulette(&mut beta, eta_scale, rr_threshold, bounces, sampler) {
            break;
        }
        bounces += 1;
    }
    l
}
