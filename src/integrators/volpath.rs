//! The volumetric path tracer: pbrt-v3's `VolPathIntegrator`
//! (src/integrators/volpath.cpp) with the MIS structure of pbrs's `path`:
//! `path`'s per-vertex step ([`super::path::path_step`]) over the ray's
//! medium ([`RayMedium`]), which this file samples and tracks.
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

use super::batch::{trace_paths, Batch};
use super::common::light_sampler;
use super::path::{path_li, PathMedium, PathParams, PathState, Segment};
use super::{Integrate, IntegratorKind, IntegratorSettings, Scratch, MAX_PASS_THROUGH};
use crate::accel::{Hit, SurfaceHit};
use crate::geometry::{offset_ray_origin, spawn_ray, Ray, RayDiff, SHADOW_EPSILON};
use crate::lights::LightSampler;
use crate::samplers::Sampler;
use crate::integrators::RenderScene;
use crate::scene::kind::Support;
use crate::scene::ParamSpec;
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

/// The runtime `volpath`: its settings and its light distribution.
pub struct VolPath {
    settings: VolPathSettings,
    lights: LightSampler,
}

impl VolPath {
    pub fn new(settings: &VolPathSettings, scene: &RenderScene, _scalar: bool) -> VolPath {
        VolPath {
            settings: *settings,
            lights: light_sampler(settings.light_sample_strategy, scene),
        }
    }
}

/// The medium of the camera's rays: the camera's, if the scene has media.
#[inline]
fn camera_medium(scene: &RenderScene) -> RayMedium {
    RayMedium(if scene.media.is_empty() {
        None
    } else {
        scene.camera_medium
    })
}

impl Integrate for VolPath {
    fn light_sampler(&self) -> Option<&LightSampler> {
        Some(&self.lights)
    }

    #[inline]
    fn li(
        &self,
        ray: Ray,
        time: f32,
        diff: Option<RayDiff>,
        scene: &RenderScene,
        sampler: &mut Sampler,
        scratch: &mut Scratch,
    ) -> Vec3 {
        let p = PathParams::new::<RayMedium>(scene, time, &self.settings, &self.lights);
        path_li(ray, camera_medium(scene), diff, &p, sampler, scratch)
    }

    fn batch(&self, lanes: usize, sampler: &Sampler) -> Batch {
        let mut b = Batch::new(lanes, sampler);
        let ray = Ray::new(Vec3::ZERO, Vec3::Z);
        b.vol_paths = vec![PathState::new(ray, None, RayMedium(None)); lanes];
        b
    }

    /// All of the batch's paths one vertex at a time, as `path`'s.
    fn li_batch(&self, b: &mut Batch, scene: &RenderScene, scratch: &mut Scratch) {
        let mut states = std::mem::take(&mut b.vol_paths);
        let start = camera_medium(scene);
        trace_paths(b, &mut states, start, &self.settings, &self.lights, scene, scratch);
        b.vol_paths = states;
    }
}

/// The medium a `volpath` ray is in (an index into the scene's media; none
/// for vacuum, and always none in a scene without media).
#[derive(Clone, Copy, Debug)]
pub(crate) struct RayMedium(Option<u32>);

impl PathMedium for RayMedium {
    const MEDIA: bool = true;

    /// pbrt-v3's `Medium::Sample` over the segment up to the hit.
    #[inline(always)]
    fn sample_segment(
        self,
        p: &PathParams,
        ray: &Ray,
        hit: &Option<Hit>,
        beta: &mut Vec3,
        sampler: &mut Sampler,
    ) -> Segment {
        let Some(m) = self.0 else {
            return Segment::Hit;
        };
        let med = &p.scene.media[m as usize];
        let segment = Ray {
            t_max: hit.map_or(f32::INFINITY, |h| h.t),
            ..*ray
        };
        let (w, scattered) = med.sample(&segment, sampler);
        *beta *= w;
        if *beta == Vec3::ZERO {
            return Segment::Absorbed;
        }
        match scattered {
            Some(t) => Segment::Scatters(t, med.phase),
            None => Segment::Hit,
        }
    }

    #[inline(always)]
    fn after(self, p: &PathParams, s: &SurfaceHit, w: Vec3) -> RayMedium {
        if p.media_on {
            RayMedium(medium_after(p.scene, s, w, self.0))
        } else {
            RayMedium(None)
        }
    }

    #[inline(always)]
    fn after_exit(p: &PathParams, s: &SurfaceHit, w: Vec3) -> RayMedium {
        RayMedium(None).after(p, s, w)
    }

    /// pbrt-v3's `VisibilityTester::Tr` ([`transmittance`]).
    #[inline(always)]
    fn shadow_tr(
        self,
        scene: &RenderScene,
        shadow: &Ray,
        time: f32,
        f: Vec3,
        sampler: &mut Sampler,
        scratch: &mut Scratch,
    ) -> Option<Vec3> {
        let tr = transmittance(scene, shadow, time, self.0, sampler, scratch);
        (tr != Vec3::ZERO).then(|| f * tr)
    }
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
        if scene.aggregate.occluded_at(shadow, time) {
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
        let Some(hit) = scene.aggregate.intersect_at(&ray, time) else {
            if let Some(m) = medium {
                tr *= scene.media[m as usize].tr(&ray, sampler);
            }
            return tr;
        };
        let s = scene.aggregate.surface_at(&hit, time);
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

