//! `mlt`: pbrt-v3's MLTIntegrator (src/integrators/mlt.{h,cpp}),
//! Metropolis light transport in primary sample space over bdpt's paths
//! (Kelemen-style mutations of the uniform values a path is made from,
//! [`MltSampler`]). A path of depth d is one bdpt strategy (s, t),
//! s + t = d + 2, chosen by the camera stream's first value; its camera
//! subpath starts at a film position drawn from the sample bounds, and its
//! contribution is the strategy's MIS-weighted one times the d + 2
//! strategies ([`bdpt`](super::bdpt)'s subpaths and connection, unchanged).
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `maxdepth` | integer | 5 | maximum number of bounces (≥ 0) |
//! | `bootstrapsamples` | integer | 100000 | paths per depth that estimate the normalisation b and seed the chains (≥ 1) |
//! | `chains` | integer | 1000 | Markov chains (≥ 1) |
//! | `mutationsperpixel` | integer | 100 | mutations per pixel of the sample bounds, over all chains (≥ 1) |
//! | `largestepprobability` | float | 0.3 | probability that a mutation redraws every value (0 to 1) |
//! | `sigma` | float | 0.01 | standard deviation of a small step's move of each value (≥ 0) |
//! | `pixelbounds` | | | ignored, with a warning |
//!
//! As pbrt-v3: `bootstrapsamples` × (`maxdepth` + 1) paths, path (i, d)
//! from the sampler seeded with sequence i·(maxdepth + 1) + d, give
//! b = (maxdepth + 1) × their mean luminance and a distribution over them
//! by luminance; chain i (its RNG seeded with sequence i) picks its
//! starting path from that distribution and makes its share of the
//! `mutationsperpixel` × sample-bounds-area mutations; each mutation
//! splats the proposal weighted by its acceptance probability and the
//! current path by its complement, both divided by their luminance; the
//! image is the splats times b / `mutationsperpixel`. Lights are chosen
//! by power. The scene's `Sampler` does not apply (pbrt-v3 neither uses
//! nor mentions it), nor does the pixel filter (splats land on the pixel
//! they are in).
//!
//! Unlike pbrt-v3, whose chains splat into the film with atomic adds, the
//! chains are rendered in fixed groups whose splats are added to the film
//! in chain order, so the image is the same for any thread count. A
//! nonzero `--seed` changes every sequence number (seed 0 is pbrt-v3's).

use super::bdpt::mis_shared::finish_subpath;
use super::bdpt::{camera_subpath, connect, light_subpath, recycle, Ctx};
use super::common::light_sampler;
use super::{max_depth_bidirectional, Integrate, IntegratorKind, IntegratorSettings, RayCounts, Scratch, Splat};
use super::{MAX_DEPTH, PIXEL_BOUNDS};
use crate::cameras::CameraImportance;
use crate::geometry::{luminance, Bounds2i, Ray, RayDiff};
use crate::integrators::RenderScene;
use crate::lights::LightSampler;
use crate::render::film::Film;
use crate::samplers::mlt::{CAMERA_STREAM, CONNECTION_STREAM, LIGHT_STREAM};
use crate::samplers::{CameraSample, MltSampler, Sampler};
use crate::sampling::distribution::DiscreteCdf;
use crate::sampling::rng::{hash_words, Pcg32};
use crate::scene::kind::{Report, Support};
use crate::scene::{LightSampleStrategy, ParamSpec, ParamValues};
use glam::{Vec2, Vec3};
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc;

pub const PARAMS: &[ParamSpec] = &[
    MAX_DEPTH,
    ParamSpec::int(
        "bootstrapsamples",
        100000,
        "paths per depth estimating the normalisation and seeding the chains (≥ 1)",
    ),
    ParamSpec::int("chains", 1000, "Markov chains (≥ 1)"),
    ParamSpec::int(
        "mutationsperpixel",
        100,
        "mutations per pixel, over all chains (≥ 1)",
    ),
    ParamSpec::float(
        "largestepprobability",
        0.3,
        "probability of a large step, which redraws every primary sample (0 to 1)",
    ),
    ParamSpec::float(
        "sigma",
        0.01,
        "standard deviation of a small step's move of each primary sample (≥ 0)",
    ),
    PIXEL_BOUNDS,
];

pub const KIND: IntegratorKind = IntegratorKind {
    name: "mlt",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "Metropolis light transport in primary sample space over bidirectional paths: bootstrap normalisation, Markov chains of large and small steps splatting onto the film; participating media; perspective camera only",
    build: |p, r| IntegratorSettings::Mlt(MltSettings::read(p, r)),
};

/// mlt samples media along bdpt's subpaths; it does not sample subsurface
/// scattering (as pbrt-v3's).
pub const RENDERS_MEDIA: bool = true;
pub const SAMPLES_SUBSURFACE: bool = false;

/// `mlt`'s settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MltSettings {
    pub max_depth: u32,
    pub bootstrap_samples: u32,
    pub chains: u32,
    pub mutations_per_pixel: u32,
    pub large_step_probability: f32,
    pub sigma: f32,
}

impl Default for MltSettings {
    fn default() -> MltSettings {
        MltSettings {
            max_depth: 5,
            bootstrap_samples: 100000,
            chains: 1000,
            mutations_per_pixel: 100,
            large_step_probability: 0.3,
            sigma: 0.01,
        }
    }
}

/// The most bootstrap paths (pbrt-v3 counts them in an `int`).
const MAX_BOOTSTRAP_PATHS: i64 = i32::MAX as i64;

impl MltSettings {
    /// The settings of a statement's parameters. pbrt-v3 checks none of
    /// them; values it would crash on or misuse (no chains, no bootstrap
    /// paths or mutations, a probability outside [0, 1], a negative or
    /// non-finite sigma) are errors here.
    pub fn read(p: &ParamValues, r: &mut dyn Report) -> MltSettings {
        let d = MltSettings::default();
        let max_depth = max_depth_bidirectional(p, r, "mlt");
        let mut count = |name: &'static str, default: u32| {
            let v = p.int(name);
            if v < 1 {
                r.error(
                    Some(name),
                    format!("\"{name}\" is {v}: it must be ≥ 1"),
                    "must be ≥ 1",
                );
                default
            } else {
                v as u32
            }
        };
        let mut bootstrap_samples = count("bootstrapsamples", d.bootstrap_samples);
        let chains = count("chains", d.chains);
        let mutations_per_pixel = count("mutationsperpixel", d.mutations_per_pixel);
        if bootstrap_samples as i64 * (max_depth as i64 + 1) > MAX_BOOTSTRAP_PATHS {
            r.error(
                Some("bootstrapsamples"),
                format!("\"bootstrapsamples\" × (maxdepth + 1) is {} paths: at most {MAX_BOOTSTRAP_PATHS}", bootstrap_samples as i64 * (max_depth as i64 + 1)),
                "too many bootstrap paths",
            );
            bootstrap_samples = 1;
        }
        // Each bootstrap path keeps its weight (f32) and its prefix sum
        // (f64) in the distribution the chains start from.
        let paths = bootstrap_samples as u64 * (max_depth as u64 + 1);
        if let Err(why) = crate::scene::memory::check_budget("the bootstrap paths' distribution", paths * 12) {
            r.error(
                Some("bootstrapsamples"),
                format!("\"bootstrapsamples\" × (maxdepth + 1) is {paths} paths: {why}"),
                "too many bootstrap paths",
            );
            bootstrap_samples = 1;
        }
        let large_step_probability = p.float("largestepprobability");
        let large_step_probability = if (0.0..=1.0).contains(&large_step_probability) {
            large_step_probability
        } else {
            r.error(
                Some("largestepprobability"),
                format!("\"largestepprobability\" is {large_step_probability}: a probability must be between 0 and 1"),
                "not a probability",
            );
            d.large_step_probability
        };
        let sigma = p.float("sigma");
        let sigma = if sigma >= 0.0 && sigma.is_finite() {
            sigma
        } else {
            r.error(
                Some("sigma"),
                format!("\"sigma\" is {sigma}: it must be a finite number ≥ 0"),
                "bad sigma",
            );
            d.sigma
        };
        MltSettings {
            max_depth,
            bootstrap_samples,
            chains,
            mutations_per_pixel,
            large_step_probability,
            sigma,
        }
    }

    pub fn summary(&self) -> String {
        format!(
            "maxdepth {}, bootstrap samples {}, chains {}, mutations per pixel {}, large step probability {}, sigma {}",
            self.max_depth,
            self.bootstrap_samples,
            self.chains,
            self.mutations_per_pixel,
            self.large_step_probability,
            self.sigma
        )
    }
}

/// The runtime `mlt`: its settings, the light distribution (by power), the
/// film's sample bounds and the scene's bounding radius.
pub struct Mlt {
    settings: MltSettings,
    lights: LightSampler,
    sample_bounds: Option<Bounds2i>,
    scene_radius: f32,
    /// The plain MIS weights (`RenderOptions::scalar`, the tests'
    /// reference).
    plain: bool,
}

/// What [`Mlt::render`] renders with.
pub struct MltRun<'r> {
    pub scene: &'r RenderScene,
    pub seed: u64,
    pub pool: &'r rayon::ThreadPool,
}

/// What a render did, for the statistics.
#[derive(Clone, Copy, Debug, Default)]
pub struct MltDone {
    pub rays: RayCounts,
    /// Bootstrap paths and mutations.
    pub bootstrap_paths: u64,
    pub mutations: u64,
    pub accepted: u64,
    /// The normalisation: the image's mean luminance over the sample bounds.
    pub b: f64,
}

/// Mutations per group of chains: the unit of parallel work whose splats
/// are added to the film in order (about 1.5 MiB of splats at most). Small,
/// so that the threads end the chains at nearly the same time
/// (`scenes/mlt/caustic.pbrt` had four groups for two threads, so one
/// thread could idle while the other ran the last); the image does not
/// depend on it (splats are added in chain order whatever the grouping).
const GROUP_MUTATIONS: u64 = 1 << 15;

/// Bootstrap samples (each `maxdepth` + 1 paths) per unit of parallel
/// work, and the most rounds of them between progress reports.
const BOOTSTRAP_CHUNK: usize = 256;
const BOOTSTRAP_ROUNDS: usize = 16;

/// The sequence number of PCG32 stream `index` under `seed` (seed 0:
/// pbrt-v3's, the index itself).
fn sequence(index: u64, seed: u64) -> u64 {
    if seed == 0 {
        index
    } else {
        hash_words(&[index, seed, 0x6d6c74])
    }
}

#[inline]
fn mlt(s: &mut Sampler) -> &mut MltSampler {
    match s {
        Sampler::Mlt(m) => m,
        _ => unreachable!("mlt paths take an MltSampler"),
    }
}

/// pbrt-v3's `std::min((Float)1, ratio)`: 1 for a NaN ratio.
#[inline]
fn acceptance(ratio: f32) -> f32 {
    if ratio < 1.0 {
        ratio
    } else {
        1.0
    }
}

impl Mlt {
    pub fn new(settings: &MltSettings, scene: &RenderScene, scalar: bool) -> Mlt {
        Mlt {
            plain: scalar,
            settings: *settings,
            lights: light_sampler(LightSampleStrategy::Power, scene),
            sample_bounds: None,
            scene_radius: scene.aggregate.bounds.bounding_sphere().1,
        }
    }

    pub fn settings(&self) -> &MltSettings {
        &self.settings
    }

    /// Renders every chain, adding their splats to `film` (whose splat
    /// scale it sets to b / `mutationsperpixel`); `progress(done, total,
    /// film)` is called after each round of bootstrap paths and each group
    /// of chains added.
    pub fn render(
        &self,
        run: &MltRun,
        film: &mut Film,
        progress: &mut dyn FnMut(usize, usize, &Film),
    ) -> MltDone {
        let mut done = MltDone::default();
        let scene = run.scene;
        let Some(bounds) = self.sample_bounds else {
            return done;
        };
        // pbrt-v3 renders nothing without lights.
        if scene.lights.is_empty() {
            progress(1, 1, film);
            return done;
        }
        let Ok(camera) = CameraImportance::new(&scene.camera, bounds, "mlt") else {
            return done;
        };
        let base = Ctx {
            scene,
            camera,
            lights: &self.lights,
            p_camera: Vec3::ZERO,
            camera_medium: if scene.media.is_empty() {
                None
            } else {
                scene.camera_medium
            },
            scene_radius: self.scene_radius,
            plain: self.plain,
        };
        let paths = PathMaker {
            base: &base,
            bounds,
            moving: scene.camera.is_moving() || scene.aggregate.moving_count() > 0,
        };
        let s = &self.settings;
        let depths = s.max_depth as usize + 1;
        let (seed, mpp) = (run.seed, s.mutations_per_pixel);
        let sampler_for = |index: usize| {
            Sampler::Mlt(MltSampler::new(
                mpp,
                sequence(index as u64, seed),
                s.sigma,
                s.large_step_probability,
            ))
        };

        // The chains, in groups of consecutive chains (fixed by the
        // settings and the film alone).
        let total = mpp as u64 * bounds.area().max(0) as u64;
        let n_chains = s.chains as u64;
        let chain_start = |i: u64| ((i as u128 * total as u128) / n_chains as u128) as u64;
        let per_group = ((GROUP_MUTATIONS as u128 * n_chains as u128) / total.max(1) as u128)
            .clamp(1, n_chains as u128) as u64;
        let groups = n_chains.div_ceil(per_group) as usize;

        // The bootstrap paths (b and the chains' starting points), in
        // rounds between which progress is reported.
        let mut weights = vec![0.0f32; s.bootstrap_samples as usize * depths];
        let chunk_len = BOOTSTRAP_CHUNK * depths;
        let n_chunks = weights.len().div_ceil(chunk_len);
        let rounds = n_chunks.min(BOOTSTRAP_ROUNDS);
        let steps = rounds + groups;
        let chunks_per_round = n_chunks.div_ceil(rounds);
        for (round, part) in weights
            .chunks_mut(chunks_per_round * chunk_len)
            .enumerate()
        {
            let first = round * chunks_per_round * chunk_len;
            let rays = run.pool.install(|| {
                part.par_chunks_mut(chunk_len)
                    .enumerate()
                    .map(|(k, chunk)| {
                        let mut scratch = Scratch::default();
                        let mut sampler = sampler_for(0);
                        for (j, w) in chunk.iter_mut().enumerate() {
                            let index = first + k * chunk_len + j;
                            mlt(&mut sampler).restart_unkept(sequence(index as u64, seed));
                            let depth = (index % depths) as u32;
                            *w = luminance(paths.path(&mut sampler, depth, &mut scratch).0);
                        }
                        scratch.counts()
                    })
                    .reduce(RayCounts::default, |mut a, b| {
                        a.add(&b);
                        a
                    })
            });
            done.rays.add(&rays);
            progress(round + 1, steps, film);
        }
        done.bootstrap_paths = weights.len() as u64;
        let bootstrap = DiscreteCdf::new(&weights);
        drop(weights);
        let b = bootstrap.func_int() * depths as f32;
        done.b = b as f64;
        film.set_splat_scale(b as f64 / mpp as f64);
        if b.is_nan() || b <= 0.0 {
            progress(steps, steps, film);
            return done;
        }

        let next = AtomicUsize::new(0);
        let (tx, rx) = mpsc::channel::<(usize, Group)>();
        let chain = |i: u64, group: &mut Group, scratch: &mut Scratch| {
            let n = chain_start(i + 1).min(total) - chain_start(i);
            let mut rng = Pcg32::with_sequence(sequence(i, seed));
            let index = bootstrap.sample_index(rng.uniform_f32());
            let depth = (index % depths) as u32;
            let mut sampler = sampler_for(index);
            let (mut l_current, mut p_current) = paths.path(&mut sampler, depth, scratch);
            for _ in 0..n {
                mlt(&mut sampler).start_iteration();
                let (l_proposed, p_proposed) = paths.path(&mut sampler, depth, scratch);
                let (y_proposed, y_current) = (luminance(l_proposed), luminance(l_current));
                let accept = acceptance(y_proposed / y_current);
                if accept > 0.0 {
                    group.splat(p_proposed, l_proposed * accept / y_proposed);
                }
                group.splat(p_current, l_current * (1.0 - accept) / y_current);
                if rng.uniform_f32() < accept {
                    p_current = p_proposed;
                    l_current = l_proposed;
                    mlt(&mut sampler).accept();
                    group.accepted += 1;
                } else {
                    mlt(&mut sampler).reject();
                }
            }
            group.mutations += n;
        };
        let pool = run.pool;
        std::thread::scope(|ts| {
            let (next, chain) = (&next, &chain);
            ts.spawn(move || {
                pool.broadcast(|_| {
                    let tx = tx.clone();
                    loop {
                        let g = next.fetch_add(1, Ordering::Relaxed);
                        if g >= groups {
                            break;
                        }
                        let mut group = Group::default();
                        let mut scratch = Scratch::default();
                        let first = g as u64 * per_group;
                        for i in first..(first + per_group).min(n_chains) {
                            chain(i, &mut group, &mut scratch);
                        }
                        group.rays = scratch.counts();
                        if tx.send((g, group)).is_err() {
                            break;
                        }
                    }
                });
                drop(tx);
            });
            // Groups are added in order; those finished early wait.
            let mut waiting: Vec<Option<Group>> = Vec::new();
            let mut merged = 0usize;
            for (g, group) in rx.iter() {
                let slot = g - merged;
                if waiting.len() <= slot {
                    waiting.resize_with(slot + 1, || None);
                }
                waiting[slot] = Some(group);
                let ready = waiting.iter().take_while(|w| w.is_some()).count();
                for group in waiting.drain(..ready).flatten() {
                    film.add_splats(&group.splats);
                    done.rays.add(&group.rays);
                    done.mutations += group.mutations;
                    done.accepted += group.accepted;
                    merged += 1;
                    progress(rounds + merged, steps, film);
                }
            }
        });
        done
    }
}

/// A group of chains' splats in order, and its counts.
#[derive(Default)]
struct Group {
    splats: Vec<Splat>,
    rays: RayCounts,
    mutations: u64,
    accepted: u64,
}

impl Group {
    #[inline]
    fn splat(&mut self, p_film: Vec2, l: Vec3) {
        // A zero adds nothing to the film's sums.
        if l != Vec3::ZERO {
            self.splats.push(Splat {
                p_film,
                l,
                layer: 0,
            });
        }
    }
}

/// Makes a path from an [`MltSampler`]'s values (pbrt-v3's `MLTIntegrator::L`).
struct PathMaker<'m, 'a> {
    base: &'m Ctx<'a>,
    bounds: Bounds2i,
    moving: bool,
}

impl PathMaker<'_, '_> {
    /// The path of depth `depth` the sampler's current values make: its
    /// contribution (times the number of strategies) and film position.
    fn path(&self, sampler: &mut Sampler, depth: u32, scratch: &mut Scratch) -> (Vec3, Vec2) {
        let scene = self.base.scene;
        mlt(sampler).start_stream(CAMERA_STREAM);
        let (s, t, strategies) = if depth == 0 {
            (0, 2, 1)
        } else {
            let n = depth as usize + 2;
            let s = ((sampler.get_1d() * n as f32) as usize).min(n - 1);
            (s, n - s, n)
        };
        let (lo, hi) = (self.bounds.min.as_vec2(), self.bounds.max.as_vec2());
        let u = sampler.get_2d();
        let p_raster = (Vec2::ONE - u) * lo + u * hi;
        let time_u = sampler.get_1d();
        let cs = CameraSample {
            p_film: p_raster,
            p_lens: sampler.get_2d(),
            time: time_u,
        };
        let time = if self.moving {
            scene.camera.time(&cs)
        } else {
            0.0
        };
        let (ray, diff, weight): (Ray, Option<RayDiff>, f32) = if scene.differentials {
            let scale = 1.0 / (mlt(sampler).samples_per_pixel() as f32).sqrt();
            let (r, d, w) = scene.camera.generate_ray_differential(&cs, scale);
            (r, Some(d), w)
        } else {
            let (r, w) = scene.camera.generate_ray(&cs);
            (r, None, w)
        };
        if weight <= 0.0 {
            return (Vec3::ZERO, p_raster);
        }
        let c = Ctx {
            p_camera: ray.o,
            camera: self.base.camera.clone(),
            ..*self.base
        };
        let mut cam = recycle(std::mem::take(&mut scratch.bdpt.camera));
        let mut light = recycle(std::mem::take(&mut scratch.bdpt.light));
        let mut out = (Vec3::ZERO, p_raster);
        let n_camera = camera_subpath(
            &c,
            (ray, time, diff),
            t as u32 - 1,
            &mut cam,
            sampler,
            scratch,
        );
        if n_camera == t {
            mlt(sampler).start_stream(LIGHT_STREAM);
            let n_light = if s == 0 {
                0
            } else {
                light_subpath(&c, time, s as u32 - 1, &mut light, sampler, scratch)
            };
            if n_light == s {
                // The one strategy connects the subpaths' last vertices.
                if !c.plain {
                    finish_subpath(&c, &mut cam, t - 1);
                    finish_subpath(&c, &mut light, s.saturating_sub(1));
                }
                mlt(sampler).start_stream(CONNECTION_STREAM);
                let st = connect::connect(&c, &mut light, &mut cam, (s, t), None, sampler, scratch);
                let p = if t == 1 {
                    st.p_raster.unwrap_or(p_raster)
                } else {
                    p_raster
                };
                out = (st.l * strategies as f32, p);
            }
        }
        scratch.bdpt.camera = recycle(cam);
        scratch.bdpt.light = recycle(light);
        out
    }
}

impl Integrate for Mlt {
    fn light_sampler(&self) -> Option<&LightSampler> {
        Some(&self.lights)
    }

    fn prepare_film(&mut self, scene: &RenderScene, sample_bounds: Bounds2i) -> Result<(), String> {
        CameraImportance::new(&scene.camera, sample_bounds, "mlt")?;
        self.sample_bounds = Some(sample_bounds);
        Ok(())
    }

    /// Not called: mlt has its own render loop ([`Mlt::render`]).
    fn li(
        &self,
        _ray: Ray,
        _time: f32,
        _diff: Option<RayDiff>,
        _scene: &RenderScene,
        _sampler: &mut Sampler,
        _scratch: &mut Scratch,
    ) -> Vec3 {
        Vec3::ZERO
    }
}
