//! The samples a thread renders together: [`Batch`] holds per lane its
//! sampler, camera ray and result; [`Integrator::li_batch`] renders them
//! (`path` one vertex of every lane at a time, directlighting's Lambertian
//! camera vertices four at a time through [`super::direct_lanes`]).

use super::common::{emitted, shade_geom, with_diff};
use super::direct_lanes;
use super::path::{path_step, PathParams, PathState};
use super::{First, Integrator, Scratch};
use crate::accel::Hit;
use crate::geometry::{Ray, RayDiff};
use crate::integrators::RenderScene;
use crate::lights::TriangleLightPack;
use crate::materials::Bsdf;
use crate::samplers::Sampler;
use glam::{Vec2, Vec3};

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
    verts: Vec<direct_lanes::LambertVertex>,
    emitted: Vec<Vec3>,
    u: Vec<Vec2>,
    sums: Vec<Vec3>,
}

impl DirectLanes {
    /// Bytes held (after a batch has grown them).
    fn bytes(&self) -> usize {
        use std::mem::size_of;
        self.lanes.capacity() * size_of::<u32>()
            + self.verts.capacity() * size_of::<direct_lanes::LambertVertex>()
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

impl Integrator {
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

    /// [`Integrator::li`] for the camera rays of a batch of samples, lane by
    /// lane the same values bit for bit: `path` advances all the batch's
    /// paths one vertex at a time (all closest hits, then all shading and
    /// light sampling), directlighting and whitted trace all camera rays
    /// first, volpath renders lane by lane. Each lane has its own sampler,
    /// positioned at its sample; lanes of weight 0 get no radiance.
    pub fn li_batch(&self, b: &mut Batch, scene: &RenderScene, scratch: &mut Scratch) {
        let n = b.len;
        match self {
            Integrator::Path { settings, lights } => {
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
                            max_depth: settings.max_depth,
                            rr_threshold: settings.rr_threshold,
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
    /// ([`direct_lanes::sample_all_lights_lanes`]); the other lanes go
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
            settings, packs, ..
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
                d.u.extend_from_slice(&direct_lanes::draw_samples(sampler, pack.count));
            }
            if 1 < settings.max_depth {
                sampler.skip_2d();
                sampler.skip_2d();
            }
            d.lanes.push(j as u32);
            d.emitted.push(emitted(scene, &s, wo));
            d.verts
                .push(direct_lanes::LambertVertex::new(&s, &bsdf, r, wo));
            d.sums.push(Vec3::ZERO);
        }
        direct_lanes::sample_all_lights_lanes(scene, &d.verts, &d.u, uniform, &mut d.sums, scratch);
        for ((&j, &e), &sum) in d.lanes.iter().zip(&d.emitted).zip(&d.sums) {
            // specular_tree_li's sums: local = emitted + estimate, then
            // l += beta · local with l = 0 and beta = 1.
            let local = e + sum;
            b.l[j as usize] = Vec3::ZERO + Vec3::ONE * local;
        }
    }
}
