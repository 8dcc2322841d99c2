//! Integrators, as pbrt-v3 defines them: `path` (next-event estimation with
//! power-heuristic MIS, Russian roulette), `volpath` (the same with
//! participating media, in [`volpath`]), `directlighting` (strategy all or
//! one, specular lobes followed recursively) and `whitted`.

use crate::render::accel::{Hit, SurfaceHit};
use crate::render::bssrdf::probe::{find_exit, pdf_sp, probe_segment};
use crate::render::bxdf::SwAdapter;
use crate::render::geometry::{spawn_ray, Frame, Ray, RayDiff};
use crate::render::lights::{
    pack_triangle_lights, LightSampler, LightSamplerKind, TriangleLightPack,
};
use crate::render::materials::{
    Bsdf, BsdfContext, BsdfSample, BxdfFlags, Material, ShadingContext,
};
use crate::render::samplers::Sampler;
use crate::render::sampling::power_heuristic;
use crate::render::scene::RenderScene;
use crate::render::shapes::{DiffGeom, SurfacePoint};
use crate::scene::{DirectStrategy, IntegratorDesc, LightSampleStrategy};
use glam::{Vec2, Vec3};

mod all_lights;
mod volpath;

/// Rays traced, counted per tile and summed at the end (no shared counters).
#[derive(Clone, Copy, Debug, Default)]
pub struct RayCounts {
    /// Closest-hit rays (camera rays included).
    pub closest: u64,
    /// Occlusion (shadow) rays.
    pub shadow: u64,
}

impl RayCounts {
    pub fn add(&mut self, o: &RayCounts) {
        self.closest += o.closest;
        self.shadow += o.shadow;
    }
    pub fn total(&self) -> u64 {
        self.closest + self.shadow
    }
}

/// A pending vertex of directlighting's and whitted's specular tree.
#[derive(Clone, Copy, Debug)]
struct Work {
    ray: Ray,
    /// The ray's differentials, if it carries them (camera rays and their
    /// specular bounces, as pbrt-v3's SpecularReflect/SpecularTransmit).
    diff: Option<RayDiff>,
    beta: Vec3,
    depth: u32,
    pass: u32,
}

/// The samples a thread renders together (see [`Integrator::li_batch`]):
/// per lane its sampler, camera ray and result, in structure-of-arrays
/// form. Made once per thread; nothing in it allocates per batch.
pub struct Batch {
    /// Lanes in use.
    pub len: usize,
    pub samplers: Vec<Sampler>,
    pub rays: Vec<Ray>,
    pub diffs: Vec<Option<RayDiff>>,
    pub times: Vec<f32>,
    /// Each camera ray's weight; lanes of weight 0 (a sample the lens
    /// blocks) get no radiance, as pbrt-v3.
    pub weights: Vec<f32>,
    /// The radiance of each lane.
    pub l: Vec<Vec3>,
    hits: Vec<Option<Hit>>,
    states: Vec<PathState>,
    active: Vec<u32>,
    direct: DirectLanes,
}

/// directlighting's Lambertian camera vertices of a batch (see
/// [`Integrator::li_batch`]): the batch lane of each, the vertex, its
/// emission, its light and BSDF samples for every light, and the sums of
/// the light estimates. Grown to the batch's need on the first batch.
#[derive(Default)]
struct DirectLanes {
    lanes: Vec<u32>,
    verts: Vec<all_lights::LambertVertex>,
    emitted: Vec<Vec3>,
    u: Vec<Vec2>,
    sums: Vec<Vec3>,
}

impl DirectLanes {
    /// Bytes held (after a batch has grown them).
    fn bytes(&self) -> usize {
        use std::mem::size_of;
        self.lanes.capacity() * size_of::<u32>()
            + self.verts.capacity() * size_of::<all_lights::LambertVertex>()
            + (self.emitted.capacity() + self.sums.capacity()) * size_of::<Vec3>()
            + self.u.capacity() * size_of::<Vec2>()
    }

    fn clear(&mut self) {
        self.lanes.clear();
        self.verts.clear();
        self.emitted.clear();
        self.u.clear();
        self.sums.clear();
    }
}

impl Batch {
    /// Bytes the batch holds: its lanes' state and their samplers (with
    /// the samplers' array stores).
    pub fn state_bytes(&self) -> usize {
        use std::mem::size_of;
        let lanes = self.samplers.len();
        lanes
            * (size_of::<Sampler>()
                + size_of::<Ray>()
                + size_of::<Option<RayDiff>>()
                + 2 * size_of::<f32>()
                + size_of::<Vec3>()
                + size_of::<Option<Hit>>()
                + size_of::<PathState>()
                + size_of::<u32>())
            + self.samplers.iter().map(|s| s.heap_bytes()).sum::<usize>()
            + self.direct.bytes()
    }

    /// A batch of `lanes` lanes, each with a copy of `sampler`.
    pub fn new(lanes: usize, sampler: &Sampler) -> Batch {
        let ray = Ray::new(Vec3::ZERO, Vec3::Z);
        Batch {
            len: 0,
            samplers: vec![sampler.clone(); lanes],
            rays: vec![ray; lanes],
            diffs: vec![None; lanes],
            times: vec![0.0; lanes],
            weights: vec![0.0; lanes],
            l: vec![Vec3::ZERO; lanes],
            hits: vec![None; lanes],
            states: vec![PathState::new(ray, None); lanes],
            active: Vec::with_capacity(lanes),
            direct: DirectLanes::default(),
        }
    }
}

/// Per-tile scratch space, so the per-sample path never allocates.
#[derive(Default)]
pub struct Scratch {
    u_light: Vec<Vec2>,
    u_scatter: Vec<Vec2>,
    work: Vec<Work>,
    counts: RayCounts,
}

impl Scratch {
    pub fn counts(&self) -> RayCounts {
        self.counts
    }
}

/// Rays crossing more than this many `Material "none"` surfaces in a row stop.
const MAX_PASS_THROUGH: u32 = 256;

pub enum Integrator {
    Path {
        max_depth: u32,
        rr_threshold: f32,
        lights: LightSampler,
    },
    Direct {
        max_depth: u32,
        strategy: DirectStrategy,
        lights: LightSampler,
        n_light_samples: Vec<u32>,
        /// The lights four to a pack, for strategy "all" when every light is
        /// a triangle of constant normal with one sample (else empty).
        packs: Vec<TriangleLightPack>,
        /// Light `i` of `packs` in all four lanes, for the camera vertices
        /// of a batch (one light at four vertices).
        uniform: Vec<TriangleLightPack>,
    },
    Whitted {
        max_depth: u32,
    },
    VolPath {
        max_depth: u32,
        rr_threshold: f32,
        lights: LightSampler,
    },
}

/// The light distribution a `lightsamplestrategy` names.
fn light_sampler_kind(s: LightSampleStrategy) -> LightSamplerKind {
    match s {
        LightSampleStrategy::Uniform => LightSamplerKind::Uniform,
        LightSampleStrategy::Power => LightSamplerKind::Power,
        LightSampleStrategy::Spatial => LightSamplerKind::Spatial,
        LightSampleStrategy::Bvh => LightSamplerKind::Bvh,
    }
}

impl Integrator {
    /// Builds the integrator and only the light distribution it uses;
    /// `simd` allows the four-lane paths (which give the same image).
    pub fn new(desc: &IntegratorDesc, scene: &RenderScene, simd: bool) -> Integrator {
        match *desc {
            IntegratorDesc::Path {
                max_depth,
                rr_threshold,
                light_sample_strategy,
            } => {
                let kind = light_sampler_kind(light_sample_strategy);
                Integrator::Path {
                    max_depth,
                    rr_threshold,
                    lights: LightSampler::new(kind, &scene.lights, &scene.geometry),
                }
            }
            IntegratorDesc::DirectLighting {
                max_depth,
                strategy,
            } => Integrator::Direct {
                max_depth,
                strategy,
                // pbrt-v3's directlighting chooses uniformly for strategy "one".
                lights: LightSampler::new(
                    LightSamplerKind::Uniform,
                    &scene.lights,
                    &scene.geometry,
                ),
                n_light_samples: Vec::new(),
                packs: match strategy {
                    DirectStrategy::All if simd => {
                        pack_triangle_lights(&scene.lights).unwrap_or_default()
                    }
                    _ => Vec::new(),
                },
                uniform: Vec::new(),
            },
            IntegratorDesc::Whitted { max_depth } => Integrator::Whitted { max_depth },
            IntegratorDesc::VolPath {
                max_depth,
                rr_threshold,
                light_sample_strategy,
            } => {
                let kind = light_sampler_kind(light_sample_strategy);
                Integrator::VolPath {
                    max_depth,
                    rr_threshold,
                    lights: LightSampler::new(kind, &scene.lights, &scene.geometry),
                }
            }
        }
    }

    /// A batch of `lanes` lanes for [`Integrator::li_batch`], each with a
    /// copy of `sampler`, with room for what this integrator keeps per lane.
    pub fn batch(&self, lanes: usize, sampler: &Sampler) -> Batch {
        let mut b = Batch::new(lanes, sampler);
        if let Integrator::Direct { uniform, .. } = self {
            if !uniform.is_empty() {
                let d = &mut b.direct;
                d.lanes.reserve(lanes);
                d.verts.reserve(lanes);
                d.emitted.reserve(lanes);
                d.sums.reserve(lanes);
                d.u.reserve(lanes * 2 * uniform.len());
            }
        }
        b
    }

    /// Requests the sampler arrays the integrator uses (pbrt-v3's Preprocess).
    pub fn prepare_sampler(&mut self, scene: &RenderScene, sampler: &mut Sampler) {
        if let Integrator::Direct {
            max_depth,
            strategy: DirectStrategy::All,
            n_light_samples,
            packs,
            uniform,
            ..
        } = self
        {
            *n_light_samples = scene
                .lights
                .iter()
                .map(|l| sampler.round_count(l.n_samples()))
                .collect();
            if n_light_samples.iter().any(|&n| n != 1) {
                packs.clear();
            }
            *uniform = packs
                .iter()
                .flat_map(|p| (0..p.count).map(|lane| p.uniform(lane)))
                .collect();
            for _ in 0..*max_depth {
                for &n in n_light_samples.iter() {
                    sampler.request_2d_array(n);
                    sampler.request_2d_array(n);
                }
            }
        }
    }

    /// What the integrator built beyond the light distribution.
    pub fn notes(&self) -> Vec<String> {
        match self {
            Integrator::Direct { packs, .. } if !packs.is_empty() => vec![format!(
                "directlighting \"all\": {} triangle lights in {} four-lane packs (Lambertian vertices sample four lights at once)",
                packs.iter().map(|p| p.count).sum::<usize>(),
                packs.len()
            )],
            _ => Vec::new(),
        }
    }

    pub fn light_sampler(&self) -> Option<&LightSampler> {
        match self {
            Integrator::Path { lights, .. }
            | Integrator::Direct { lights, .. }
            | Integrator::VolPath { lights, .. } => Some(lights),
            Integrator::Whitted { .. } => None,
        }
    }

    /// Radiance arriving at the camera along `ray` at scene time `time`
    /// (every ray of the path is traced at it), with its differentials if it
    /// has them.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub fn li(
        &self,
        ray: Ray,
        time: f32,
        diff: Option<RayDiff>,
        scene: &RenderScene,
        sampler: &mut Sampler,
        scratch: &mut Scratch,
    ) -> Vec3 {
        match self {
            Integrator::Path {
                max_depth,
                rr_threshold,
                lights,
            } => path_li(
                ray,
                time,
                diff,
                scene,
                sampler,
                scratch,
                *max_depth,
                *rr_threshold,
                lights,
            ),
            Integrator::VolPath {
                max_depth,
                rr_threshold,
                lights,
            } => volpath::volpath_li(
                ray,
                time,
                diff,
                scene,
                sampler,
                scratch,
                *max_depth,
                *rr_threshold,
                lights,
            ),
            Integrator::Direct { .. } | Integrator::Whitted { .. } => {
                let mut bsdf = Bsdf::empty();
                self.specular_tree_li(
                    ray,
                    First::Trace,
                    time,
                    diff,
                    scene,
                    sampler,
                    scratch,
                    &mut bsdf,
                )
            }
        }
    }

    /// [`Integrator::li`] for the camera rays of a batch of samples, lane by
    /// lane the same values bit for bit: `path` advances all the batch's
    /// paths one vertex at a time (all closest hits, then all shading and
    /// light sampling), directlighting and whitted trace all camera rays
    /// first, volpath renders lane by lane. Each lane has its own sampler,
    /// positioned at its sample; lanes of weight 0 get no radiance.
    pub fn li_batch(&self, b: &mut Batch, scene: &RenderScene, scratch: &mut Scratch) {
        let n = b.len;
        match self {
            Integrator::Path {
                max_depth,
                rr_threshold,
                lights,
            } => {
                b.active.clear();
                for j in 0..n {
                    b.l[j] = Vec3::ZERO;
                    if b.weights[j] > 0.0 {
                        b.states[j].reset(b.rays[j], &b.diffs[j]);
                        b.active.push(j as u32);
                    }
                }
                let mut bsdf = Bsdf::empty();
                while !b.active.is_empty() {
                    for &j in &b.active {
                        let j = j as usize;
                        scratch.counts.closest += 1;
                        let ray = &b.states[j].ray;
                        scene
                            .geometry
                            .intersect_into(ray, b.times[j], &mut b.hits[j]);
                    }
                    let mut kept = 0;
                    for k in 0..b.active.len() {
                        let j = b.active[k] as usize;
                        let p = PathParams {
                            scene,
                            time: b.times[j],
                            max_depth: *max_depth,
                            rr_threshold: *rr_threshold,
                            lights,
                        };
                        if path_step(
                            &mut b.states[j],
                            &b.hits[j],
                            &p,
                            &mut b.samplers[j],
                            scratch,
                            &mut bsdf,
                        ) {
                            b.active[kept] = j as u32;
                            kept += 1;
                        } else {
                            b.l[j] = b.states[j].l;
                        }
                    }
                    b.active.truncate(kept);
                }
            }
            Integrator::Direct { .. } | Integrator::Whitted { .. } | Integrator::VolPath { .. } => {
                // volpath's first ray may pass through media: it starts
                // from the camera ray itself.
                let first_hits = !matches!(self, Integrator::VolPath { .. });
                if first_hits {
                    for j in 0..n {
                        if b.weights[j] > 0.0 {
                            let hit = &mut b.hits[j];
                            scene.geometry.intersect_into(&b.rays[j], b.times[j], hit);
                        }
                    }
                }
                if let Integrator::Direct { uniform, .. } = self {
                    if !uniform.is_empty() {
                        self.direct_batch(b, scene, scratch, uniform);
                        return;
                    }
                }
                let mut bsdf = Bsdf::empty();
                for j in 0..n {
                    let (ray, time, diff) = (b.rays[j], b.times[j], b.diffs[j]);
                    let sampler = &mut b.samplers[j];
                    // The scalar loop's test: a NaN weight gets no radiance.
                    b.l[j] = if b.weights[j] > 0.0 {
                        if first_hits {
                            let first = First::Hit(b.hits[j]);
                            self.specular_tree_li(
                                ray, first, time, diff, scene, sampler, scratch, &mut bsdf,
                            )
                        } else {
                            self.li(ray, time, diff, scene, sampler, scratch)
                        }
                    } else {
                        Vec3::ZERO
                    };
                }
            }
        }
    }

    /// directlighting (strategy "all", triangle lights) for a batch whose
    /// camera rays are traced: camera vertices whose BSDF is one
    /// Lambertian are shaded and their samples drawn lane by lane, then
    /// their light estimates are computed four vertices at a time
    /// ([`all_lights::sample_all_lights_lanes`]); the other lanes go
    /// through [`Integrator::specular_tree_li`] from their shaded vertex.
    /// Lane by lane the same values, samples and rays as `li`.
    fn direct_batch<'a>(
        &self,
        b: &mut Batch,
        scene: &'a RenderScene,
        scratch: &mut Scratch,
        uniform: &[TriangleLightPack],
    ) {
        let Integrator::Direct {
            max_depth, packs, ..
        } = self
        else {
            unreachable!("direct_batch is directlighting's");
        };
        let d = &mut b.direct;
        d.clear();
        let mut bsdf = Bsdf::empty();
        for j in 0..b.len {
            // The differentials are copied only where they are read (a
            // copy of every lane's stalled on the camera stage's stores).
            let (ray, time, diff) = (b.rays[j], b.times[j], &b.diffs[j]);
            let sampler = &mut b.samplers[j];
            b.l[j] = Vec3::ZERO;
            // The scalar loop's test: a NaN weight gets no radiance.
            if b.weights[j].partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                continue;
            }
            let mut go_on = |first: First, bsdf: &mut Bsdf<'a>| {
                self.specular_tree_li(ray, first, time, *diff, scene, sampler, scratch, bsdf)
            };
            let Some(hit) = b.hits[j] else {
                b.l[j] = go_on(First::Hit(None), &mut bsdf);
                continue;
            };
            let mut s = scene.geometry.surface_at(&hit, time);
            let material = &scene.materials[s.material as usize];
            if material.is_none() {
                b.l[j] = go_on(First::Hit(Some(hit)), &mut bsdf);
                continue;
            }
            // specular_tree_li's shading of its first vertex.
            let geom = diff
                .as_ref()
                .filter(|_| scene.material_needs_geom[s.material as usize])
                .map(|dd| with_diff(scene, &hit, &s, dd));
            shade_geom(
                scene,
                &hit,
                &mut s,
                material,
                false,
                geom.as_ref(),
                &mut bsdf,
            );
            let Some(r) = bsdf.single_lambertian() else {
                b.l[j] = go_on(First::Shaded { hit, s, geom }, &mut bsdf);
                continue;
            };
            // What specular_tree_li does at a Lambertian first vertex: the
            // vertex counted, the light samples drawn, and no specular
            // children (their samples skipped).
            scratch.counts.closest += 1;
            let wo = -ray.d;
            for pack in packs {
                all_lights::draw_samples(sampler, pack.count, &mut d.u);
            }
            if 1 < *max_depth {
                sampler.skip_2d();
                sampler.skip_2d();
            }
            d.lanes.push(j as u32);
            d.emitted.push(emitted(scene, &s, wo));
            d.verts
                .push(all_lights::LambertVertex::new(&s, &bsdf, r, wo));
            d.sums.push(Vec3::ZERO);
        }
        all_lights::sample_all_lights_lanes(scene, &d.verts, &d.u, uniform, &mut d.sums, scratch);
        for ((&j, &e), &sum) in d.lanes.iter().zip(&d.emitted).zip(&d.sums) {
            // specular_tree_li's sums: local = emitted + estimate, then
            // l += beta · local with l = 0 and beta = 1.
            let local = e + sum;
            b.l[j as usize] = Vec3::ZERO + Vec3::ONE * local;
        }
    }

    /// directlighting and whitted: pbrt-v3's recursive Li, run with an
    /// explicit stack (kept in the per-tile scratch) instead of recursion, so
    /// that a hall of mirrors with a huge `maxdepth` cannot overflow a
    /// thread's stack. Vertices are expanded depth first, reflection before
    /// transmission, as pbrt-v3 recurses; both specular samples of a vertex
    /// are drawn when it is expanded (the same distribution as pbrt-v3, which
    /// draws the transmission sample after the reflection subtree).
    /// `first` says how far the camera ray's vertex has got already;
    /// `bsdf` is the BSDF to shade into (holding the first vertex's when
    /// `first` is [`First::Shaded`]).
    #[allow(clippy::too_many_arguments)]
    fn specular_tree_li<'a>(
        &self,
        ray: Ray,
        first: First,
        time: f32,
        diff: Option<RayDiff>,
        scene: &'a RenderScene,
        sampler: &mut Sampler,
        scratch: &mut Scratch,
        bsdf: &mut Bsdf<'a>,
    ) -> Vec3 {
        let mut stack = std::mem::take(&mut scratch.work);
        stack.clear();
        // The camera ray's vertex is taken without going through the stack
        // (most samples have no other).
        let mut root = Some(Work {
            ray,
            diff,
            beta: Vec3::ONE,
            depth: 0,
            pass: 0,
        });
        let mut l = Vec3::ZERO;
        let mut first = first;
        while let Some(w) = root.take().or_else(|| stack.pop()) {
            scratch.counts.closest += 1;
            let (hit, s, mut geom) = match std::mem::replace(&mut first, First::Trace) {
                First::Shaded { hit, s, geom } => (hit, s, geom),
                f => {
                    let hit = match f {
                        First::Hit(h) => h,
                        _ => scene.geometry.intersect_at(&w.ray, time),
                    };
                    let Some(hit) = hit else {
                        l += w.beta * escaped(scene, w.ray.d);
                        continue;
                    };
                    let mut s = scene.geometry.surface_at(&hit, time);
                    let material = &scene.materials[s.material as usize];
                    if material.is_none() {
                        if w.pass < MAX_PASS_THROUGH {
                            let ray = spawn_ray(s.point.p, s.point.p_error, s.point.n, w.ray.d);
                            // A spawned ray has no differentials (pbrt-v3's SpawnRay).
                            stack.push(Work {
                                ray,
                                diff: None,
                                pass: w.pass + 1,
                                ..w
                            });
                        }
                        continue;
                    }
                    // A material that reads the geometry gets it with the
                    // ray's differentials; otherwise it is computed only if
                    // specular children will carry differentials.
                    let geom = w
                        .diff
                        .as_ref()
                        .filter(|_| scene.material_needs_geom[s.material as usize])
                        .map(|d| with_diff(scene, &hit, &s, d));
                    shade_geom(scene, &hit, &mut s, material, false, geom.as_ref(), bsdf);
                    (hit, s, geom)
                }
            };
            let wo = -w.ray.d;
            if geom.is_none() && bsdf.has_specular() {
                geom = w.diff.as_ref().map(|d| with_diff(scene, &hit, &s, d));
            }
            let mut local = emitted(scene, &s, wo);
            let max_depth = match *self {
                Integrator::Direct {
                    max_depth,
                    strategy,
                    ref lights,
                    ref n_light_samples,
                    ref packs,
                    ..
                } => {
                    if !scene.lights.is_empty() {
                        local += match (strategy, bsdf.single_lambertian()) {
                            (DirectStrategy::All, Some(r)) if !packs.is_empty() => {
                                all_lights::sample_all_lights_packed(
                                    scene, &s, bsdf, r, wo, sampler, scratch, packs,
                                )
                            }
                            (DirectStrategy::All, _) => sample_all_lights(
                                scene,
                                &s,
                                bsdf,
                                wo,
                                sampler,
                                scratch,
                                n_light_samples,
                            ),
                            (DirectStrategy::One, _) => {
                                sample_one_light(scene, &s, bsdf, wo, sampler, scratch, lights)
                            }
                        };
                    }
                    max_depth
                }
                Integrator::Whitted { max_depth } => {
                    for light in &scene.lights {
                        let u = sampler.get_2d();
                        let Some(ls) = light.sample_li(&s.point, u, &scene.geometry) else {
                            continue;
                        };
                        if ls.li == Vec3::ZERO || ls.pdf == 0.0 {
                            continue;
                        }
                        let f = bsdf.f(wo, ls.wi, BxdfFlags::ALL);
                        if f != Vec3::ZERO {
                            scratch.counts.shadow += 1;
                            if !scene.geometry.occluded_at(&ls.shadow, s.time) {
                                local += f * ls.li * ls.wi.dot(s.point.ns).abs() / ls.pdf;
                            }
                        }
                    }
                    max_depth
                }
                Integrator::Path { .. } | Integrator::VolPath { .. } => {
                    unreachable!("path and volpath are not recursive")
                }
            };
            l += w.beta * local;
            if w.depth + 1 < max_depth {
                let mut children = [None, None];
                for (i, filter) in [
                    BxdfFlags::SPECULAR_REFLECTION,
                    BxdfFlags::SPECULAR_TRANSMISSION,
                ]
                .into_iter()
                .enumerate()
                {
                    if !bsdf.has_specular() {
                        // pbrt-v3 draws the sample and the BSDF ignores it.
                        sampler.skip_2d();
                        continue;
                    }
                    let u = sampler.get_2d();
                    if let Some(bs) = bsdf.sample(wo, u, filter) {
                        let cos = bs.wi.dot(s.point.ns).abs();
                        if bs.pdf > 0.0 && bs.f != Vec3::ZERO && cos != 0.0 {
                            let ray = spawn_ray(s.point.p, s.point.p_error, s.point.n, bs.wi);
                            let beta = w.beta * bs.f * cos / bs.pdf;
                            let diff = match (&w.diff, &geom) {
                                (Some(d), Some(g)) if i == 0 => {
                                    Some(g.reflected(s.point.p, s.point.ns, wo, bs.wi, d))
                                }
                                (Some(d), Some(g)) => Some(
                                    g.transmitted(s.point.p, s.point.ns, wo, bs.wi, bsdf.eta, d),
                                ),
                                _ => None,
                            };
                            children[i] = Some(Work {
                                ray,
                                diff,
                                beta,
                                depth: w.depth + 1,
                                pass: 0,
                            });
                        }
                    }
                }
                // Pushed transmission first so that reflection is expanded first.
                stack.extend(children.into_iter().rev().flatten());
            }
        }
        scratch.work = stack;
        l
    }
}

/// Where [`Integrator::specular_tree_li`] starts its camera vertex.
#[allow(clippy::large_enum_variant)] // one per camera ray, on the stack, never stored
enum First {
    /// The camera ray is still to be traced.
    Trace,
    /// The camera ray's intersection, already traced.
    Hit(Option<Hit>),
    /// The camera ray's hit already shaded: its surface (with the BSDF's
    /// shading normal) and its differential geometry, if computed; the
    /// BSDF is the one handed to `specular_tree_li`.
    Shaded {
        hit: Hit,
        s: SurfaceHit,
        geom: Option<DiffGeom>,
    },
}

/// The differential geometry of `hit` at `s`, with the screen-space
/// derivatives of ray differentials `d`.
#[inline]
fn with_diff(scene: &RenderScene, hit: &Hit, s: &SurfaceHit, d: &RayDiff) -> DiffGeom {
    let mut g = scene.geometry.diff_geom(hit, s);
    g.compute_differentials(s.point.p, s.point.n, d);
    g
}

/// The BSDF of `material` at a hit, built into `bsdf`, with the hit's
/// differential geometry (and its screen-space derivatives when the ray
/// has differentials) computed only if the material uses it.
#[inline(always)]
fn shade<'a>(
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
            let mut g = scene.geometry.diff_geom(hit, s);
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
fn shade_geom<'a>(
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
        let geom = scene.geometry.diff_geom(hit, s);
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
fn emitted(scene: &RenderScene, s: &SurfaceHit, wo: Vec3) -> Vec3 {
    match s.light {
        Some(i) => scene.lights[i as usize].emitted(s.point.n, wo),
        None => Vec3::ZERO,
    }
}

/// Radiance of rays with direction `d` that leave the scene.
#[inline]
fn escaped(scene: &RenderScene, d: Vec3) -> Vec3 {
    scene
        .infinite_lights
        .iter()
        .map(|&i| scene.lights[i as usize].le(d))
        .sum()
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
fn path_li(
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
    ray: Ray,
    /// Its differentials (only the camera ray has them: pbrt-v3's path
    /// tracer spawns every later ray without them, specular bounces
    /// included).
    diff: Option<RayDiff>,
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
    scene: &'a RenderScene,
    time: f32,
    max_depth: u32,
    rr_threshold: f32,
    lights: &'a LightSampler,
}

/// One vertex of the path tracer: `hit` is the intersection of `st.ray`
/// (already traced and counted). Gathers emission and a light sample, then
/// samples the next direction into `st.ray`; false when the path ends.
#[inline(always)]
fn path_step<'a>(
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

/// pbrt-v3's BSSRDF step (`SeparableBSSRDF::Sample_S`), taken by `path`
/// and `volpath` after a BSDF sample that transmits through the boundary
/// of a subsurface material at `s` (with shading frame `frame`): samples an
/// exit point by a probe ray, and returns it with the weight Sp / pdf and
/// the BSDF there (the Sw adapter lobe, wo along the exit's shading
/// normal). `None` ends the path (no profile, no exit found, zero weight),
/// as pbrt-v3's `break`.
#[inline(never)]
#[allow(clippy::too_many_arguments)]
fn subsurface_exit<'a>(
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
        scene.geometry.diff_geom(hit, s)
    } else {
        DiffGeom::ZERO
    };
    let b = material.bssrdf(&ShadingContext {
        hit: s,
        geom: &geom,
    })?;
    let seg = probe_segment(&b, s.point.p, frame, u1, u2)?;
    let (pi, found) = find_exit(
        &scene.geometry,
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
fn sample_exit(pi: &SurfaceHit, exit: &Bsdf, sampler: &mut Sampler) -> Option<BsdfSample> {
    let bs = exit.sample(pi.point.ns, sampler.get_2d(), BxdfFlags::ALL)?;
    (bs.f != Vec3::ZERO && bs.pdf != 0.0).then_some(bs)
}

/// Adds to `l` the radiance of the infinite lights along an escaped ray
/// `d`, times the path throughput `beta`, each weighted against next-event
/// estimation from `from` (the last scattering vertex, `None` after a
/// specular bounce or for the camera ray: weight 1), whose sampled direction
/// had density `pdf`.
#[inline]
fn add_escaped_mis(
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
fn emitted_mis(
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
fn eta_scale_change(bsdf: &Bsdf, bs: &BsdfSample, wo: Vec3, n: Vec3) -> f32 {
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
fn roulette(
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
fn bsdf_mis_weight(
    scene: &RenderScene,
    lights: &LightSampler,
    r: &SurfacePoint,
    light: u32,
    wi: Vec3,
    bsdf_pdf: f32,
) -> f32 {
    // The context of the vertex the BSDF sample left (pbrt-v4's
    // PMF(prevIntrCtx, light)).
    let pmf = lights.pmf(r.p, r.n, light, &scene.lights, &scene.geometry);
    if pmf == 0.0 {
        return 1.0;
    }
    let light_pdf = pmf * scene.lights[light as usize].pdf_li(r, wi, &scene.geometry);
    power_heuristic(1, bsdf_pdf, 1, light_pdf)
}

/// Next-event estimation of the path tracer: choose a light, sample it,
/// trace the shadow ray, weight against the BSDF strategy (whose sample is
/// the path's continuation, see `path_li`).
#[inline]
fn sample_light_mis(
    scene: &RenderScene,
    s: &SurfaceHit,
    bsdf: &Bsdf,
    wo: Vec3,
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
        lights.sample(s.point.p, s.point.n, u, &scene.lights, &scene.geometry)
    else {
        return Vec3::ZERO;
    };
    light_strategy(
        scene,
        s,
        bsdf,
        wo,
        light_index,
        u_light,
        pmf,
        BxdfFlags::ALL,
        scratch,
    )
}

/// The light-sampling strategy of MIS: sample light `light_index`, trace the
/// shadow ray, and weight the sample by the power heuristic against the BSDF
/// density. `pmf` is the light's selection probability as the weights should
/// see it: the path tracer's weights include it; pbrt-v3's EstimateDirect
/// passes 1 and divides by the selection probability afterwards. `flags`:
/// the lobes of the BSDF strategy it is weighted against (all of them for
/// the path tracer, whose continuation is that strategy; the non-specular
/// ones for EstimateDirect, as pbrt-v3).
#[allow(clippy::too_many_arguments)]
#[inline]
fn light_strategy(
    scene: &RenderScene,
    s: &SurfaceHit,
    bsdf: &Bsdf,
    wo: Vec3,
    light_index: u32,
    u_light: Vec2,
    pmf: f32,
    flags: BxdfFlags,
    scratch: &mut Scratch,
) -> Vec3 {
    let light = &scene.lights[light_index as usize];
    // Read in place: moved out of the option, the sample was copied by
    // wide loads that stalled on the narrower stores that had just made it.
    let sample = light.sample_li(&s.point, u_light, &scene.geometry);
    let Some(ls) = sample.as_ref() else {
        return Vec3::ZERO;
    };
    if ls.pdf.is_nan() || ls.pdf <= 0.0 || ls.li == Vec3::ZERO {
        return Vec3::ZERO;
    }
    let (f, scattering_pdf) = bsdf.f_pdf(wo, ls.wi, flags);
    let f = f * ls.wi.dot(s.point.ns).abs();
    if f == Vec3::ZERO {
        return Vec3::ZERO;
    }
    scratch.counts.shadow += 1;
    if scene.geometry.occluded_at(&ls.shadow, s.time) {
        return Vec3::ZERO;
    }
    let light_pdf = pmf * ls.pdf;
    if light.is_delta() {
        return f * ls.li / light_pdf;
    }
    f * ls.li * power_heuristic(1, light_pdf, 1, scattering_pdf) / light_pdf
}

/// pbrt-v3's UniformSampleOneLight with a light distribution.
#[inline]
fn sample_one_light(
    scene: &RenderScene,
    s: &SurfaceHit,
    bsdf: &Bsdf,
    wo: Vec3,
    sampler: &mut Sampler,
    scratch: &mut Scratch,
    lights: &LightSampler,
) -> Vec3 {
    if scene.lights.is_empty() {
        return Vec3::ZERO;
    }
    let u = sampler.get_1d();
    let Some((light, pmf)) = lights.sample(s.point.p, s.point.n, u, &scene.lights, &scene.geometry)
    else {
        return Vec3::ZERO;
    };
    let u_light = sampler.get_2d();
    let u_scatter = sampler.get_2d();
    estimate_direct(scene, s, bsdf, wo, light, u_light, u_scatter, scratch) / pmf
}

/// pbrt-v3's UniformSampleAllLights with per-pixel sample arrays.
fn sample_all_lights(
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
fn estimate_direct(
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
