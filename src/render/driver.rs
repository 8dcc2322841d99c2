//! Rendering a scene description to an image: compile the scene, render
//! 16×16 tiles in parallel with rayon, merge them in a fixed order (so the
//! image is bit-identical for any thread count), and count what happened.

use crate::geometry::Bounds2i;
use crate::geometry::{Ray, RayDiff};
use crate::image::Image;
use crate::integrators::RenderScene;
use crate::integrators::{Batch, Integrator, RayCounts, Scratch};
use crate::render::film::part::{self, PartHeader, PartKind};
use crate::render::film::{luminance, Film, FilmTile, TileMaker};
use crate::samplers::{CameraSample, Sampler};
use crate::scene::SceneDescription;
use glam::{IVec2, Vec3};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// Options that do not change the expected image.
#[derive(Clone, Debug, Default)]
pub struct RenderOptions {
    /// Worker threads; None = all cores.
    pub threads: Option<usize>,
    /// Seed for the sampler's scrambling and random dimensions.
    pub seed: u64,
    /// Scalar code only: no four-lane fast paths and no batches, each
    /// sample rendered from its camera ray to its end before the next (they
    /// give the same image bit for bit; tests compare the two).
    pub scalar: bool,
}

/// What a render did.
#[derive(Clone, Debug, Default)]
pub struct RenderStats {
    pub build_time: Duration,
    /// The part of `build_time` spent on the BVHs.
    pub bvh_time: Duration,
    pub render_time: Duration,
    pub rays: RayCounts,
    pub samples: u64,
    pub nan_samples: u64,
    pub inf_samples: u64,
    pub negative_samples: u64,
    pub threads: usize,
    /// What was built and what was left out.
    pub notes: Vec<String>,
}

impl RenderStats {
    pub fn dropped_samples(&self) -> u64 {
        self.nan_samples + self.inf_samples + self.negative_samples
    }
    pub fn mrays_per_sec(&self) -> f64 {
        self.rays.total() as f64 / self.render_time.as_secs_f64().max(1e-9) / 1e6
    }
}

#[derive(Default)]
struct TileCounts {
    rays: RayCounts,
    samples: u64,
    nan: u64,
    inf: u64,
    negative: u64,
}

/// What [`Renderer::render_samples_observed`] reports after each group of
/// tiles: counts, the group's tiles (sample-space bounds, in merge order)
/// and the film with them merged.
pub struct ChunkDone<'a> {
    pub done: usize,
    pub total: usize,
    pub tiles: &'a [Bounds2i],
    pub film: &'a Film,
}

/// A scene compiled for rendering, with its film. Samples can be added in
/// ranges of sample indices: the samplers are stateless per (pixel, index),
/// so rendering indices 0..n and then n..2n gives exactly the image of a
/// 2n-spp render (progressive rendering for convergence studies).
pub struct Renderer {
    scene: RenderScene,
    integrator: Integrator,
    film: Film,
    sampler: Sampler,
    pool: rayon::ThreadPool,
    stats: RenderStats,
    /// Samples in flight per thread (1: the scalar loop).
    batch: usize,
    /// The image file, for integrators that write images as they go
    /// (`sppm`'s `imagewritefrequency`).
    output: std::path::PathBuf,
    seed: u64,
}

impl Renderer {
    pub fn new(desc: &SceneDescription, opts: &RenderOptions) -> Result<Renderer, String> {
        let t0 = Instant::now();
        check_film_memory(desc)?;
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(opts.threads.unwrap_or(0))
            .build()
            .map_err(|e| format!("cannot start worker threads: {e}"))?;
        // The BVH is built on the render's threads (as many as it has).
        let scene = pool.install(|| RenderScene::new(desc));
        let mut integrator = Integrator::new(&desc.integrator, &scene, opts.scalar);
        let film = Film::new(&desc.film, &desc.filter);
        integrator.prepare_film(&scene, film.sample_bounds())?;
        let mut sampler = Sampler::new(&desc.sampler, film.sample_bounds(), opts.seed);
        integrator.prepare_sampler(&scene, &mut sampler);
        let batch = if opts.scalar || !sampler.batches_well() {
            1
        } else {
            BATCH
        };
        let stats = RenderStats {
            build_time: t0.elapsed(),
            bvh_time: scene.aggregate.build_time,
            threads: pool.current_num_threads(),
            ..Default::default()
        };
        Ok(Renderer {
            scene,
            integrator,
            film,
            sampler,
            pool,
            stats,
            batch,
            output: desc.film.filename.clone(),
            seed: opts.seed,
        })
    }

    /// Renders sample indices `samples` of every pixel into the film.
    /// `progress` is called with (tiles done, tiles total).
    pub fn render_samples(
        &mut self,
        samples: std::ops::Range<u32>,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) {
        self.render_samples_observed(samples, &mut |c: &ChunkDone| progress(c.done, c.total));
    }

    /// [`Renderer::render_samples`], calling `on_chunk` on this thread after
    /// each group of tiles is merged (between groups: render threads are not
    /// waiting on it mid-tile, and nothing is done per sample).
    pub fn render_samples_observed(
        &mut self,
        samples: std::ops::Range<u32>,
        on_chunk: &mut dyn FnMut(&ChunkDone),
    ) {
        self.render_region_observed(samples, None, on_chunk);
    }

    /// [`Renderer::render_samples_observed`], taking samples only in the
    /// pixels of `region` (sample-space pixel coordinates; None: all). The
    /// tiles, their order, the order of pixels and samples within a tile and
    /// the merge order are those of the full render, with the pixels outside
    /// `region` skipped: every film pixel that only samples inside `region`
    /// can reach gets exactly the full render's sums, bit for bit (a render
    /// farm's tile: see [`crate::render::film::part`]).
    pub fn render_region_observed(
        &mut self,
        samples: std::ops::Range<u32>,
        region: Option<Bounds2i>,
        on_chunk: &mut dyn FnMut(&ChunkDone),
    ) {
        match self.integrator {
            Integrator::Sppm(_) => return self.render_sppm(on_chunk),
            Integrator::Mlt(_) => return self.render_mlt(on_chunk),
            _ => {}
        }
        let t1 = Instant::now();
        self.film.add_splat_samples(samples.len() as u64);
        let mut tiles = self.film.tiles(16);
        if let Some(r) = region {
            tiles.retain(|t| {
                let i = t.intersect(&r);
                i.width() > 0 && i.height() > 0
            });
        }
        let total = tiles.len();
        // Workers take tiles in order from a shared counter and send them
        // here as they finish; this thread merges them in tile order (so the
        // image is the same for any thread count) and reports after each
        // group of `chunk` tiles. Nothing waits at the end of a group: a
        // thread that finishes a tile takes the next one at once.
        let chunk = (self.stats.threads * 8).max(1);
        let (scene, integrator, sampler) = (&self.scene, &self.integrator, &self.sampler);
        let batch = self.batch;
        let maker = self.film.tile_maker();
        let next = AtomicUsize::new(0);
        let (tx, rx) = mpsc::channel::<(usize, FilmTile, TileCounts)>();
        let pool = &self.pool;
        let film = &mut self.film;
        let stats = &mut self.stats;
        std::thread::scope(|ts| {
            let tiles = &tiles;
            let (next, maker) = (&next, &maker);
            ts.spawn(move || {
                pool.broadcast(|_| {
                    let tx = tx.clone();
                    // The batch's lanes, made once per thread.
                    let mut lanes = (batch > 1).then(|| Lanes::new(batch, sampler, integrator));
                    loop {
                        let k = next.fetch_add(1, Ordering::Relaxed);
                        let Some(&tb) = tiles.get(k) else { break };
                        let (tile, c) = if let Some(lanes) = lanes.as_mut() {
                            render_tile_batched(
                                scene,
                                integrator,
                                maker,
                                tb,
                                region,
                                samples.clone(),
                                lanes,
                            )
                        } else {
                            render_tile(
                                scene,
                                integrator,
                                maker,
                                sampler,
                                tb,
                                region,
                                samples.clone(),
                            )
                        };
                        if tx.send((k, tile, c)).is_err() {
                            break;
                        }
                    }
                });
                drop(tx);
            });
            // Finished tiles waiting for an earlier one (few: tiles are
            // handed out in order).
            let mut waiting: Vec<Option<(FilmTile, TileCounts)>> = Vec::new();
            let mut merged = 0usize;
            let mut reported = 0usize;
            for (k, tile, c) in rx.iter() {
                let slot = k - merged;
                if waiting.len() <= slot {
                    waiting.resize_with(slot + 1, || None);
                }
                waiting[slot] = Some((tile, c));
                let ready = waiting.iter().take_while(|w| w.is_some()).count();
                for (tile, c) in waiting.drain(..ready).flatten() {
                    film.merge_tile(tile);
                    stats.rays.add(&c.rays);
                    stats.samples += c.samples;
                    stats.nan_samples += c.nan;
                    stats.inf_samples += c.inf;
                    stats.negative_samples += c.negative;
                }
                merged += ready;
                while merged - reported >= chunk || (merged == total && reported < total) {
                    let end = (reported + chunk).min(merged);
                    on_chunk(&ChunkDone {
                        done: end,
                        total,
                        tiles: &tiles[reported..end],
                        film,
                    });
                    reported = end;
                }
            }
        });
        self.stats.render_time += t1.elapsed();
    }

    /// `sppm`'s own loop of iterations over the whole film: the film is
    /// set to the image after every iteration (`on_chunk` is called with
    /// the iterations as its groups), and the image file is written
    /// (atomically) where `imagewritefrequency` asks. The range of samples
    /// and the region of the other integrators do not apply.
    fn render_sppm(&mut self, on_chunk: &mut dyn FnMut(&ChunkDone)) {
        let Integrator::Sppm(sppm) = &self.integrator else {
            return;
        };
        let t1 = Instant::now();
        let run = crate::integrators::SppmRun {
            scene: &self.scene,
            pixel_bounds: self.film.pixel_bounds(),
            seed: self.seed,
            pool: &self.pool,
        };
        let total = sppm.settings().iterations as usize;
        let whole = [self.film.pixel_bounds()];
        let (film, output) = (&mut self.film, &self.output);
        let mut write_error = None;
        let rays = sppm.render(&run, &mut |k, rgb, write| {
            film.set_pixels(rgb);
            if write && (k as usize) < total {
                if let Err(e) = crate::image::io::write_image(output, &film.image()) {
                    write_error = Some(e);
                }
            }
            on_chunk(&ChunkDone {
                done: k as usize,
                total,
                tiles: &whole,
                film,
            });
        });
        if let Some(e) = write_error {
            // Kept with the scene's notes, which `stats` reports.
            self.scene
                .notes
                .push(format!("sppm: an intermediate image was not written: {e}"));
        }
        self.stats.rays.add(&rays);
        self.stats.samples += self.film.pixel_bounds().area().max(0) as u64 * total as u64;
        self.stats.render_time += t1.elapsed();
    }

    /// `mlt`'s own loop: bootstrap paths, then the Markov chains in groups
    /// whose splats are added to the film in chain order (`on_chunk` is
    /// called with the groups). The range of samples and the region of the
    /// other integrators do not apply.
    fn render_mlt(&mut self, on_chunk: &mut dyn FnMut(&ChunkDone)) {
        let Integrator::Mlt(mlt) = &self.integrator else {
            return;
        };
        let t1 = Instant::now();
        let run = crate::integrators::MltRun {
            scene: &self.scene,
            seed: self.seed,
            pool: &self.pool,
        };
        let whole = [self.film.pixel_bounds()];
        let done = mlt.render(&run, &mut self.film, &mut |k, total, film| {
            on_chunk(&ChunkDone {
                done: k,
                total,
                tiles: &whole,
                film,
            })
        });
        self.scene.notes.push(format!(
            "mlt: b = {:.6} from {} bootstrap paths; {} mutations, {:.1}% accepted",
            done.b,
            done.bootstrap_paths,
            done.mutations,
            100.0 * done.accepted as f64 / done.mutations.max(1) as f64
        ));
        self.stats.rays.add(&done.rays);
        self.stats.samples += done.mutations;
        self.stats.render_time += t1.elapsed();
    }

    /// Writes the integrator's extra splat images (bdpt's strategy
    /// images) next to the output image; returns the paths written.
    pub fn write_splat_images(&self) -> Result<Vec<std::path::PathBuf>, String> {
        let dir = self.output.parent().unwrap_or(std::path::Path::new(""));
        let mut written = Vec::new();
        for (layer, name) in self.integrator.splat_images() {
            let path = dir.join(name);
            crate::image::io::write_image(&path, &self.film.layer_image(layer))?;
            written.push(path);
        }
        Ok(written)
    }

    /// The sampler's samples per pixel.
    pub fn samples_per_pixel(&self) -> u32 {
        self.sampler.samples_per_pixel()
    }

    /// The film as rendered so far.
    pub fn film(&self) -> &Film {
        &self.film
    }

    pub fn image(&self) -> Image {
        self.film.image()
    }

    /// Statistics so far, with notes on what was built.
    pub fn stats(&self) -> RenderStats {
        let mut stats = self.stats.clone();
        stats.notes = self.scene.notes.clone();
        stats.notes.push(
            if let Integrator::Sppm(_) | Integrator::Mlt(_) = self.integrator {
                "the integrator's own render loop over the whole film (not tiles of samples)"
                    .to_string()
            } else if self.batch > 1 {
                format!(
                    "batched: {} samples in flight per thread ({:.1} KiB of lane state per thread)",
                    self.batch,
                    self.integrator
                        .batch(self.batch, &self.sampler)
                        .state_bytes() as f64
                        / 1024.0
                )
            } else {
                "one sample at a time per thread (scalar loop)".to_string()
            },
        );
        stats.notes.extend(self.integrator.notes());
        if let Some(ls) = self.integrator.light_sampler() {
            stats.notes.push(format!(
                "light selection: {:?} over {} lights that emit{}",
                ls.kind(),
                ls.active_count(),
                match (ls.kind(), ls.bvh_shape()) {
                    (crate::lights::LightSamplerKind::Spatial, _) =>
                        format!(", {} voxel distributions built", ls.voxels_built()),
                    (_, Some((tree, inf, depth))) => format!(
                        ", {tree} in a light BVH of depth {depth}, {inf} at infinity{}",
                        if ls.spatial_fallback() {
                            format!(" (\"spatial\" asked for: past {} lights pbrt-v3's voxel distributions would cost 128 estimates × every light per voxel, so the light BVH chooses instead)", crate::lights::SPATIAL_MAX_LIGHTS)
                        } else {
                            String::new()
                        }
                    ),
                    _ => String::new(),
                }
            ));
        }
        stats
    }
}

/// Renders `desc` (with its film, sampler and integrator settings as given:
/// apply command-line overrides to the description first). `progress` is
/// called after each group of tiles with (tiles done, tiles total).
pub fn render(
    desc: &SceneDescription,
    opts: &RenderOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<(Image, RenderStats), String> {
    render_observed(desc, opts, &mut |c: &ChunkDone| progress(c.done, c.total))
}

/// [`render`], with `on_chunk` called after each group of tiles (see
/// [`Renderer::render_samples_observed`]).
pub fn render_observed(
    desc: &SceneDescription,
    opts: &RenderOptions,
    on_chunk: &mut dyn FnMut(&ChunkDone),
) -> Result<(Image, RenderStats), String> {
    let mut r = Renderer::new(desc, opts)?;
    let spp = r.sampler.samples_per_pixel();
    r.render_samples_observed(0..spp, on_chunk);
    let mut stats = r.stats();
    match r.write_splat_images() {
        Ok(paths) if !paths.is_empty() => stats.notes.push(format!(
            "{} strategy images written next to the output image ({} … {})",
            paths.len(),
            paths[0].display(),
            paths[paths.len() - 1].display()
        )),
        Ok(_) => {}
        Err(e) => stats
            .notes
            .push(format!("the strategy images were not written: {e}")),
    }
    Ok((r.image(), stats))
}

/// Renders part `kind` of the frame `desc` describes (a tile or a range of
/// sample indices, see [`crate::render::film::part`]) and writes it to
/// `path` atomically (replacing an older copy). Returns the statistics.
pub fn render_part(
    desc: &SceneDescription,
    opts: &RenderOptions,
    kind: PartKind,
    path: &std::path::Path,
) -> Result<RenderStats, String> {
    let mut r = Renderer::new(desc, opts)?;
    if let Integrator::Sppm(_) = r.integrator {
        return Err(format!(
            "{kind}: sppm's iterations depend on each other (each shrinks the radii the next uses), so a frame cannot be split into parts; render it whole"
        ));
    }
    if let Integrator::Mlt(_) = r.integrator {
        return Err(format!(
            "{kind}: mlt's Markov chains splat anywhere in the image and its normalisation comes from the whole frame's bootstrap paths, so a frame cannot be split into tiles or sample ranges; render it whole"
        ));
    }
    let spp = r.samples_per_pixel();
    let header = PartHeader::new(desc, r.film(), opts.seed, kind);
    match kind {
        PartKind::Tile { .. } if matches!(r.integrator, Integrator::Bdpt(_)) => {
            return Err(format!(
                "{kind}: bdpt's light-tracing splats land anywhere in the image, so one tile needs every pixel's samples; split the frame by samples instead (--spp-range)"
            ));
        }
        PartKind::Tile { index, count } => {
            part::check_tile(r.film(), index, count)?;
            let rect = part::tile_rect(r.film().pixel_bounds(), index, count);
            let region = part::sample_region(r.film(), rect);
            r.render_region_observed(0..spp, Some(region), &mut |_| {});
            part::write_tile_part(path, &header, r.film())?;
        }
        PartKind::Samples { start, end } => {
            if start >= end || end > spp {
                return Err(format!(
                    "{kind} is not a range of the {spp} samples per pixel"
                ));
            }
            r.render_samples_observed(start..end, &mut |_| {});
            part::write_samples_part(path, &header, r.film())?;
        }
    }
    Ok(r.stats())
}

// Not inlined: a stable symbol for profilers (callgrind --toggle-collect).
#[inline(never)]
fn render_tile(
    scene: &RenderScene,
    integrator: &Integrator,
    film: &TileMaker,
    proto: &Sampler,
    bounds: Bounds2i,
    region: Option<Bounds2i>,
    samples: std::ops::Range<u32>,
) -> (FilmTile, TileCounts) {
    // The film tile of the whole tile (as the full render), samples taken
    // only in the region's pixels.
    let mut tile = film.tile(bounds);
    let pixels = match region {
        Some(r) => bounds.intersect(&r),
        None => bounds,
    };
    let mut sampler = proto.clone();
    let mut scratch = Scratch::default();
    let mut c = TileCounts::default();
    let camera = CameraRays::new(scene, proto);
    for pixel in pixels.iter() {
        for i in samples.clone() {
            sampler.start_pixel_sample(pixel, i);
            let (cs, time, ray, diff, weight) = camera.ray(scene, &mut sampler, pixel);
            // pbrt-v3 computes no radiance for a sample the lens blocks
            // (weight 0), but the film still counts its filter weight.
            let mut l = if weight > 0.0 {
                integrator.li(ray, time, diff, scene, &mut sampler, &mut scratch)
            } else {
                Vec3::ZERO
            };
            l = sanitise(l, &mut c);
            tile.add_sample(cs.p_film, l, weight);
            c.samples += 1;
        }
    }
    c.rays = scratch.counts();
    tile.set_splats(scratch.take_splats());
    (tile, c)
}

/// How the camera samples of a render become rays.
struct CameraRays {
    /// Only moving geometry (or a moving camera) reads a ray's time.
    moving: bool,
    /// Whether the camera sample's time and lens values are read (all
    /// samplers draw both, as pbrt-v3; Halton skips computing them when
    /// nothing reads them).
    lens: bool,
    /// Rays carry differentials only in scenes whose materials can use
    /// them; pbrt-v3 scales them by 1/√spp.
    differentials: bool,
    diff_scale: f32,
}

impl CameraRays {
    fn new(scene: &RenderScene, sampler: &Sampler) -> CameraRays {
        let moving = scene.camera.is_moving() || scene.aggregate.moving_count() > 0;
        CameraRays {
            moving,
            lens: scene.camera.uses_lens() || moving,
            differentials: scene.differentials,
            diff_scale: 1.0 / (sampler.samples_per_pixel() as f32).sqrt(),
        }
    }

    /// [`CameraRays::ray`] with the ray and its differentials written to
    /// `ray` and `diff` (where the batch keeps them: a ray returned and
    /// then copied stalls on the stores that made it).
    #[inline(always)]
    fn ray_into(
        &self,
        scene: &RenderScene,
        sampler: &mut Sampler,
        pixel: IVec2,
        ray: &mut Ray,
        diff: &mut Option<RayDiff>,
    ) -> (CameraSample, f32, f32) {
        let cs = sampler.camera_sample(pixel, self.lens);
        let time = if self.moving {
            scene.camera.time(&cs)
        } else {
            0.0
        };
        let w = if self.differentials {
            let (r, d, w) = scene.camera.generate_ray_differential(&cs, self.diff_scale);
            *ray = r;
            *diff = Some(d);
            w
        } else {
            let (r, w) = scene.camera.generate_ray(&cs);
            *ray = r;
            *diff = None;
            w
        };
        (cs, time, w)
    }

    /// The camera sample of `sampler`'s current sample (started at
    /// `pixel`) with its ray's time, the ray, its differentials and weight.
    #[inline(always)]
    fn ray(
        &self,
        scene: &RenderScene,
        sampler: &mut Sampler,
        pixel: IVec2,
    ) -> (CameraSample, f32, Ray, Option<RayDiff>, f32) {
        let (mut ray, mut diff) = (Ray::new(Vec3::ZERO, Vec3::Z), None);
        let (cs, time, w) = self.ray_into(scene, sampler, pixel, &mut ray, &mut diff);
        (cs, time, ray, diff, w)
    }
}

/// Samples in flight per thread in the batched renderer: enough
/// independent paths for the core to overlap one's memory and division
/// latencies with another's work, few enough that their state (10–13 KiB
/// for the Cornell scenes, the samplers included) stays in the first-level
/// cache.
pub const BATCH: usize = 16;

/// A thread's lanes for [`render_tile_batched`]: the batch, a sampler to
/// start at each pixel, and each lane's camera sample.
struct Lanes {
    b: Batch,
    at_pixel: Sampler,
    cs: Vec<CameraSample>,
}

impl Lanes {
    fn new(lanes: usize, proto: &Sampler, integrator: &Integrator) -> Lanes {
        Lanes {
            b: integrator.batch(lanes, proto),
            at_pixel: proto.clone(),
            cs: vec![CameraSample::default(); lanes],
        }
    }
}

/// [`render_tile`] with `lanes` samples at a time: their camera rays, then
/// the integrator's batch ([`Integrator::li_batch`]), then the film, in
/// the scalar loop's order (so the tile's sums are the same bit for bit).
#[inline(never)]
#[allow(clippy::too_many_arguments)]
fn render_tile_batched(
    scene: &RenderScene,
    integrator: &Integrator,
    film: &TileMaker,
    bounds: Bounds2i,
    region: Option<Bounds2i>,
    samples: std::ops::Range<u32>,
    lanes: &mut Lanes,
) -> (FilmTile, TileCounts) {
    let mut tile = film.tile(bounds);
    let pixels = match region {
        Some(r) => bounds.intersect(&r),
        None => bounds,
    };
    let Lanes { b, at_pixel, cs } = lanes;
    let lanes = b.samplers.len();
    // `at_pixel` is started at each pixel once, for what the lanes share.
    let mut current: Option<IVec2> = None;
    let mut scratch = Scratch::default();
    let mut c = TileCounts::default();
    let camera = CameraRays::new(scene, at_pixel);
    let mut todo = pixels
        .iter()
        .flat_map(|p| samples.clone().map(move |i| (p, i)))
        .peekable();
    while todo.peek().is_some() {
        // Camera rays.
        b.len = 0;
        for (pixel, i) in todo.by_ref().take(lanes) {
            let j = b.len;
            if current != Some(pixel) {
                at_pixel.start_pixel_sample(pixel, i);
                current = Some(pixel);
            }
            let sampler = &mut b.samplers[j];
            sampler.start_pixel_sample_from(at_pixel, pixel, i);
            let (ray, diff) = (&mut b.rays[j], &mut b.diffs[j]);
            let (cs_j, time, weight) = camera.ray_into(scene, sampler, pixel, ray, diff);
            cs[j] = cs_j;
            b.times[j] = time;
            b.weights[j] = weight;
            b.len += 1;
        }
        // Radiance.
        integrator.li_batch(b, scene, &mut scratch);
        // The film, in sample order.
        for ((cs, &l), &weight) in cs.iter().zip(&b.l).zip(&b.weights).take(b.len) {
            let l = sanitise(l, &mut c);
            tile.add_sample(cs.p_film, l, weight);
            c.samples += 1;
        }
    }
    c.rays = scratch.counts();
    tile.set_splats(scratch.take_splats());
    (tile, c)
}

/// pbrt-v3: samples with NaN, infinite or negative radiance are zeroed
/// (their weight is kept) and counted.
#[inline]
fn sanitise(l: Vec3, c: &mut TileCounts) -> Vec3 {
    if l.is_nan() {
        c.nan += 1;
        Vec3::ZERO
    } else if !l.is_finite() {
        c.inf += 1;
        Vec3::ZERO
    } else if luminance(l) < -1e-5 {
        c.negative += 1;
        Vec3::ZERO
    } else {
        l
    }
}

/// Bytes per film pixel over a render: f64 sums (32), the final linear image
/// (12) and the encoded file's buffer (up to 12).
const BYTES_PER_PIXEL: u64 = 56;

/// A film too large for this machine is an error before anything is
/// allocated, not an abort in the middle of the render.
fn check_film_memory(desc: &SceneDescription) -> Result<(), String> {
    let f = &desc.film;
    let [x0, x1, y0, y1] = f.cropwindow;
    let w = ((f.xresolution as f64 * x1 as f64).ceil() - (f.xresolution as f64 * x0 as f64).ceil())
        .max(0.0) as u64;
    let h = ((f.yresolution as f64 * y1 as f64).ceil() - (f.yresolution as f64 * y0 as f64).ceil())
        .max(0.0) as u64;
    // sppm keeps each pixel's state and visible point besides the film.
    // bdpt's splats: one f64 RGB sum per pixel, and one per strategy
    // image when they are written.
    let per_pixel = match desc.integrator {
        crate::integrators::IntegratorSettings::Sppm(_) => {
            BYTES_PER_PIXEL + crate::integrators::SPPM_PIXEL_BYTES
        }
        crate::integrators::IntegratorSettings::Bdpt(b) => {
            BYTES_PER_PIXEL + 24 * (1 + b.strategy_images().len() as u64)
        }
        crate::integrators::IntegratorSettings::Mlt(_) => BYTES_PER_PIXEL + 24,
        _ => BYTES_PER_PIXEL,
    };
    let need = w * h * per_pixel;
    match available_memory_bytes() {
        Some(avail) if need > avail / 10 * 9 => Err(format!(
            "the film needs {:.1} GiB ({w}×{h} pixels), more than the {:.1} GiB of memory available",
            need as f64 / (1u64 << 30) as f64,
            avail as f64 / (1u64 << 30) as f64
        )),
        _ => Ok(()),
    }
}

pub use crate::scene::memory::available_memory_bytes;

/// Peak resident memory of this process in bytes (Linux), if known.
pub fn peak_memory_bytes() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}
