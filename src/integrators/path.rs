//! `path`: pbrt-v3's PathIntegrator (see [`path_li`]), and the per-vertex
//! step it shares with `volpath` ([`path_step`], over the medium the path
//! is in: [`NoMedium`] here, the ray's medium in [`super::volpath`]).
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `maxdepth` | integer | 5 | maximum number of bounces (≥ 0) |
//! | `rrthreshold` | float | 1 | Russian roulette once max(β·etaScale) is below it (after bounce 3) |
//! | `lightsamplestrategy` | string | `spatial` | light choice: `uniform`, `power`, `spatial` or `bvh` |
//! | `pixelbounds` | | | ignored, with a warning |

use super::batch::{trace_paths, Batch};
use super::common::{
    add_escaped_mis, emitted_mis, eta_scale_change, light_sampler, roulette, sample_light_mis,
    shade, ShadowRay, SurfaceScatter, Unoccluded,
};
use super::subsurface::{sample_exit, subsurface_exit};
use super::{Integrate, IntegratorKind, IntegratorSettings, Scratch, MAX_PASS_THROUGH};
use super::{MAX_DEPTH, PIXEL_BOUNDS};
use crate::accel::{Hit, SurfaceHit};
use crate::geometry::{spawn_ray, Ray, RayDiff};
use crate::lights::LightSampler;
use crate::materials::{Bsdf, BxdfFlags};
use crate::media::HenyeyGreenstein;
use crate::samplers::Sampler;
use crate::integrators::RenderScene;
use crate::shapes::SurfacePoint;
use crate::scene::kind::{Report, Support};
use crate::scene::{LightSampleStrategy, ParamSpec, ParamValues};
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
pub(super) fn light_sample_strategy(p: &ParamValues, r: &mut dyn Report) -> LightSampleStrategy {
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

/// The runtime `path`: its settings and its light distribution.
pub struct Path {
    settings: PathSettings,
    lights: LightSampler,
}

impl Path {
    pub fn new(settings: &PathSettings, scene: &RenderScene, _scalar: bool) -> Path {
        Path {
            settings: *settings,
            lights: light_sampler(settings.light_sample_strategy, scene),
        }
    }
}

impl Integrate for Path {
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
        let p = PathParams::new::<NoMedium>(scene, time, &self.settings, &self.lights);
        path_li(ray, NoMedium, diff, &p, sampler, scratch)
    }

    fn batch(&self, lanes: usize, sampler: &Sampler) -> Batch {
        let mut b = Batch::new(lanes, sampler);
        b.paths = vec![PathState::new(Ray::new(Vec3::ZERO, Vec3::Z), None, NoMedium); lanes];
        b
    }

    /// All of the batch's paths one vertex at a time (see [`trace_paths`]).
    fn li_batch(&self, b: &mut Batch, scene: &RenderScene, scratch: &mut Scratch) {
        let mut states = std::mem::take(&mut b.paths);
        trace_paths(b, &mut states, NoMedium, &self.settings, &self.lights, scene, scratch);
        b.paths = states;
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
/// next-event estimation happens below it). `volpath` is the same loop
/// with the camera ray starting in `medium`.
pub(super) fn path_li<M: PathMedium>(
    ray: Ray,
    medium: M,
    diff: Option<RayDiff>,
    p: &PathParams,
    sampler: &mut Sampler,
    scratch: &mut Scratch,
) -> Vec3 {
    let mut st = PathState::new(ray, diff, medium);
    let mut bsdf = Bsdf::empty();
    loop {
        scratch.counts.closest += 1;
        let hit = p.scene.aggregate.intersect_at(&st.ray, p.time);
        if !path_step(&mut st, &hit, p, sampler, scratch, &mut bsdf) {
            break;
        }
    }
    st.l
}

/// Where a segment of a path ends, as [`PathMedium::sample_segment`] finds.
pub(crate) enum Segment {
    /// At the ray's hit (or escaping the scene).
    Hit,
    /// Nowhere: the medium's weight is zero (the path ends).
    Absorbed,
    /// Scattering in the medium at this distance along the ray, by this
    /// phase function.
    Scatters(f32, HenyeyGreenstein),
}

/// The medium a path is in between two vertices, as [`path_step`] sees it:
/// [`NoMedium`] for `path` (pbrt-v3's PathIntegrator ignores media, and
/// any surface blocks a shadow ray), the ray's medium for `volpath`
/// ([`super::volpath::RayMedium`]). Every method is inlined into the step,
/// so `path` pays nothing for `volpath`'s media.
pub(crate) trait PathMedium: Copy + std::fmt::Debug {
    /// True if the kind renders participating media (`volpath`).
    const MEDIA: bool;

    /// Samples this medium along `ray` up to `hit` (pbrt-v3's
    /// `Medium::Sample`), multiplying its weight into `beta`.
    fn sample_segment(
        self,
        p: &PathParams,
        ray: &Ray,
        hit: &Option<Hit>,
        beta: &mut Vec3,
        sampler: &mut Sampler,
    ) -> Segment;

    /// The medium of a ray leaving surface `s` in direction `w`, this one
    /// being the medium the path arrived in.
    fn after(self, p: &PathParams, s: &SurfaceHit, w: Vec3) -> Self;

    /// The medium of a ray leaving a subsurface exit point `s` in
    /// direction `w` (the probe rays that found it carry none).
    fn after_exit(p: &PathParams, s: &SurfaceHit, w: Vec3) -> Self;

    /// `f` times the transmittance of the shadow ray `shadow` starting in
    /// this medium, traced and counted; `None` when it is blocked.
    #[allow(clippy::too_many_arguments)]
    fn shadow_tr(
        self,
        scene: &RenderScene,
        shadow: &Ray,
        time: f32,
        f: Vec3,
        sampler: &mut Sampler,
        scratch: &mut Scratch,
    ) -> Option<Vec3>;
}

/// The shadow rays of next-event estimation at a vertex of `path` or
/// `volpath`: the one towards `wi` starts in the medium `self.0(wi)`.
pub(crate) struct ShadowFrom<F>(pub F);

impl<M: PathMedium, F: Fn(Vec3) -> M> ShadowRay for ShadowFrom<F> {
    #[inline(always)]
    fn through(
        &self,
        scene: &RenderScene,
        shadow: &Ray,
        time: f32,
        wi: Vec3,
        f: Vec3,
        sampler: &mut Sampler,
        scratch: &mut Scratch,
    ) -> Option<Vec3> {
        (self.0)(wi).shadow_tr(scene, shadow, time, f, sampler, scratch)
    }
}

/// `path`'s medium: none (shadow rays are blocked by any surface).
#[derive(Clone, Copy, Debug)]
pub(crate) struct NoMedium;

impl PathMedium for NoMedium {
    const MEDIA: bool = false;

    #[inline(always)]
    fn sample_segment(
        self,
        _: &PathParams,
        _: &Ray,
        _: &Option<Hit>,
        _: &mut Vec3,
        _: &mut Sampler,
    ) -> Segment {
        Segment::Hit
    }

    #[inline(always)]
    fn after(self, _: &PathParams, _: &SurfaceHit, _: Vec3) -> NoMedium {
        NoMedium
    }

    #[inline(always)]
    fn after_exit(_: &PathParams, _: &SurfaceHit, _: Vec3) -> NoMedium {
        NoMedium
    }

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
        Unoccluded.through(scene, shadow, time, shadow.d, f, sampler, scratch)
    }
}

/// A path of `path` or `volpath` between two vertices: what [`path_step`]
/// carries from one intersection to the next (the batched renderer keeps
/// one per lane).
#[derive(Clone, Copy, Debug)]
pub(crate) struct PathState<M> {
    /// The ray to trace next.
    pub(super) ray: Ray,
    /// Its differentials (only the camera ray has them: pbrt-v3's path
    /// tracer spawns every later ray without them, specular bounces
    /// included).
    pub(super) diff: Option<RayDiff>,
    /// The medium the ray is in.
    medium: M,
    /// Radiance gathered so far.
    pub l: Vec3,
    beta: Vec3,
    specular_bounce: bool,
    eta_scale: f32,
    bounces: u32,
    pass: u32,
    /// The last scattering vertex (a medium point has no normal and no
    /// error bound) and the BSDF or phase density of the direction sampled
    /// there (for the MIS weight of emission found along it).
    prev: Option<SurfacePoint>,
    scatter_pdf: f32,
    /// `path` only: the ray left a non-specular vertex and crossed a
    /// material-less surface, so emission it finds is not counted (pbrt-v3's
    /// `path` stops both strategies of that vertex's light sample there:
    /// the shadow ray is occluded and the BSDF-sampled ray ends at it).
    dark: bool,
}

impl<M: PathMedium> PathState<M> {
    /// `*self = PathState::new(ray, *diff, medium)`, field by field (a new
    /// state built on the stack and copied stalled on the copy's loads).
    #[inline]
    pub(crate) fn reset(&mut self, ray: Ray, diff: &Option<RayDiff>, medium: M) {
        self.ray = ray;
        self.diff = *diff;
        self.medium = medium;
        self.l = Vec3::ZERO;
        self.beta = Vec3::ONE;
        self.specular_bounce = false;
        self.eta_scale = 1.0;
        self.bounces = 0;
        self.pass = 0;
        self.prev = None;
        self.scatter_pdf = 0.0;
        self.dark = false;
    }

    #[inline]
    pub(crate) fn new(ray: Ray, diff: Option<RayDiff>, medium: M) -> PathState<M> {
        PathState {
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
            dark: false,
        }
    }
}

/// What every step of a `path` or `volpath` render shares.
pub(crate) struct PathParams<'a> {
    pub(super) scene: &'a RenderScene,
    pub(super) time: f32,
    pub(super) max_depth: u32,
    pub(super) rr_threshold: f32,
    pub(super) lights: &'a LightSampler,
    /// The kind renders media and the scene has some (else every ray's
    /// medium stays none).
    pub(super) media_on: bool,
}

impl<'a> PathParams<'a> {
    #[inline(always)]
    pub(super) fn new<M: PathMedium>(
        scene: &'a RenderScene,
        time: f32,
        settings: &PathSettings,
        lights: &'a LightSampler,
    ) -> PathParams<'a> {
        PathParams {
            scene,
            time,
            max_depth: settings.max_depth,
            rr_threshold: settings.rr_threshold,
            lights,
            media_on: M::MEDIA && !scene.media.is_empty(),
        }
    }
}

/// One vertex of `path` and `volpath`: `hit` is the intersection of
/// `st.ray` (already traced and counted). The medium is sampled up to it
/// first: if the path scatters there, [`medium_step`]; else emission and a
/// light sample at the surface, then the next direction sampled into
/// `st.ray` (a material-less surface is crossed without a bounce, into the
/// medium on its other side). False when the path ends.
#[inline(always)]
pub(super) fn path_step<'a, M: PathMedium>(
    st: &mut PathState<M>,
    hit: &Option<Hit>,
    p: &PathParams<'a>,
    sampler: &mut Sampler,
    scratch: &mut Scratch,
    bsdf: &mut Bsdf<'a>,
) -> bool {
    let (scene, time, lights) = (p.scene, p.time, p.lights);
    match st.medium.sample_segment(p, &st.ray, hit, &mut st.beta, sampler) {
        Segment::Hit => {}
        Segment::Absorbed => return false,
        Segment::Scatters(t, phase) => return medium_step(st, t, phase, p, sampler, scratch),
    }
    let ray = st.ray;
    let from = st.prev.filter(|_| !st.specular_bounce);
    // By reference: a copy of the hit just read stalls on its stores.
    let Some(hit) = hit.as_ref() else {
        if st.dark {
            return false;
        }
        add_escaped_mis(
            &mut st.l,
            scene,
            lights,
            st.beta,
            from.as_ref(),
            ray.d,
            st.scatter_pdf,
        );
        return false;
    };
    let mut s = scene.aggregate.surface_at(hit, time);
    let wo = -ray.d;
    if !st.dark {
        st.l += emitted_mis(
            scene,
            lights,
            st.beta,
            &s,
            from.as_ref(),
            ray.d,
            st.scatter_pdf,
        );
    }
    let material = &scene.materials[s.material as usize];
    // A medium boundary only: crossed without counting a bounce (pbrt-v3:
    // bounces--). In `volpath` also past the last bounce: the continuation
    // is the BSDF or phase strategy of the last vertex's light sample,
    // whose rays pbrt-v3 traces through such surfaces (`IntersectTr`); in
    // `path` pbrt-v3's rays stop there (see `PathState::dark`).
    if material.is_none() && (M::MEDIA || st.bounces < p.max_depth) {
        st.pass += 1;
        if st.pass > MAX_PASS_THROUGH {
            return false;
        }
        st.medium = st.medium.after(p, &s, ray.d);
        st.ray = spawn_ray(s.point.p, s.point.p_error, s.point.n, ray.d);
        st.diff = None;
        st.dark |= !M::MEDIA && from.is_some();
        return true;
    }
    if st.bounces >= p.max_depth {
        return false;
    }
    shade(scene, hit, &mut s, material, true, st.diff.as_ref(), bsdf);
    st.diff = None;
    if bsdf.has_non_specular() {
        let scatter = SurfaceScatter {
            bsdf,
            ns: s.point.ns,
            flags: BxdfFlags::ALL,
        };
        let current = st.medium;
        let shadow = ShadowFrom(|wi| current.after(p, &s, wi));
        st.l += st.beta
            * sample_light_mis(
                scene, &s.point, time, &scatter, wo, shadow, sampler, scratch, lights,
            );
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
    st.scatter_pdf = bs.pdf;
    st.prev = Some(s.point);
    st.dark = false;
    st.eta_scale *= eta_scale_change(bsdf, &bs, wo, s.point.n);
    st.medium = st.medium.after(p, &s, bs.wi);
    st.ray = spawn_ray(s.point.p, s.point.p_error, s.point.n, bs.wi);
    if bs.is_transmission() && material.has_bssrdf() {
        // pbrt-v3's subsurface step: continue from a sampled exit point,
        // with light sampled there, not counted as a bounce. As in
        // pbrt-v3, the exit point is found by probe rays that carry no
        // medium, so unless its shape has a medium transition the rays
        // leaving it start in vacuum (pbrt-v3's
        // `GeometricPrimitive::Intersect` gives a hit of a non-transition
        // shape the probe ray's medium, none).
        let frame = bsdf.frame;
        let Some((pi, w, exit)) =
            subsurface_exit(scene, hit, &s, material, &frame, time, sampler, scratch)
        else {
            return false;
        };
        st.beta *= w;
        let wo = pi.point.ns;
        let scatter = SurfaceScatter {
            bsdf: &exit,
            ns: pi.point.ns,
            flags: BxdfFlags::ALL,
        };
        let shadow = ShadowFrom(|wi| M::after_exit(p, &pi, wi));
        st.l += st.beta
            * sample_light_mis(
                scene, &pi.point, time, &scatter, wo, shadow, sampler, scratch, lights,
            );
        let Some(bs) = sample_exit(&pi, &exit, sampler) else {
            return false;
        };
        st.beta *= bs.f * bs.wi.dot(pi.point.ns).abs() / bs.pdf;
        st.specular_bounce = false;
        st.scatter_pdf = bs.pdf;
        st.prev = Some(pi.point);
        st.dark = false;
        st.medium = M::after_exit(p, &pi, bs.wi);
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

/// The path scatters in its medium at distance `t` along `st.ray`: a
/// medium vertex whose phase function plays the BSDF's part (next-event
/// estimation, then a phase-function sample to continue). False when the
/// path ends.
#[inline(always)]
fn medium_step<M: PathMedium>(
    st: &mut PathState<M>,
    t: f32,
    phase: HenyeyGreenstein,
    p: &PathParams,
    sampler: &mut Sampler,
    scratch: &mut Scratch,
) -> bool {
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
    let current = st.medium;
    let shadow = ShadowFrom(|_| current);
    st.l += st.beta
        * sample_light_mis(
            p.scene, &point, p.time, &phase, wo, shadow, sampler, scratch, p.lights,
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
