//! `path`: pbrt-v3's PathIntegrator (see [`path_li`]).
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `maxdepth` | integer | 5 | maximum number of bounces (≥ 0) |
//! | `rrthreshold` | float | 1 | Russian roulette once max(β·etaScale) is below it (after bounce 3) |
//! | `lightsamplestrategy` | string | `spatial` | light choice: `uniform`, `power`, `spatial` or `bvh` |
//! | `pixelbounds` | | | ignored, with a warning |

use super::common::{
    add_escaped_mis, emitted_mis, eta_scale_change, roulette, sample_light_mis, shade,
};
use super::subsurface::{sample_exit, subsurface_exit};
use super::{IntegratorKind, IntegratorSettings, Scratch, MAX_PASS_THROUGH};
use super::{MAX_DEPTH, PIXEL_BOUNDS};
use crate::accel::Hit;
use crate::geometry::{spawn_ray, Ray, RayDiff};
use crate::integrators::RenderScene;
use crate::lights::LightSampler;
use crate::materials::{Bsdf, BxdfFlags};
use crate::samplers::Sampler;
use crate::scene::kind::{Report, Support};
use crate::scene::{LightSampleStrategy, ParamSpec, ParamValues};
use crate::shapes::SurfacePoint;
use glam::Vec3;

pub const PARAMS: &[ParamSpec] = &[
    MAX_DEPTH,
    ParamSpec::float(
        "rrthreshold",
        1.0,
        "Russian roulette once max(β·etaScale) is below it (after bounce 3)",
    ),
    LIGHT_SAMPLE_STRATEGY,
    PIXEL_BOUNDS,
];

pub const KIND: IntegratorKind = IntegratorKind {
    name: "path",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "unidirectional path tracing: next-event estimation with power-heuristic MIS, Russian roulette; no participating media",
    build: |p, r| IntegratorSettings::Path(PathSettings::read(p, r)),
};

/// `path` ignores participating media (as pbrt-v3's) and samples
/// subsurface scattering.
pub const RENDERS_MEDIA: bool = false;
pub const SAMPLES_SUBSURFACE: bool = true;

/// `lightsamplestrategy`.
const LIGHT_SAMPLE_STRATEGY: ParamSpec = ParamSpec::string(
    "lightsamplestrategy",
    "spatial",
    "how a vertex chooses the light to sample: `uniform`, `power`, `spatial` (pbrt-v3's voxel distribution) or `bvh` (a pbrs extension: pbrt-v4's light BVH)",
);

/// `path`'s settings (and `volpath`'s).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathSettings {
    pub max_depth: u32,
    pub rr_threshold: f32,
    pub light_sample_strategy: LightSampleStrategy,
}

impl Default for PathSettings {
    fn default() -> PathSettings {
        PathSettings {
            max_depth: 5,
            rr_threshold: 1.0,
            light_sample_strategy: LightSampleStrategy::Spatial,
        }
    }
}

impl PathSettings {
    /// The settings of a statement's parameters, checked as pbrt-v3 does.
    pub fn read(p: &ParamValues, r: &mut dyn Report) -> PathSettings {
        PathSettings {
            max_depth: super::max_depth(p, r),
            rr_threshold: p.float("rrthreshold"),
            light_sample_strategy: light_sample_strategy(p, r),
        }
    }

    pub fn summary(&self) -> String {
        let PathSettings {
            max_depth,
            rr_threshold,
            light_sample_strategy,
        } = self;
        format!("maxdepth {max_depth}, rrthreshold {rr_threshold}, light samples {light_sample_strategy:?}").to_lowercase()
    }
}

/// `lightsamplestrategy`: an unknown one is a warning, and `spatial` is
/// used (as pbrt-v3).
fn light_sample_strategy(p: &ParamValues, r: &mut dyn Report) -> LightSampleStrategy {
    match p.string("lightsamplestrategy") {
        "spatial" => LightSampleStrategy::Spatial,
        "uniform" => LightSampleStrategy::Uniform,
        "power" => LightSampleStrategy::Power,
        "bvh" => LightSampleStrategy::Bvh,
        other => {
            r.warn(
                Some("lightsamplestrategy"),
                format!(
                    "unknown light sample strategy \"{other}\": \"spatial\" is used (as pbrt-v3)"
                ),
                "expected uniform, power, spatial or bvh",
            );
            LightSampleStrategy::Spatial
        }
    }
}

/// The path tracer: pbrt-v3's PathIntegrator (next-event estimation,
/// power-heuristic MIS, `maxdepth`, pbrt-v3's Russian roulette with
/// `rrthreshold`), with the MIS structure of pbrt-v4 and Mitsuba: the BSDF
/// sample that continues the path is also the BSDF strategy of MIS, so a
/// vertex draws one BSDF sample instead of two and needs no separate ray or
/// light-shape test for it. When the continued path hits an emitter (or
/// escapes to an infinite light) after a non-specular bounce, its emission
/// is weighted against the density with which next-event estimation at the
/// previous vertex would have produced that direction (light choice
/// probability times the light's solid-angle density); light samples are
/// weighted the same way. Both estimators are unbiased and the weights of
/// each direction sum to one, so the expected image is pbrt-v3's; the path
/// lengths covered are the same (emission is collected at depth `maxdepth`,
/// next-event estimation happens below it).
#[allow(clippy::too_many_arguments)]
pub(super) fn path_li(
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
    let mut st = PathState::new(ray, diff);
    let mut bsdf = Bsdf::empty();
    let p = PathParams {
        scene,
        time,
        max_depth,
        rr_threshold,
        lights,
    };
    loop {
        scratch.counts.closest += 1;
        let hit = scene.geometry.intersect_at(&st.ray, time);
        if !path_step(&mut st, &hit, &p, sampler, scratch, &mut bsdf) {
            break;
        }
    }
    st.l
}

/// A path of `path` between two vertices: what [`path_step`] carries from
/// one intersection to the next (the batched renderer keeps one per lane).
#[derive(Clone, Copy, Debug)]
pub(crate) struct PathState {
    /// The ray to trace next.
    pub(super) ray: Ray,
    /// Its differentials (only the camera ray has them: pbrt-v3's path
    /// tracer spawns every later ray without them, specular bounces
    /// included).
    pub(super) diff: Option<RayDiff>,
    /// Radiance gathered so far.
    pub l: Vec3,
    beta: Vec3,
    specular_bounce: bool,
    eta_scale: f32,
    bounces: u32,
    pass: u32,
    /// The last scattering vertex and the BSDF density of the direction
    /// sampled there (for the MIS weight of emission found along it).
    prev: Option<SurfacePoint>,
    bsdf_pdf: f32,
}

impl PathState {
    /// `*self = PathState::new(ray, *diff)`, field by field (a new state
    /// built on the stack and copied stalled on the copy's loads).
    #[inline]
    pub(crate) fn reset(&mut self, ray: Ray, diff: &Option<RayDiff>) {
        self.ray = ray;
        self.diff = *diff;
        self.l = Vec3::ZERO;
        self.beta = Vec3::ONE;
        self.specular_bounce = false;
        self.eta_scale = 1.0;
        self.bounces = 0;
        self.pass = 0;
        self.prev = None;
        self.bsdf_pdf = 0.0;
    }

    #[inline]
    pub(crate) fn new(ray: Ray, diff: Option<RayDiff>) -> PathState {
        PathState {
            ray,
            diff,
            l: Vec3::ZERO,
            beta: Vec3::ONE,
            specular_bounce: false,
            eta_scale: 1.0,
            bounces: 0,
            pass: 0,
            prev: None,
            bsdf_pdf: 0.0,
        }
    }
}

/// What every step of a `path` render shares.
pub(crate) struct PathParams<'a> {
    pub(super) scene: &'a RenderScene,
    pub(super) time: f32,
    pub(super) max_depth: u32,
    pub(super) rr_threshold: f32,
    pub(super) lights: &'a LightSampler,
}

/// One vertex of the path tracer: `hit` is the intersection of `st.ray`
/// (already traced and counted). Gathers emission and a light sample, then
/// samples the next direction into `st.ray`; false when the path ends.
#[inline(always)]
pub(super) fn path_step<'a>(
    st: &mut PathState,
    hit: &Option<Hit>,
    p: &PathParams<'a>,
    sampler: &mut Sampler,
    scratch: &mut Scratch,
    bsdf: &mut Bsdf<'a>,
) -> bool {
    let (scene, time, lights) = (p.scene, p.time, p.lights);
    let ray = st.ray;
    let from = st.prev.filter(|_| !st.specular_bounce);
    // By reference: a copy of the hit just read stalls on its stores.
    let Some(hit) = hit.as_ref() else {
        add_escaped_mis(
            &mut st.l,
            scene,
            lights,
            st.beta,
            from.as_ref(),
            ray.d,
            st.bsdf_pdf,
        );
        return false;
    };
    let mut s = scene.geometry.surface_at(hit, time);
    let wo = -ray.d;
    st.l += emitted_mis(
        scene,
        lights,
        st.beta,
        &s,
        from.as_ref(),
        ray.d,
        st.bsdf_pdf,
    );
    if st.bounces >= p.max_depth {
        return false;
    }
    let material = &scene.materials[s.material as usize];
    if material.is_none() {
        // Pass through without counting a bounce (pbrt-v3: bounces--).
        st.pass += 1;
        if st.pass > MAX_PASS_THROUGH {
            return false;
        }
        st.ray = spawn_ray(s.point.p, s.point.p_error, s.point.n, ray.d);
        st.diff = None;
        return true;
    }
    shade(scene, hit, &mut s, material, true, st.diff.as_ref(), bsdf);
    st.diff = None;
    if bsdf.has_non_specular() {
        st.l += st.beta * sample_light_mis(scene, &s, bsdf, wo, sampler, scratch, lights);
    }
    let u = sampler.get_2d();
    let Some(bs) = bsdf.sample(wo, u, BxdfFlags::ALL) else {
        return false;
    };
    if bs.f == Vec3::ZERO || bs.pdf == 0.0 {
        return false;
    }
    st.beta *= bs.f * bs.wi.dot(s.point.ns).abs() / bs.pdf;
    st.specular_bounce = bs.is_specular();
    st.bsdf_pdf = bs.pdf;
    st.prev = Some(s.point);
    st.eta_scale *= eta_scale_change(bsdf, &bs, wo, s.point.n);
    st.ray = spawn_ray(s.point.p, s.point.p_error, s.point.n, bs.wi);
    if bs.is_transmission() && material.has_bssrdf() {
        // pbrt-v3's subsurface step: continue from a sampled exit
        // point, with light sampled there, not counted as a bounce.
        let frame = bsdf.frame;
        let Some((pi, w, exit)) =
            subsurface_exit(scene, hit, &s, material, &frame, time, sampler, scratch)
        else {
            return false;
        };
        st.beta *= w;
        let wo = pi.point.ns;
        st.l += st.beta * sample_light_mis(scene, &pi, &exit, wo, sampler, scratch, lights);
        let Some(bs) = sample_exit(&pi, &exit, sampler) else {
            return false;
        };
        st.beta *= bs.f * bs.wi.dot(pi.point.ns).abs() / bs.pdf;
        st.specular_bounce = false;
        st.bsdf_pdf = bs.pdf;
        st.prev = Some(pi.point);
        st.ray = spawn_ray(pi.point.p, pi.point.p_error, pi.point.n, bs.wi);
    }
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
