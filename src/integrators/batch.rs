//! The samples a thread renders together: [`Batch`] holds per lane its
//! sampler, camera ray and result; each kind's `li_batch` renders them
//! (`path` and `volpath` one vertex of every lane at a time, by
//! [`trace_paths`]; directlighting and whitted trace all camera rays first,
//! by [`trace_camera_rays`], and directlighting's Lambertian camera
//! vertices are lit four at a time through [`super::direct_lanes`]).

use super::direct_lanes::DirectLanes;
use super::path::{path_step, NoMedium, PathMedium, PathParams, PathSettings, PathState};
use super::volpath::RayMedium;
use super::Scratch;
use crate::accel::{Hit, PACKET_MAX};
use crate::geometry::{Ray, RayDiff};
use crate::integrators::RenderScene;
use crate::lights::LightSampler;
use crate::materials::Bsdf;
use crate::samplers::Sampler;
use glam::Vec3;

/// The samples a thread renders together (see [`super::Integrator::li_batch`]):
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
    pub(super) hits: Vec<Option<Hit>>,
    /// `path`'s and `volpath`'s paths, one per lane (empty for the other
    /// kinds).
    pub(super) paths: Vec<PathState<NoMedium>>,
    pub(super) vol_paths: Vec<PathState<RayMedium>>,
    active: Vec<u32>,
    /// directlighting's Lambertian camera vertices.
    pub(super) direct: DirectLanes,
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
                + size_of::<u32>())
            + self.paths.capacity() * size_of::<PathState<NoMedium>>()
            + self.vol_paths.capacity() * size_of::<PathState<RayMedium>>()
            + self.samplers.iter().map(|s| s.heap_bytes()).sum::<usize>()
            + self.direct.bytes()
    }

    /// A batch of `lanes` lanes, each with a copy of `sampler` (a kind adds
    /// what it keeps per lane).
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
            paths: Vec::new(),
            vol_paths: Vec::new(),
            active: Vec::with_capacity(lanes),
            direct: DirectLanes::default(),
        }
    }
}

/// `path` and `volpath` over a batch, lane by lane the same values bit for
/// bit as `path_li`: all the batch's paths (in `states`, one per lane,
/// starting in medium `start`) advance one vertex at a time (all closest
/// hits, then all shading and light sampling).
#[allow(clippy::too_many_arguments)]
pub(super) fn trace_paths<M: PathMedium>(
    b: &mut Batch,
    states: &mut [PathState<M>],
    start: M,
    settings: &PathSettings,
    lights: &LightSampler,
    scene: &RenderScene,
    scratch: &mut Scratch,
) {
    b.active.clear();
    for (j, st) in states.iter_mut().enumerate().take(b.len) {
        b.l[j] = Vec3::ZERO;
        if b.weights[j] > 0.0 {
            st.reset(b.rays[j], &b.diffs[j], start);
            b.active.push(j as u32);
        }
    }
    let mut bsdf = Bsdf::empty();
    // The camera rays of the batch (one pixel's) are coherent: traced as
    // packets.
    let mut camera_rays = true;
    while !b.active.is_empty() {
        scratch.counts.closest += b.active.len() as u64;
        // The bounces are not: traced side by side.
        let rays = |j: usize| states[j].ray;
        closest_of_lanes(&b.active, rays, &b.times, &mut b.hits, scene, camera_rays);
        camera_rays = false;
        let mut kept = 0;
        for k in 0..b.active.len() {
            let j = b.active[k] as usize;
            let p = PathParams::new::<M>(scene, b.times[j], settings, lights);
            if path_step(
                &mut states[j],
                &b.hits[j],
                &p,
                &mut b.samplers[j],
                scratch,
                &mut bsdf,
            ) {
                b.active[kept] = j as u32;
                kept += 1;
            } else {
                b.l[j] = states[j].l;
            }
        }
        b.active.truncate(kept);
    }
}

/// The camera rays of a batch traced (lanes of weight > 0), their hits in
/// `b.hits` (directlighting and whitted).
pub(super) fn trace_camera_rays(b: &mut Batch, scene: &RenderScene) {
    b.active.clear();
    for j in 0..b.len {
        if b.weights[j] > 0.0 {
            b.active.push(j as u32);
        }
    }
    closest_of_lanes(&b.active, |j| b.rays[j], &b.times, &mut b.hits, scene, true);
}

/// The closest hits of lanes `active`'s rays (`ray(lane)`, at times
/// `times[lane]`) in `hits[lane]`, up to [`PACKET_MAX`] lanes at a time:
/// traced as packets if they are `coherent`, else side by side.
fn closest_of_lanes(
    active: &[u32],
    ray: impl Fn(usize) -> Ray,
    times: &[f32],
    hits: &mut [Option<Hit>],
    scene: &RenderScene,
    coherent: bool,
) {
    for lanes in active.chunks(PACKET_MAX) {
        let n = lanes.len();
        let mut rays = [Ray::new(Vec3::ZERO, Vec3::Z); PACKET_MAX];
        let mut at = [0f32; PACKET_MAX];
        for (k, &j) in lanes.iter().enumerate() {
            rays[k] = ray(j as usize);
            at[k] = times[j as usize];
        }
        let mut found = [None; PACKET_MAX];
        if coherent {
            scene
                .aggregate
                .intersect_packet(&rays[..n], &at[..n], &mut found[..n]);
        } else {
            scene
                .aggregate
                .intersect_stream(&rays[..n], &at[..n], &mut found[..n]);
        }
        for (&j, &h) in lanes.iter().zip(&found[..n]) {
            hits[j as usize] = h;
        }
    }
}
