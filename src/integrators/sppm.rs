//! `sppm`: pbrt-v3's SPPMIntegrator, stochastic progressive photon
//! mapping. Each iteration (1) follows one camera path per pixel through
//! specular bounces to its first diffuse vertex (or a glossy one at the
//! last depth), adding emission and direct lighting (one light chosen
//! uniformly, pbrt-v3's UniformSampleOneLight) on the way, and keeps that
//! vertex as the pixel's visible point; (2) puts the visible points in a
//! hash grid; (3) traces `photonsperiteration` photons from lights chosen
//! by power (each light's [`crate::lights::LightModel::sample_le`]), each
//! photon vertex after the first adding its power times the visible
//! point's BSDF to every visible point within the pixel's radius; (4)
//! shrinks each pixel's radius by pbrt-v3's rule (γ = 2/3). The image is
//! the direct light averaged over iterations plus τ / (N_p · π · r²).
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `iterations` | integer | 64 | iterations (≥ 1); `numiterations` is read when it is absent |
//! | `photonsperiteration` | integer | −1 | photons per iteration (−1: one per pixel) |
//! | `maxdepth` | integer | 5 | bounces of camera paths and photon paths |
//! | `radius` | float | 1 | initial search radius (> 0), in world units |
//! | `imagewritefrequency` | integer | never | write the image every this many iterations |
//! | `pixelbounds` | | | ignored, with a warning |
//!
//! As pbrt-v3, the camera pass uses its own Halton sampler of
//! `iterations` samples per pixel (iteration i takes sample i; the scene's
//! `Sampler` is not used), and photon i of iteration k takes the unscrambled
//! radical inverses of index k·photonsperiteration + i, one prime base per
//! dimension. The image has no pixel filter (pbrt-v3 sets the film's pixels
//! directly). Unlike pbrt-v3, which adds photons with floating-point
//! atomics, photons are traced in fixed chunks and their contributions
//! added to the pixels in photon order, so the image does not depend on the
//! thread count. Within a row of the camera pass and within a chunk of
//! photons, sixteen paths advance side by side, their rays traced together
//! (`Aggregate::intersect_stream`, which overlaps their traversals); each
//! path's values are those it has alone. Photons cross transmissive surfaces as importance (the
//! radiance-mode (η_i/η_t)² of dielectric transmission is undone).

use crate::accel::Hit;
use super::common::{emitted, escaped, light_sampler, shade};
use super::directlighting::sample_one_light;
use super::{
    max_depth, Integrate, IntegratorKind, IntegratorSettings, RayCounts, Scratch, MAX_DEPTH,
    MAX_PASS_THROUGH, PIXEL_BOUNDS,
};
use crate::geometry::{luminance, spawn_ray, Bounds2i, Bounds3, Ray, RayDiff};
use crate::integrators::RenderScene;
use crate::bxdf::{Bsdf, BsdfHead, BxdfFlags, Lobe, MAX_BXDFS};
use crate::lights::LightSampler;
use crate::samplers::lowdiscrepancy::{RadicalTable, PRIMES};
use crate::samplers::{CameraSample, Sampler};
use crate::scene::kind::{Report, Support};
use crate::scene::{LightSampleStrategy, ParamSpec, ParamValues, SamplerDesc, SamplerKind};
use glam::{DVec3, IVec2, IVec3, Vec2, Vec3};
use rayon::prelude::*;
use std::sync::atomic::{AtomicU32, Ordering};

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::int_opt("iterations", "iterations (≥ 1; default 64)"),
    ParamSpec::int_opt(
        "numiterations",
        "iterations, read when \"iterations\" is absent",
    ),
    ParamSpec::int(
        "photonsperiteration",
        -1,
        "photons traced per iteration (-1: the number of pixels)",
    ),
    MAX_DEPTH,
    ParamSpec::float("radius", 1.0, "initial photon search radius (> 0)"),
    ParamSpec::int_opt(
        "imagewritefrequency",
        "write the image every this many iterations (≥ 1; default: at the end only)",
    ),
    PIXEL_BOUNDS,
];

pub const KIND: IntegratorKind = IntegratorKind {
    name: "sppm",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "stochastic progressive photon mapping: visible points from camera paths, photons from lights chosen by power, per-pixel radius reduction",
    build: |p, r| IntegratorSettings::Sppm(SppmSettings::read(p, r)),
};

/// SPPM sees no media and no subsurface scattering (as pbrt-v3's).
pub const RENDERS_MEDIA: bool = false;
pub const SAMPLES_SUBSURFACE: bool = false;

/// `sppm`'s settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SppmSettings {
    pub iterations: u32,
    /// Photons per iteration; 0: one per pixel of the (cropped) film.
    pub photons_per_iteration: u32,
    pub max_depth: u32,
    pub radius: f32,
    /// Write the image after every this many iterations (0: at the end).
    pub write_frequency: u32,
}

impl Default for SppmSettings {
    fn default() -> Self {
        SppmSettings {
            iterations: 64,
            photons_per_iteration: 0,
            max_depth: 5,
            radius: 1.0,
            write_frequency: 0,
        }
    }
}

/// The most photons per iteration (pbrt-v3 counts them in an `int`).
const MAX_PHOTONS: i32 = i32::MAX;

/// The most photons per iteration a statement may ask for (2^24, the bound
/// of `pixelsamples`): an iteration's time stays bounded.
const MAX_PHOTONS_PARAM: i32 = 1 << 24;

impl SppmSettings {
    /// The settings of a statement's parameters, with pbrt-v3's defaults;
    /// values pbrt-v3 would misuse are warnings, and the default is used
    /// (a negative `maxdepth` is an error, as for every integrator).
    pub fn read(p: &ParamValues, r: &mut dyn Report) -> Self {
        let d = SppmSettings::default();
        let (name, n) = match (p.int_opt("iterations"), p.int_opt("numiterations")) {
            (Some(n), _) => ("iterations", n),
            (None, Some(n)) => ("numiterations", n),
            (None, None) => ("iterations", d.iterations as i32),
        };
        let iterations = if n < 1 {
            r.warn(
                Some(name),
                format!("\"{name}\" is {n}: it must be ≥ 1; 64 is used"),
                "no iterations",
            );
            d.iterations
        } else {
            n as u32
        };
        let np = p.int("photonsperiteration");
        let photons_per_iteration = match np {
            -1 => 0,
            1..=MAX_PHOTONS_PARAM => np as u32,
            _ if np > MAX_PHOTONS_PARAM => {
                r.warn(
                    Some("photonsperiteration"),
                    format!("\"photonsperiteration\" is {np}: pbrs traces at most {MAX_PHOTONS_PARAM} photons per iteration (the bound of \"pixelsamples\"), which is used"),
                    "photons clamped",
                );
                MAX_PHOTONS_PARAM as u32
            }
            _ => {
                r.warn(
                    Some("photonsperiteration"),
                    format!("\"photonsperiteration\" is {np}: it must be ≥ 1 (or -1, one per pixel); one per pixel is used"),
                    "no photons",
                );
                0
            }
        };
        let radius = p.float("radius");
        let radius = if radius > 0.0 && radius.is_finite() {
            radius
        } else {
            r.warn(
                Some("radius"),
                format!("\"radius\" is {radius}: it must be a positive number; 1 is used"),
                "bad radius",
            );
            d.radius
        };
        let write_frequency = match p.int_opt("imagewritefrequency") {
            None => 0,
            Some(f) if f >= 1 => f as u32,
            Some(f) => {
                r.warn(
                    Some("imagewritefrequency"),
                    format!("\"imagewritefrequency\" is {f}: it must be ≥ 1; the image is written at the end only"),
                    "bad frequency",
                );
                0
            }
        };
        SppmSettings {
            iterations,
            photons_per_iteration,
            max_depth: max_depth(p, r),
            radius,
            write_frequency,
        }
    }

    pub fn summary(&self) -> String {
        let photons = match self.photons_per_iteration {
            0 => "one per pixel".to_string(),
            n => n.to_string(),
        };
        format!(
            "iterations {}, photons per iteration {photons}, maxdepth {}, radius {}",
            self.iterations, self.max_depth, self.radius
        )
    }
}

/// The runtime `sppm`: its settings and its two light distributions
/// (uniform for direct lighting at visible points, by power for photons).
pub struct Sppm {
    settings: SppmSettings,
    /// Boxed: the runtime enum's variants stay small.
    direct: Box<LightSampler>,
    power: Box<LightSampler>,
}

impl Sppm {
    pub fn new(settings: &SppmSettings, scene: &RenderScene, _scalar: bool) -> Self {
        Sppm {
            settings: *settings,
            direct: Box::new(light_sampler(LightSampleStrategy::Uniform, scene)),
            power: Box::new(light_sampler(LightSampleStrategy::Power, scene)),
        }
    }

    pub fn settings(&self) -> &SppmSettings {
        &self.settings
    }
}

impl Integrate for Sppm {
    fn notes(&self) -> Vec<String> {
        vec![format!(
            "sppm: {} (its own render loop; the scene's sampler is not used)",
            self.settings.summary()
        )]
    }

    fn light_sampler(&self) -> Option<&LightSampler> {
        Some(&self.power)
    }

    /// SPPM has no per-ray estimate: it renders through
    /// [`Sppm::render`], which the driver calls for this kind.
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

/// A pixel's visible point: where its camera path met a diffuse surface;
/// none while `beta` is zero. Its BSDF's lobes are those of
/// [`VisiblePoints::lobes`]`[row][first..][..n]`.
struct VisiblePoint {
    p: Vec3,
    wo: Vec3,
    beta: Vec3,
    bsdf: BsdfHead,
    row: u32,
    first: u32,
    n: u32,
}

/// Every pixel's visible point, with the lobes of their BSDFs packed in one
/// array per row of pixels (as pbrt-v3's arenas do: a BSDF with room for the
/// most lobes would make a visible point 800 bytes, and the camera pass's
/// writes to them would sweep the caches).
struct VisiblePoints<'a> {
    points: Vec<VisiblePoint>,
    /// Refilled by every camera pass, their capacity kept (no allocation
    /// after the first iterations).
    lobes: Vec<Vec<Lobe<'a>>>,
}

impl VisiblePoints<'_> {
    /// The BSDF of pixel `i`'s visible point towards `wi`.
    #[inline]
    fn f(&self, i: usize, wi: Vec3) -> Vec3 {
        let vp = &self.points[i];
        let lobes = &self.lobes[vp.row as usize][vp.first as usize..][..vp.n as usize];
        vp.bsdf.f_pdf(lobes, vp.wo, wi, BxdfFlags::ALL).0
    }
}

/// What SPPM keeps per pixel across iterations (pbrt-v3's `SPPMPixel`
/// without its visible point, which is kept apart: the per-pixel loops
/// between passes then read a few bytes per pixel, not a BSDF's worth).
struct Pixel {
    radius: f32,
    /// Emitted and directly sampled light, summed over iterations.
    ld: Vec3,
    /// Photons accumulated so far (γ-weighted) and the flux they carried.
    n: f32,
    tau: Vec3,
}

/// Bytes SPPM keeps per pixel (its state, its visible point with a BSDF
/// and the photon grid's copy of the point), for the driver's memory check
/// before anything is allocated.
pub const PIXEL_BYTES: u64 = (std::mem::size_of::<Pixel>()
    + std::mem::size_of::<VisiblePoint>()
    + MAX_BXDFS * std::mem::size_of::<Lobe<'static>>()
    + std::mem::size_of::<Option<(Vec3, f32)>>()) as u64;

/// What [`Sppm::render`] needs of the render: the scene, the film's
/// (cropped) pixel bounds, the seed of the camera pass's Halton sampler and
/// the worker threads.
pub struct SppmRun<'r> {
    pub scene: &'r RenderScene,
    pub pixel_bounds: Bounds2i,
    pub seed: u64,
    pub pool: &'r rayon::ThreadPool,
}

/// Camera paths a row advances side by side.
const LANES: usize = 16;

/// The rays of the lanes under way, traced side by side.
struct LaneRays {
    rays: [Ray; LANES],
    times: [f32; LANES],
    /// Their closest hits, and the lane of each.
    hits: [Option<Hit>; LANES],
    which: [usize; LANES],
}

impl Default for LaneRays {
    fn default() -> LaneRays {
        LaneRays {
            rays: [Ray::new(Vec3::ZERO, Vec3::Z); LANES],
            times: [0.0; LANES],
            hits: [None; LANES],
            which: [0; LANES],
        }
    }
}

impl LaneRays {
    /// Traces the ray (and time) `of` each lane under way together
    /// (`Aggregate::intersect_stream`); returns how many there were: the
    /// first that many `hits` and `which` are theirs.
    fn trace<L>(&mut self, lanes: &[Option<L>], of: impl Fn(&L) -> (Ray, f32), scene: &RenderScene) -> usize {
        let mut n = 0;
        for (k, lane) in lanes.iter().enumerate() {
            if let Some(l) = lane {
                (self.rays[n], self.times[n]) = of(l);
                self.which[n] = k;
                n += 1;
            }
        }
        scene
            .aggregate
            .intersect_stream(&self.rays[..n], &self.times[..n], &mut self.hits[..n]);
        n
    }
}

/// A camera path under way: the `pixel`th of its row, its next ray and
/// what pbrt-v3's camera loop keeps.
#[derive(Clone, Copy)]
struct CameraLane {
    pixel: usize,
    ray: Ray,
    time: f32,
    beta: Vec3,
    specular_bounce: bool,
    depth: u32,
    crossed: u32,
}

/// A photon under way: its place in its chunk, its index and next Halton
/// dimension, its next ray and power.
#[derive(Clone, Copy)]
struct PhotonLane {
    at: usize,
    index: u64,
    dim: usize,
    ray: Ray,
    time: f32,
    beta: Vec3,
    depth: u32,
    crossed: u32,
}

/// Photons per chunk: the unit of parallel work whose contributions are
/// added in order (small enough that an iteration of one photon per pixel
/// of a small film still keeps every thread busy to its end).
const PHOTON_CHUNK: u32 = 256;

/// Chunks in flight per thread: their records are kept until the group is
/// added in.
const CHUNKS_PER_THREAD: usize = 128;

impl Sppm {
    /// Renders all iterations. `done(k, image)` is called after iteration
    /// k (1-based) with the radiance of every pixel of `run.pixel_bounds`
    /// in row order, and whether pbrt-v3 would write the image then.
    /// Returns the rays traced.
    pub fn render(&self, run: &SppmRun, done: &mut dyn FnMut(u32, &[Vec3], bool)) -> RayCounts {
        let s = &self.settings;
        let pb = run.pixel_bounds;
        let n_pixels = pb.area().max(0) as usize;
        let photons = if s.photons_per_iteration > 0 {
            s.photons_per_iteration
        } else {
            n_pixels.min(MAX_PHOTONS as usize) as u32
        };
        let mut pixels: Vec<Pixel> = (0..n_pixels)
            .map(|_| Pixel {
                radius: s.radius,
                ld: Vec3::ZERO,
                n: 0.0,
                tau: Vec3::ZERO,
            })
            .collect();
        let points = (0..n_pixels)
            .map(|_| VisiblePoint {
                p: Vec3::ZERO,
                wo: Vec3::ZERO,
                beta: Vec3::ZERO,
                bsdf: Bsdf::empty().head(),
                row: 0,
                first: 0,
                n: 0,
            })
            .collect();
        let mut vps = VisiblePoints {
            points,
            lobes: (0..pb.height().max(0)).map(|_| Vec::new()).collect(),
        };
        let desc = SamplerDesc {
            kind: SamplerKind::Halton,
            pixel_samples: s.iterations,
            sample_pixel_center: false,
        };
        let sampler = Sampler::new(&desc, pb, run.seed);
        let bases: Vec<RadicalTable> = PRIMES.iter().map(|&p| RadicalTable::new(p)).collect();
        let mut counts = RayCounts::default();
        let mut image = vec![Vec3::ZERO; n_pixels];
        let mut grid = Grid::default();
        // Each pixel's photons of the iteration (flux and count), zeroed
        // again as the pixels are updated.
        let mut acc = vec![(DVec3::ZERO, 0u32); n_pixels];
        // The iterations run as one job on the render's threads (a pass
        // started from outside them waits for a thread to wake up and then
        // wakes this one: two thread switches per pass, a tenth of a small
        // scene's time); this thread hands each iteration's image to `done`
        // while the next iteration runs.
        let (images, finished) = std::sync::mpsc::sync_channel::<(u32, Vec<Vec3>, bool)>(1);
        run.pool.in_place_scope(|scope| {
            scope.spawn(|_| {
                // Moved in: dropped when the iterations end, which ends
                // the loop below.
                let images = images;
                for iter in 0..s.iterations {
                    counts.add(&self.camera_pass(run, &sampler, &mut pixels, &mut vps, iter));
                    grid.rebuild(&pixels, &vps.points);
                    let c = self.photon_pass(run, &grid, &vps, &bases, iter, photons, &mut acc);
                    counts.add(&c);
                    let k = iter + 1;
                    let write =
                        k == s.iterations || (s.write_frequency > 0 && k % s.write_frequency == 0);
                    let np = k as u64 * photons as u64;
                    // Each pixel on its own: in parallel, the same values.
                    (pixels.par_iter_mut(), vps.points.par_iter_mut(), acc.par_iter_mut(), image.par_iter_mut())
                        .into_par_iter()
                        .for_each(|(p, vp, a, l)| {
                            let (phi, m) = std::mem::take(a);
                            update_pixel(p, vp, phi, m);
                            *l = p.ld / k as f32;
                            if np > 0 && p.radius > 0.0 {
                                *l += p.tau / (np as f32 * std::f32::consts::PI * p.radius * p.radius);
                            }
                        });
                    if images.send((k, image.clone(), write)).is_err() {
                        return;
                    }
                }
            });
            // Moved in too: if `done` panics, the receiver is dropped on the
            // way out, so the iterations' job stops at its next send
            // instead of waiting for room.
            let finished = finished;
            for (k, image, write) in finished.iter() {
                done(k, &image, write);
            }
        });
        counts
    }

    /// Step (1): each pixel's camera path, rows in parallel (each pixel's
    /// path depends only on its own samples). Within a row, [`LANES`]
    /// pixels' paths advance side by side, their rays traced together
    /// ([`crate::accel::Aggregate::intersect_stream`]), each lane with its
    /// own copy of the sampler; a lane whose path ends takes the row's next
    /// pixel.
    fn camera_pass<'a>(
        &self,
        run: &SppmRun<'a>,
        sampler: &Sampler,
        pixels: &mut [Pixel],
        vps: &mut VisiblePoints<'a>,
        iter: u32,
    ) -> RayCounts {
        let pb = run.pixel_bounds;
        let w = pb.width().max(1) as usize;
        let scene = run.scene;
        let rows: Vec<RayCounts> = run.pool.install(|| {
            pixels
            .par_chunks_mut(w)
            .zip(vps.points.par_chunks_mut(w))
            .zip(vps.lobes.par_iter_mut())
            .enumerate()
            // One task per row: rayon splits a range further only when it
            // is stolen, so without this a thread that finishes early sits
            // idle while the other works through a long run of costly rows
            // (a fifth of this pass's wall time on pbrt-v3's f16-9a).
            .with_max_len(1)
            .map(|(row, ((px, vp), lobes))| {
                let mut samplers = vec![sampler.clone(); LANES];
                let mut lanes: [Option<CameraLane>; LANES] = [None; LANES];
                let mut scratch = Scratch::default();
                let mut bsdf = Bsdf::empty();
                lobes.clear();
                let y = pb.min.y + row as i32;
                let mut next = 0;
                let mut traced = LaneRays::default();
                loop {
                    for (lane, sampler) in lanes.iter_mut().zip(&mut samplers) {
                        while lane.is_none() && next < px.len() {
                            let pixel = IVec2::new(pb.min.x + next as i32, y);
                            sampler.start_pixel_sample(pixel, iter);
                            *lane = self.camera_lane(scene, sampler, pixel, next);
                            next += 1;
                        }
                    }
                    let n = traced.trace(&lanes, |l| (l.ray, l.time), scene);
                    if n == 0 {
                        break;
                    }
                    scratch.counts.closest += n as u64;
                    let LaneRays { hits, which, .. } = &traced;
                    for (&k, hit) in which[..n].iter().zip(&hits[..n]) {
                        let Some(l) = lanes[k].as_mut() else {
                            continue;
                        };
                        let i = l.pixel;
                        let out = (&mut px[i], &mut vp[i], &mut bsdf);
                        let Some(made) = self.camera_step(scene, l, hit, &mut samplers[k], &mut scratch, out) else {
                            continue;
                        };
                        if made {
                            let vp = &mut vp[i];
                            vp.row = row as u32;
                            vp.first = lobes.len() as u32;
                            vp.n = bsdf.lobes().len() as u32;
                            vp.bsdf = bsdf.head();
                            lobes.extend_from_slice(bsdf.lobes());
                        }
                        lanes[k] = None;
                    }
                }
                scratch.counts()
            })
            .collect()
        });
        let mut c = RayCounts::default();
        rows.iter().for_each(|r| c.add(r));
        c
    }

    /// The start of pixel `pixel`'s camera path (pbrt-v3's camera sample
    /// and ray), the `i`th of its row; `None` if it traces nothing.
    fn camera_lane(
        &self,
        scene: &RenderScene,
        sampler: &mut Sampler,
        pixel: IVec2,
        i: usize,
    ) -> Option<CameraLane> {
        let lens = scene.camera.uses_lens() || scene.camera.is_moving();
        let cs: CameraSample = sampler.camera_sample(pixel, lens);
        let (ray, weight) = scene.camera.generate_ray(&cs);
        if weight <= 0.0 || weight.is_nan() || self.settings.max_depth == 0 {
            return None;
        }
        Some(CameraLane {
            pixel: i,
            ray,
            time: scene.camera.time(&cs),
            beta: Vec3::ONE,
            specular_bounce: false,
            depth: 0,
            crossed: 0,
        })
    }

    /// One vertex of a pixel's camera path (pbrt-v3's loop "Follow camera
    /// ray path until a visible point is created"), where its ray met
    /// `hit`: `None` while the path goes on (`lane.ray` is its next ray),
    /// else whether it made a visible point: then `vp` holds all of it but
    /// its BSDF, which is `bsdf`.
    fn camera_step<'a>(
        &self,
        scene: &'a RenderScene,
        lane: &mut CameraLane,
        hit: &Option<Hit>,
        sampler: &mut Sampler,
        scratch: &mut Scratch,
        (px, vp, bsdf): (&mut Pixel, &mut VisiblePoint, &mut Bsdf<'a>),
    ) -> Option<bool> {
        let CameraLane { ray, time, beta, .. } = *lane;
        let max_depth = self.settings.max_depth;
        let Some(hit) = hit else {
            px.ld += beta * escaped(scene, ray.d);
            return Some(false);
        };
        let mut s = scene.aggregate.surface_at(hit, time);
        let material = &scene.materials[s.material as usize];
        if material.is_none() {
            lane.crossed += 1;
            if lane.crossed > MAX_PASS_THROUGH {
                return Some(false);
            }
            lane.ray = spawn_ray(s.point.p, s.point.p_error, s.point.n, ray.d);
            return None;
        }
        shade(scene, hit, &mut s, material, true, None, bsdf);
        let bsdf = &*bsdf;
        let wo = -ray.d;
        if lane.depth == 0 || lane.specular_bounce {
            px.ld += beta * emitted(scene, &s, wo);
        }
        px.ld += beta * sample_one_light(scene, &s, bsdf, wo, sampler, scratch, &self.direct);
        let diffuse = bsdf.num_components(BxdfFlags(
            BxdfFlags::DIFFUSE.0 | BxdfFlags::REFLECTION.0 | BxdfFlags::TRANSMISSION.0,
        )) > 0;
        let glossy = bsdf.num_components(BxdfFlags(
            BxdfFlags::GLOSSY.0 | BxdfFlags::REFLECTION.0 | BxdfFlags::TRANSMISSION.0,
        )) > 0;
        if diffuse || (glossy && lane.depth + 1 == max_depth) {
            vp.p = s.point.p;
            vp.wo = wo;
            vp.beta = beta;
            return Some(true);
        }
        if lane.depth + 1 < max_depth {
            let Some(bs) = bsdf.sample(wo, sampler.get_2d(), BxdfFlags::ALL) else {
                return Some(false);
            };
            if bs.pdf == 0.0 || bs.f == Vec3::ZERO {
                return Some(false);
            }
            lane.specular_bounce = bs.is_specular();
            let mut beta = beta;
            beta *= bs.f * bs.wi.dot(s.point.ns).abs() / bs.pdf;
            let y = luminance(beta);
            if y < 0.25 {
                let continue_prob = y.min(1.0);
                if sampler.get_1d() > continue_prob {
                    return Some(false);
                }
                beta /= continue_prob;
            }
            lane.beta = beta;
            lane.ray = spawn_ray(s.point.p, s.point.p_error, s.point.n, bs.wi);
        }
        lane.depth += 1;
        if lane.depth < max_depth {
            None
        } else {
            Some(false)
        }
    }

    /// Step (3): photons in fixed chunks traced in parallel, each chunk's
    /// contributions (pixel, flux) recorded in photon order and added
    /// chunk by chunk in order into `acc` (zero on entry): each pixel's
    /// flux and photon count.
    #[allow(clippy::too_many_arguments)]
    fn photon_pass(
        &self,
        run: &SppmRun,
        grid: &Grid,
        vps: &VisiblePoints,
        bases: &[RadicalTable],
        iter: u32,
        photons: u32,
        acc: &mut [(DVec3, u32)],
    ) -> RayCounts {
        let mut counts = RayCounts::default();
        if grid.is_empty() || run.scene.lights.is_empty() {
            return counts;
        }
        let chunks = photons.div_ceil(PHOTON_CHUNK);
        // Chunks in flight at once: enough for every thread, few enough
        // that their records stay small.
        let group = (run.pool.current_num_threads().max(1) * CHUNKS_PER_THREAD) as u32;
        let mut all: Vec<(Vec<(u32, Vec3)>, RayCounts)> = Vec::new();
        let mut first = 0;
        while first < chunks {
            let last = (first + group).min(chunks);
            all.clear();
            run.pool.install(|| {
            (first..last)
                .into_par_iter()
                // One task per chunk (as the camera pass's rows).
                .with_max_len(1)
                .map(|c| {
                    let start = c * PHOTON_CHUNK;
                    let end = (start + PHOTON_CHUNK).min(photons);
                    let mut recs = Vec::new();
                    let mut counts = RayCounts::default();
                    // The chunk's photon indices (iteration-major).
                    let from = iter as u64 * photons as u64 + start as u64;
                    let len = (end - start) as usize;
                    let mut runs = PhotonRuns::new(len, bases);
                    let photons = (&mut runs, bases, from);
                    self.trace_photons(run.scene, grid, vps, photons, &mut recs, &mut counts);
                    (recs, counts)
                })
                .collect_into_vec(&mut all)
            });
            for (recs, c) in all.drain(..) {
                counts.add(&c);
                for (i, phi) in recs {
                    let a = &mut acc[i as usize];
                    a.0 += phi.as_dvec3();
                    a.1 += 1;
                }
            }
            first = last;
        }
        counts
    }
}

/// pbrt-v3's per-pixel update after an iteration's photons: the radius
/// shrinks so that the pixel keeps γ = 2/3 of the new photons, τ is
/// rescaled to the new disc; the visible point is dropped.
fn update_pixel(p: &mut Pixel, vp: &mut VisiblePoint, phi: DVec3, m: u32) {
    if m > 0 {
        let gamma = 2.0f32 / 3.0;
        let n_new = p.n + gamma * m as f32;
        let r_new = p.radius * (n_new / (p.n + m as f32)).sqrt();
        let beta = vp.beta;
        p.tau = (p.tau + beta * phi.as_vec3()) * (r_new * r_new) / (p.radius * p.radius);
        p.n = n_new;
        p.radius = r_new;
    }
    vp.beta = Vec3::ZERO;
}

/// Dimensions of the photons' Halton sequence that a chunk fills in runs
/// (those whose base has a digit table; the others are looked up one value
/// at a time).
const RUN_DIMS: usize = 32;

/// A chunk's photons have consecutive indices: dimension `d` of all of
/// them from the first photon that may still draw it (when one first does)
/// to the chunk's end, filled at once ([`RadicalTable::fill`]).
struct PhotonRuns {
    len: usize,
    /// Bit `d`: dimension `d`'s base has a digit table (it is filled in runs).
    fills: u32,
    /// Bit `d`: dimension `d` is filled from some photon on.
    filled: u32,
    /// The places in the chunk of the photons under way, one per lane
    /// (`u32::MAX`: none): a dimension is filled from the first of them on.
    under_way: [u32; LANES],
    values: Vec<f32>,
}

thread_local! {
    /// A thread's run storage, kept between its chunks: every value is
    /// written before it is read (`filled`), so it is never cleared.
    static RUN_VALUES: std::cell::Cell<Vec<f32>> = const { std::cell::Cell::new(Vec::new()) };
}

impl PhotonRuns {
    fn new(len: usize, bases: &[RadicalTable]) -> PhotonRuns {
        let mut values = RUN_VALUES.take();
        if values.len() < RUN_DIMS * len {
            values.resize(RUN_DIMS * len, 0.0);
        }
        let fills = bases
            .iter()
            .take(RUN_DIMS)
            .enumerate()
            .filter(|(_, b)| b.fills())
            .fold(0u32, |m, (d, _)| m | 1 << d);
        PhotonRuns {
            len,
            fills,
            filled: 0,
            under_way: [u32::MAX; LANES],
            values,
        }
    }
}

impl Drop for PhotonRuns {
    fn drop(&mut self) {
        RUN_VALUES.set(std::mem::take(&mut self.values));
    }
}

/// The radical inverses of one photon's index, dimension by dimension.
struct Halton<'b, 'r> {
    bases: &'b [RadicalTable],
    runs: &'r mut PhotonRuns,
    index: u64,
    /// The photon's place in the chunk (`index` − the chunk's first).
    at: usize,
    dim: usize,
}

impl Halton<'_, '_> {
    #[inline(always)]
    fn next(&mut self) -> f32 {
        let d = self.dim;
        // Dimensions past the last base start again at the first.
        self.dim += 1;
        if self.dim == self.bases.len() {
            self.dim = 0;
        }
        let runs = &mut *self.runs;
        if d < RUN_DIMS && runs.fills & (1 << d) != 0 {
            if runs.filled & (1 << d) == 0 {
                // The photons from the first that may still draw values
                // to the chunk's end.
                let low = (runs.under_way.iter().copied().min().unwrap_or(u32::MAX) as usize).min(self.at);
                let first = self.index - (self.at - low) as u64;
                let row = &mut runs.values[d * runs.len..(d + 1) * runs.len];
                self.bases[d].fill(first, &mut row[low..]);
                runs.filled |= 1 << d;
            }
            runs.values[d * runs.len + self.at]
        } else {
            self.bases[d].radical_inverse(self.index)
        }
    }
    #[inline(always)]
    fn next_2d(&mut self) -> Vec2 {
        let x = self.next();
        Vec2::new(x, self.next())
    }
}

impl Sppm {
    /// A chunk's photons (indices `from ..`, as many as `runs` holds;
    /// pbrt-v3's "Follow photon path for photonIndex"), [`LANES`] of them
    /// side by side, their rays traced together; a lane whose photon ends
    /// takes the chunk's next one. Their contributions are pushed to
    /// `recs` in photon order.
    #[allow(clippy::too_many_arguments)]
    fn trace_photons(
        &self,
        scene: &RenderScene,
        grid: &Grid,
        vps: &VisiblePoints,
        (runs, bases, from): (&mut PhotonRuns, &[RadicalTable], u64),
        recs: &mut Vec<(u32, Vec3)>,
        counts: &mut RayCounts,
    ) {
        let len = runs.len;
        let mut lanes: [Option<PhotonLane>; LANES] = [None; LANES];
        // Each record's photon (its place in the chunk).
        let mut places: Vec<u16> = Vec::new();
        let mut next = 0;
        let mut traced = LaneRays::default();
        loop {
            for (k, lane) in lanes.iter_mut().enumerate() {
                while lane.is_none() && next < len {
                    runs.under_way[k] = next as u32;
                    *lane = self.emit_photon(scene, (runs, bases), from + next as u64, next);
                    if lane.is_none() {
                        runs.under_way[k] = u32::MAX;
                    }
                    next += 1;
                }
            }
            let n = traced.trace(&lanes, |l| (l.ray, l.time), scene);
            if n == 0 {
                break;
            }
            counts.closest += n as u64;
            let LaneRays { hits, which, .. } = &traced;
            for (&k, hit) in which[..n].iter().zip(&hits[..n]) {
                let Some(l) = lanes[k].as_mut() else {
                    continue;
                };
                let before = recs.len();
                let goes_on = self.photon_step(scene, (grid, vps), (runs, bases), l, hit, recs);
                places.resize(places.len() + recs.len() - before, l.at as u16);
                if !goes_on {
                    lanes[k] = None;
                    runs.under_way[k] = u32::MAX;
                }
            }
        }
        // In photon order (each photon's in the order it made them): a
        // counting sort by place, stable.
        let mut start = vec![0u32; len + 1];
        for &p in &places {
            start[p as usize + 1] += 1;
        }
        for i in 0..len {
            start[i + 1] += start[i];
        }
        let mut sorted = vec![(0u32, Vec3::ZERO); recs.len()];
        for (&p, &r) in places.iter().zip(recs.iter()) {
            let slot = &mut start[p as usize];
            sorted[*slot as usize] = r;
            *slot += 1;
        }
        *recs = sorted;
    }

    /// A photon's emission (the chunk's `at`th, index `index`): `None` if
    /// it carries nothing or traces no ray.
    fn emit_photon(
        &self,
        scene: &RenderScene,
        (runs, bases): (&mut PhotonRuns, &[RadicalTable]),
        index: u64,
        at: usize,
    ) -> Option<PhotonLane> {
        let mut h = Halton {
            bases,
            runs,
            index,
            at,
            dim: 0,
        };
        // The emission's dimensions drawn together, before anything
        // branches on them (those looked up one index at a time then have
        // their digit chains in flight at once).
        let u = h.next();
        let u_light0 = h.next_2d();
        let u_light1 = h.next_2d();
        let u_time = h.next();
        let dim = h.dim;
        let (light, light_pmf) =
            self.power
                .sample(Vec3::ZERO, Vec3::ZERO, u, &scene.lights, &scene.aggregate)?;
        let time = scene.camera.time(&CameraSample {
            time: u_time,
            ..CameraSample::default()
        });
        let e = scene.lights[light as usize].sample_le(u_light0, u_light1, &scene.aggregate)?;
        if !(e.pdf_pos > 0.0 && e.pdf_dir > 0.0) || e.le == Vec3::ZERO {
            return None;
        }
        let beta = e.n.dot(e.ray.d).abs() * e.le / (light_pmf * e.pdf_pos * e.pdf_dir);
        if beta == Vec3::ZERO || !beta.is_finite() || self.settings.max_depth == 0 {
            return None;
        }
        Some(PhotonLane {
            at,
            index,
            dim,
            ray: e.ray,
            time,
            beta,
            depth: 0,
            crossed: 0,
        })
    }

    /// One vertex of a photon's path, where its ray met `hit`: its
    /// contributions pushed to `recs`; whether it goes on (`lane.ray` its
    /// next ray).
    fn photon_step(
        &self,
        scene: &RenderScene,
        (grid, vps): (&Grid, &VisiblePoints),
        (runs, bases): (&mut PhotonRuns, &[RadicalTable]),
        lane: &mut PhotonLane,
        hit: &Option<Hit>,
        recs: &mut Vec<(u32, Vec3)>,
    ) -> bool {
        let PhotonLane {
            ray,
            time,
            beta,
            depth,
            ..
        } = *lane;
        let Some(hit) = hit else {
            return false;
        };
        let mut s = scene.aggregate.surface_at(hit, time);
        let material = &scene.materials[s.material as usize];
        if material.is_none() {
            if depth > 0 {
                grid.gather(s.point.p, -ray.d, beta, vps, recs);
            }
            lane.crossed += 1;
            if lane.crossed > MAX_PASS_THROUGH {
                return false;
            }
            lane.ray = spawn_ray(s.point.p, s.point.p_error, s.point.n, ray.d);
            return true;
        }
        let mut h = Halton {
            bases,
            runs,
            index: lane.index,
            at: lane.at,
            dim: lane.dim,
        };
        // The photon's next ray first, the visible points it reaches here
        // after it: the gather is off the path's critical chain (the step
        // changes neither the ray, the power nor the point).
        let next = 'step: {
            // This vertex's dimensions (the BSDF sample's and Russian
            // roulette's), drawn before the shading that needs them.
            let u_bsdf = h.next_2d();
            let u_rr = h.next();
            lane.dim = h.dim;
            let mut bsdf = Bsdf::empty();
            shade(scene, hit, &mut s, material, true, None, &mut bsdf);
            let wo = -ray.d;
            let Some(bs) = bsdf.sample(wo, u_bsdf, BxdfFlags::ALL) else {
                break 'step None;
            };
            if bs.f == Vec3::ZERO || bs.pdf == 0.0 {
                break 'step None;
            }
            let bnew =
                beta * bs.f * bs.wi.dot(s.point.ns).abs() / bs.pdf * importance(&bsdf, &bs, wo);
            let q = (1.0 - luminance(bnew) / luminance(beta)).max(0.0);
            if u_rr < q {
                break 'step None;
            }
            Some((
                bnew / (1.0 - q),
                spawn_ray(s.point.p, s.point.p_error, s.point.n, bs.wi),
            ))
        };
        if depth > 0 {
            grid.gather(s.point.p, -ray.d, beta, vps, recs);
        }
        let Some((b, r)) = next else {
            return false;
        };
        lane.beta = b;
        lane.ray = r;
        lane.depth += 1;
        lane.depth < self.settings.max_depth
    }
}

/// The factor that turns a sampled transmission through a dielectric,
/// whose BSDF carries radiance's (η_i/η_t)², into importance's (pbrt-v3's
/// `TransportMode::Importance`): (η_t/η_i)², by the side `wo` is on.
#[inline]
pub(super) fn importance(bsdf: &Bsdf, bs: &crate::materials::BsdfSample, wo: Vec3) -> f32 {
    if !bs.is_transmission() || bs.flags.intersects(BxdfFlags::DIFFUSE) || bsdf.eta == 1.0 {
        return 1.0;
    }
    let eta2 = bsdf.eta * bsdf.eta;
    if wo.dot(bsdf.frame.n) > 0.0 {
        eta2
    } else {
        1.0 / eta2
    }
}

/// The hash grid over visible points (pbrt-v3's): cells of about the
/// largest radius over the visible points' bounds, hashed into as many
/// buckets as pixels; each bucket lists, in pixel order, the pixels whose
/// search disc reaches one of its cells.
#[derive(Default)]
struct Grid {
    bounds: Bounds3,
    res: IVec3,
    buckets: Buckets,
    /// Bucket b lists `entries[starts[b]..starts[b + 1]]` (atomic only
    /// so that the build's runs can write their disjoint slots in
    /// parallel; read and written relaxed, plain loads and stores).
    starts: Vec<u32>,
    entries: Vec<AtomicU32>,
    /// Each pixel's visible point and search radius, by pixel index (none
    /// where the pixel has no visible point that carries light).
    points: Vec<Option<(Vec3, f32)>>,
    /// Work space of the build, kept for the next iteration: each pixel's
    /// first key, and the buckets of every pixel's cells in pixel order.
    key_starts: Vec<u32>,
    keys: Vec<u32>,
    /// Work space of the build: each run's count of keys per bucket, then
    /// its next slot per bucket.
    counts: Vec<Vec<u32>>,
}

impl Grid {
    /// Builds the grid on the current thread pool, in the buffers of the
    /// last iteration's grid; the same grid for any number of threads.
    fn rebuild(&mut self, pixels: &[Pixel], vps: &[VisiblePoint]) {
        pixels
            .par_iter()
            .zip(vps)
            .map(|(p, vp)| (vp.beta != Vec3::ZERO).then_some((vp.p, p.radius)))
            .collect_into_vec(&mut self.points);
        // Minima and maxima: exact, so in any order.
        let (bounds, max_radius) = self
            .points
            .par_iter()
            .flatten()
            .fold(
                || (Bounds3::EMPTY, 0.0f32),
                |(b, m), &(p, r)| {
                    let b = b
                        .union_point(p - Vec3::splat(r))
                        .union_point(p + Vec3::splat(r));
                    (b, m.max(r))
                },
            )
            .reduce(
                || (Bounds3::EMPTY, 0.0f32),
                |(a, ma), (b, mb)| (a.union(&b), ma.max(mb)),
            );
        let size = pixels.len().max(1);
        self.bounds = bounds;
        self.res = IVec3::ONE;
        self.buckets = Buckets::new(size);
        self.starts.clear();
        self.starts.resize(size + 1, 0);
        self.entries.clear();
        if max_radius <= 0.0 {
            return;
        }
        let diag = bounds.max - bounds.min;
        let max_diag = diag.max_element();
        let base = (max_diag / max_radius) as i32;
        self.res = IVec3::new(
            ((base as f32 * diag.x / max_diag) as i32).max(1),
            ((base as f32 * diag.y / max_diag) as i32).max(1),
            ((base as f32 * diag.z / max_diag) as i32).max(1),
        );
        let mut key_starts = std::mem::take(&mut self.key_starts);
        let mut keys = std::mem::take(&mut self.keys);
        // The cells a pixel's disc reaches (an empty range for none).
        let cells = |pt: &Option<(Vec3, f32)>| match pt {
            Some((p, radius)) => {
                let r = Vec3::splat(*radius);
                (self.cell(*p - r).0, self.cell(*p + r).0)
            }
            None => (IVec3::ONE, IVec3::ZERO),
        };
        // Each pixel's number of cells, then their buckets in pixel order,
        // written in parallel (each chunk of pixels owns its run of keys).
        self.points
            .par_iter()
            .map(|pt| {
                let (lo, hi) = cells(pt);
                let n = (hi - lo + IVec3::ONE).max(IVec3::ZERO);
                (n.x * n.y * n.z) as u32
            })
            .collect_into_vec(&mut key_starts);
        let mut total = 0u32;
        for k in key_starts.iter_mut() {
            let n = *k;
            *k = total;
            total += n;
        }
        key_starts.push(total);
        keys.clear();
        keys.resize(total as usize, 0);
        let mut runs = Vec::new();
        let mut rest = &mut keys[..];
        for first in (0..self.points.len()).step_by(GRID_CHUNK) {
            let last = (first + GRID_CHUNK).min(self.points.len());
            let (run, tail) = rest.split_at_mut((key_starts[last] - key_starts[first]) as usize);
            runs.push((first..last, run));
            rest = tail;
        }
        // One task per run (as the camera pass's rows).
        runs.into_par_iter().with_max_len(1).for_each(|(range, run)| {
            let mut k = 0;
            for pt in &self.points[range] {
                let (lo, hi) = cells(pt);
                for z in lo.z..=hi.z {
                    for y in lo.y..=hi.y {
                        for x in lo.x..=hi.x {
                            run[k] = self.buckets.of(IVec3::new(x, y, z)) as u32;
                            k += 1;
                        }
                    }
                }
            }
        });
        // A counting sort, so that buckets list pixels in pixel order: the
        // pixels in a few runs, each counting its keys per bucket, then
        // writing them after the earlier runs' (runs in parallel; the same
        // lists for any number of runs).
        let n = self.points.len();
        let parts = rayon::current_num_threads().clamp(1, MAX_GRID_PARTS).min(n.max(1));
        let edges: Vec<usize> = (0..=parts).map(|p| p * n / parts).collect();
        let mut counts = std::mem::take(&mut self.counts);
        counts.resize_with(parts, Vec::new);
        counts.par_iter_mut().enumerate().for_each(|(p, c)| {
            c.clear();
            c.resize(size, 0);
            let run = key_starts[edges[p]] as usize..key_starts[edges[p + 1]] as usize;
            for &b in &keys[run] {
                c[b as usize] += 1;
            }
        });
        // Each bucket's start, and each run's first slot in it.
        for b in 0..size {
            let mut next = self.starts[b];
            for c in counts.iter_mut() {
                let k = c[b];
                c[b] = next;
                next += k;
            }
            self.starts[b + 1] = next;
        }
        // Cleared at the top of the build.
        self.entries.resize_with(total as usize, || AtomicU32::new(0));
        let entries = &self.entries;
        counts.par_iter_mut().enumerate().for_each(|(p, fill)| {
            for i in edges[p]..edges[p + 1] {
                let run = key_starts[i] as usize..key_starts[i + 1] as usize;
                for &b in &keys[run] {
                    // Each slot is written by one run only.
                    entries[fill[b as usize] as usize].store(i as u32, Ordering::Relaxed);
                    fill[b as usize] += 1;
                }
            }
        });
        self.counts = counts;
        self.key_starts = key_starts;
        self.keys = keys;
    }

    fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// pbrt-v3's `ToGrid`: the cell of `p` (clamped to the grid) and
    /// whether `p` is inside the grid's bounds.
    #[inline]
    fn cell(&self, p: Vec3) -> (IVec3, bool) {
        let ext = self.bounds.max - self.bounds.min;
        let o = p - self.bounds.min;
        let off = Vec3::new(
            if ext.x > 0.0 { o.x / ext.x } else { o.x },
            if ext.y > 0.0 { o.y / ext.y } else { o.y },
            if ext.z > 0.0 { o.z / ext.z } else { o.z },
        );
        let c = IVec3::new(
            (self.res.x as f32 * off.x) as i32,
            (self.res.y as f32 * off.y) as i32,
            (self.res.z as f32 * off.z) as i32,
        );
        let inside = c.cmpge(IVec3::ZERO).all() && c.cmplt(self.res).all();
        (c.clamp(IVec3::ZERO, self.res - IVec3::ONE), inside)
    }

    /// A photon at `p` arriving from `wi` with flux `beta`: a record for
    /// every visible point within its pixel's radius.
    #[inline]
    fn gather(
        &self,
        p: Vec3,
        wi: Vec3,
        beta: Vec3,
        vps: &VisiblePoints,
        recs: &mut Vec<(u32, Vec3)>,
    ) {
        let (c, inside) = self.cell(p);
        if !inside {
            return;
        }
        let b = self.buckets.of(c);
        let (lo, hi) = (self.starts[b] as usize, self.starts[b + 1] as usize);
        for i in &self.entries[lo..hi] {
            let i = i.load(Ordering::Relaxed);
            // Only pixels with a visible point are listed.
            let Some((q, radius)) = self.points[i as usize] else {
                continue;
            };
            if q.distance_squared(p) > radius * radius {
                continue;
            }
            let phi = beta * vps.f(i as usize, wi);
            recs.push((i, phi));
        }
    }
}

/// Runs of pixels the grid's counting sort is split into at most (each
/// holds a count per bucket, four bytes per pixel of the film).
const MAX_GRID_PARTS: usize = 4;

/// Pixels per task of the grid's parallel key pass.
const GRID_CHUNK: usize = 4096;

/// pbrt-v3's grid hash of a cell, before the remainder by the bucket count.
#[inline(always)]
fn cell_hash(p: IVec3) -> u32 {
    ((p.x.wrapping_mul(73856093)) ^ (p.y.wrapping_mul(19349663)) ^ (p.z.wrapping_mul(83492791))) as u32
}

/// pbrt-v3's bucket of a cell, with its division ([`Buckets::of`] computes
/// it).
#[cfg(test)]
fn hash(p: IVec3, size: usize) -> usize {
    cell_hash(p) as usize % size
}

/// [`hash`] into a fixed number of buckets, the remainder taken with a
/// multiply instead of a division (Lemire, Kaser and Kurz 2019, "Faster
/// remainder by direct computation"): exact for every 32-bit hash and
/// bucket count.
#[derive(Clone, Copy, Debug, Default)]
struct Buckets {
    size: u64,
    /// `⌈2^64 / size⌉` (0 where `size` does not fit 32 bits, or is 1).
    magic: u64,
}

impl Buckets {
    fn new(size: usize) -> Buckets {
        let size = size.max(1) as u64;
        let magic = if size > 1 && size <= u32::MAX as u64 {
            u64::MAX / size + 1
        } else {
            0
        };
        Buckets { size, magic }
    }

    #[inline(always)]
    fn of(&self, p: IVec3) -> usize {
        let h = cell_hash(p);
        if self.magic != 0 {
            let low = self.magic.wrapping_mul(h as u64);
            ((low as u128 * self.size as u128) >> 64) as usize
        } else {
            (h as u64 % self.size) as usize
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::rng::Pcg32;

    #[test]
    fn buckets_are_pbrt_v3_hash() {
        let mut r = Pcg32::with_sequence(3);
        for size in [1usize, 2, 3, 7, 160 * 229, 1 << 20, (1 << 31) - 1, u32::MAX as usize, 1 << 33] {
            let b = Buckets::new(size);
            for _ in 0..20_000 {
                let c = IVec3::new(
                    r.uniform_u32() as i32,
                    (r.uniform_u32() % 1000) as i32,
                    r.uniform_u32() as i32 >> 7,
                );
                assert_eq!(b.of(c), hash(c, size), "size {size} cell {c}");
            }
        }
    }

    /// A chunk's photons, each drawing its own number of dimensions (some
    /// past the filled ones, and wrapping past the last base), get every
    /// value the table gives their index.
    #[test]
    fn photon_runs_are_the_tables_values() {
        let bases: Vec<RadicalTable> = PRIMES.iter().map(|&p| RadicalTable::new(p)).collect();
        let mut r = Pcg32::with_sequence(9);
        for (first, len) in [(0u64, 256usize), (1_000_000, 256), (4095, 17), (1 << 40, 30)] {
            for lanes in [1, 3, 16] {
                // Photons under way side by side, started in order, each
                // drawing its dimensions a few at a time in turns, as
                // `trace_photons` draws them (a later photon may draw a
                // dimension first).
                let mut runs = PhotonRuns::new(len, &bases);
                let mut under_way: Vec<(usize, usize, usize)> = Vec::new(); // (at, dim, dims)
                let mut next = 0;
                let mut drawn = 0;
                while next < len || !under_way.is_empty() {
                    while under_way.len() < lanes && next < len {
                        let dims = match r.uniform_u32() % 8 {
                            0 => 0,
                            1 => bases.len() + 5,
                            k => (r.uniform_u32() % (6 + 12 * k)) as usize,
                        };
                        under_way.push((next, 0, dims));
                        next += 1;
                    }
                    let k = r.uniform_u32_below(under_way.len() as u32) as usize;
                    runs.under_way = [u32::MAX; LANES];
                    for (slot, u) in runs.under_way.iter_mut().zip(&under_way) {
                        *slot = u.0 as u32;
                    }
                    let (at, dim, dims) = under_way[k];
                    let index = first + at as u64;
                    let mut h = Halton {
                        bases: &bases,
                        runs: &mut runs,
                        index,
                        at,
                        dim: dim % bases.len(),
                    };
                    let end = dims.min(dim + 1 + r.uniform_u32_below(6) as usize);
                    for d in dim..end {
                        let want = bases[d % bases.len()].radical_inverse(index);
                        assert_eq!(h.next().to_bits(), want.to_bits(), "index {index} dim {d}");
                        drawn += 1;
                    }
                    if end == dims {
                        under_way.swap_remove(k);
                    } else {
                        under_way[k].1 = end;
                    }
                }
                assert!(drawn > len, "{drawn} values drawn");
            }
        }
    }
}
