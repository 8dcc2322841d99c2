//! `directlighting`: pbrt-v3's DirectLightingIntegrator, direct light at
//! every vertex of the specular tree ([`super::specular`]) by strategy
//! `all` (every light, its sample counts in sampler arrays; four lights at
//! a time at Lambertian vertices when they are triangles, see
//! [`super::direct_lanes`]) or `one` (one light chosen uniformly).
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `maxdepth` | integer | 5 | maximum depth of the specular tree (≥ 0) |
//! | `strategy` | string | `all` | `all` lights at every vertex, or `one` chosen uniformly |
//! | `pixelbounds` | | | ignored, with a warning |

use super::common::{choose_light, light_strategy, LightSampleFirst};
use super::direct_lanes;
use super::{IntegratorKind, IntegratorSettings, Scratch, MAX_DEPTH, PIXEL_BOUNDS};
use crate::accel::SurfaceHit;
use crate::geometry::spawn_ray;
use crate::integrators::RenderScene;
use crate::lights::{LightSampler, TriangleLightPack};
use crate::materials::{Bsdf, BxdfFlags};
use crate::samplers::Sampler;
use crate::sampling::power_heuristic;
use crate::scene::kind::{Report, Support};
use crate::scene::{DirectStrategy, ParamSpec, ParamValues};
use glam::{Vec2, Vec3};

pub const PARAMS: &[ParamSpec] = &[
    MAX_DEPTH,
    ParamSpec::string(
        "strategy",
        "all",
        "`all`: every light at every vertex (its sample count from the light's `nsamples`); `one`: one light chosen uniformly",
    ),
    PIXEL_BOUNDS,
];

pub const KIND: IntegratorKind = IntegratorKind {
    name: "directlighting",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "direct lighting with MIS at every vertex, specular reflection and transmission followed recursively",
    build: |p, r| IntegratorSettings::DirectLighting(DirectLightingSettings::read(p, r)),
};

/// directlighting ignores participating media and subsurface scattering
/// (as pbrt-v3's).
pub const RENDERS_MEDIA: bool = false;
pub const SAMPLES_SUBSURFACE: bool = false;

/// `directlighting`'s settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectLightingSettings {
    pub max_depth: u32,
    pub strategy: DirectStrategy,
}

impl Default for DirectLightingSettings {
    fn default() -> DirectLightingSettings {
        DirectLightingSettings {
            max_depth: 5,
            strategy: DirectStrategy::All,
        }
    }
}

impl DirectLightingSettings {
    /// The settings of a statement's parameters, checked as pbrt-v3 does:
    /// an unknown strategy is a warning, and `all` is used.
    pub fn read(p: &ParamValues, r: &mut dyn Report) -> DirectLightingSettings {
        let max_depth = super::max_depth(p, r);
        let strategy = match p.string("strategy") {
            "all" => DirectStrategy::All,
            "one" => DirectStrategy::One,
            other => {
                r.warn(
                    Some("strategy"),
                    format!("unknown strategy \"{other}\": \"all\" is used (as pbrt-v3)"),
                    "expected all or one",
                );
                DirectStrategy::All
            }
        };
        DirectLightingSettings {
            max_depth,
            strategy,
        }
    }

    pub fn summary(&self) -> String {
        let DirectLightingSettings {
            max_depth,
            strategy,
        } = self;
        format!("maxdepth {max_depth}, strategy {strategy:?}").to_lowercase()
    }
}

/// How directlighting lights a vertex: its strategy, the light choice of
/// strategy `one`, the sample counts of strategy `all` and its four-lane
/// packs (empty unless every light is a triangle with one sample).
pub(super) struct Lights<'a> {
    pub strategy: DirectStrategy,
    pub lights: &'a LightSampler,
    pub n_light_samples: &'a [u32],
    pub packs: &'a [TriangleLightPack],
}

/// Adds to `local` the direct light at `s` (nothing without lights).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn add_direct(
    local: &mut Vec3,
    scene: &RenderScene,
    s: &SurfaceHit,
    bsdf: &Bsdf,
    wo: Vec3,
    sampler: &mut Sampler,
    scratch: &mut Scratch,
    how: &Lights,
) {
    if !scene.lights.is_empty() {
        *local += match (how.strategy, bsdf.single_lambertian()) {
            (DirectStrategy::All, Some(r)) if !how.packs.is_empty() => {
                direct_lanes::sample_all_lights_packed(
                    scene, s, bsdf, r, wo, sampler, scratch, how.packs,
                )
            }
            (DirectStrategy::All, _) => {
                sample_all_lights(scene, s, bsdf, wo, sampler, scratch, how.n_light_samples)
            }
            (DirectStrategy::One, _) => {
                sample_one_light(scene, s, bsdf, wo, sampler, scratch, how.lights)
            }
        };
    }
}

/// pbrt-v3's UniformSampleOneLight with a light distribution.
#[inline]
pub(super) fn sample_one_light(
    scene: &RenderScene,
    s: &SurfaceHit,
    bsdf: &Bsdf,
    wo: Vec3,
    sampler: &mut Sampler,
    scratch: &mut Scratch,
    lights: &LightSampler,
) -> Vec3 {
    let Some((light, pmf, u_light)) =
        choose_light(scene, &s.point, sampler, lights, LightSampleFirst::No)
    else {
        return Vec3::ZERO;
    };
    let u_scatter = sampler.get_2d();
    estimate_direct(scene, s, bsdf, wo, light, u_light, u_scatter, scratch) / pmf
}

/// pbrt-v3's UniformSampleAllLights with per-pixel sample arrays.
pub(super) fn sample_all_lights(
    scene: &RenderScene,
    s: &SurfaceHit,
    bsdf: &Bsdf,
    wo: Vec3,
    sampler: &mut Sampler,
    scratch: &mut Scratch,
    n_light_samples: &[u32],
) -> Vec3 {
    let mut l = Vec3::ZERO;
    let mut u_light = std::mem::take(&mut scratch.u_light);
    let mut u_scatter = std::mem::take(&mut scratch.u_scatter);
    for (j, &n) in n_light_samples.iter().enumerate() {
        let light = j as u32;
        // Both arrays are always asked for, as pbrt-v3 does.
        let got_light = sampler.fill_2d_array(n, &mut u_light);
        let got_scatter = sampler.fill_2d_array(n, &mut u_scatter);
        let ld = if got_light && got_scatter {
            let mut sum = Vec3::ZERO;
            for (&ul, &us) in u_light.iter().zip(&u_scatter) {
                sum += estimate_direct(scene, s, bsdf, wo, light, ul, us, scratch);
            }
            sum / n as f32
        } else {
            let ul = sampler.get_2d();
            let us = sampler.get_2d();
            estimate_direct(scene, s, bsdf, wo, light, ul, us, scratch)
        };
        l += ld;
    }
    scratch.u_light = u_light;
    scratch.u_scatter = u_scatter;
    l
}

/// pbrt-v3's EstimateDirect: one light sample and one BSDF sample combined
/// with the power heuristic; the BSDF sample is skipped for delta lights.
#[allow(clippy::too_many_arguments)]
#[inline]
pub(super) fn estimate_direct(
    scene: &RenderScene,
    s: &SurfaceHit,
    bsdf: &Bsdf,
    wo: Vec3,
    light_index: u32,
    u_light: Vec2,
    u_scatter: Vec2,
    scratch: &mut Scratch,
) -> Vec3 {
    let light = &scene.lights[light_index as usize];
    let geom = &scene.geometry;
    let ns = s.point.ns;
    let mut ld = light_strategy(
        scene,
        s,
        bsdf,
        wo,
        light_index,
        u_light,
        1.0,
        BxdfFlags::NON_SPECULAR,
        scratch,
    );
    if !light.is_delta() {
        if let Some(bs) = bsdf.sample(wo, u_scatter, BxdfFlags::NON_SPECULAR) {
            let f = bs.f * bs.wi.dot(ns).abs();
            if f != Vec3::ZERO && bs.pdf > 0.0 {
                let ray = spawn_ray(s.point.p, s.point.p_error, s.point.n, bs.wi);
                let light_pdf = light.pdf_li_ray(&s.point, &ray, geom);
                if light_pdf == 0.0 {
                    return ld;
                }
                let weight = power_heuristic(1, bs.pdf, 1, light_pdf);
                scratch.counts.closest += 1;
                let li = match geom.intersect_at(&ray, s.time) {
                    Some(h) => {
                        let hs = geom.surface_at(&h, s.time);
                        if hs.light == Some(light_index) {
                            light.emitted(hs.point.n, -bs.wi)
                        } else {
                            Vec3::ZERO
                        }
                    }
                    None => light.le(bs.wi),
                };
                ld += f * li * weight / bs.pdf;
            }
        }
    }
    ld
}
