//! Rendering from the command line: load, apply overrides, render with a
//! progress bar (and optionally partial images and a live view), write the
//! image atomically, print a summary.

use super::display::Display;
use super::Args;
use crate::image::io::{
    check_output_path, format_for_path, write_image, write_image_with, ImageFormat,
};
use crate::image::Image;
use crate::loader::{load_scene_files_each, print_diagnostics, strictly};
use crate::render::driver::{
    peak_memory_bytes, render_observed, render_part, ChunkDone, RenderOptions,
};
use crate::render::film::part::PartKind;
use crate::scene::{Light, SamplerKind, SceneDescription};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::sync::mpsc::{sync_channel, TrySendError};
use std::time::{Duration, Instant};

/// Largest sample count accepted from the command line (as the scene builder).
const MAX_SPP: u32 = 1 << 24;

/// Seconds between partial images when `--write-partial-images` is given alone.
const DEFAULT_PARTIAL_INTERVAL: f64 = 10.0;

fn fail(msg: impl std::fmt::Display) -> i32 {
    eprintln!("error: {msg}");
    1
}

/// The scene files as one name for messages.
pub fn scenes_label(args: &Args) -> String {
    let names: Vec<String> = args
        .scenes
        .iter()
        .map(|p| {
            if p.as_os_str() == "-" {
                crate::loader::STDIN_NAME.to_string()
            } else {
                p.display().to_string()
            }
        })
        .collect();
    names.join(", ")
}

/// pbrt-v3's `--quick` (`PbrtOptions.quickRender`): film.cpp divides each
/// resolution by 4 (at least 1) before the crop window applies; every
/// sampler but "random" takes 1 sample per pixel (stratified: 1 × 1); the
/// diffuse area and infinite lights take a quarter of their "nsamples" (at
/// least 1); sppm takes a sixteenth of its iterations, mlt of its
/// mutations per pixel and bootstrap samples (at least 1).
pub fn apply_quick(desc: &mut SceneDescription) {
    match &mut desc.integrator {
        crate::integrators::IntegratorSettings::Sppm(s) => {
            s.iterations = (s.iterations / 16).max(1);
        }
        crate::integrators::IntegratorSettings::Mlt(m) => {
            m.mutations_per_pixel = (m.mutations_per_pixel / 16).max(1);
            m.bootstrap_samples = (m.bootstrap_samples / 16).max(1);
        }
        _ => {}
    }
    desc.film.xresolution = (desc.film.xresolution / 4).max(1);
    desc.film.yresolution = (desc.film.yresolution / 4).max(1);
    match &mut desc.sampler.kind {
        SamplerKind::Random => {}
        SamplerKind::Stratified {
            xsamples, ysamples, ..
        } => {
            *xsamples = 1;
            *ysamples = 1;
            desc.sampler.pixel_samples = 1;
        }
        _ => desc.sampler.pixel_samples = 1,
    }
    let quarter = |n: &mut u32| *n = (*n / 4).max(1);
    let shapes = desc
        .shapes
        .iter_mut()
        .chain(desc.objects.iter_mut().flat_map(|o| o.shapes.iter_mut()));
    for s in shapes {
        if let Some(a) = &mut s.area_light {
            quarter(&mut a.n_samples);
        }
    }
    for l in desc.lights.iter_mut().filter_map(Light::n_samples_mut) {
        quarter(l);
    }
}

/// A crop window in NDC whose pixel bounds are exactly `x0..x1, y0..y1`
/// under the film's `ceil(res · c)` (pbrt-v4's `--pixelbounds`, clamped to
/// the image). `(p - 1/2) / res` lands strictly inside pixel `p`'s interval.
fn pixel_bounds_to_crop(b: [i64; 4], xres: u32, yres: u32) -> Option<[f32; 4]> {
    let ndc = |p: i64, res: u32| {
        let p = p.clamp(0, res as i64);
        if p == 0 {
            0.0
        } else if p == res as i64 {
            1.0
        } else {
            ((p as f64 - 0.5) / res as f64) as f32
        }
    };
    let (x0, x1) = (b[0].min(b[1]), b[0].max(b[1]));
    let (y0, y1) = (b[2].min(b[3]), b[2].max(b[3]));
    let c = [ndc(x0, xres), ndc(x1, xres), ndc(y0, yres), ndc(y1, yres)];
    (c[0] < c[1] && c[2] < c[3]).then_some(c)
}

/// Applies the command line to the loaded description; an error message for
/// a value pbrs cannot use.
fn apply_overrides(
    args: &Args,
    desc: &mut SceneDescription,
    film_crop: bool,
) -> Result<(), String> {
    if args.quick {
        apply_quick(desc);
    }
    if let Some(spp) = args.spp {
        if spp == 0 || spp > MAX_SPP {
            return Err(format!("--spp must be between 1 and {MAX_SPP}, not {spp}"));
        }
        if let Some(w) = crate::samplers::override_spp(&mut desc.sampler, spp) {
            if args.warnings() {
                eprintln!("warning: --spp {spp}: {w}");
            }
        }
    }
    if let Some(c) = &args.cropwindow {
        if c.len() != 4 || !c.iter().all(|v| v.is_finite()) {
            return Err("--cropwindow takes four numbers X0 X1 Y0 Y1".into());
        }
        // pbrt-v3 (film.cpp): the Film's own crop window wins; the command
        // line's is clamped to [0, 1] and ordered.
        if film_crop {
            if args.warnings() {
                eprintln!("warning: --cropwindow is ignored: the Film gives a \"cropwindow\" (pbrt-v3 uses the scene's)");
            }
        } else {
            let k = |v: f32| v.clamp(0.0, 1.0);
            let w = [
                k(c[0].min(c[1])),
                k(c[0].max(c[1])),
                k(c[2].min(c[3])),
                k(c[2].max(c[3])),
            ];
            if w[0] >= w[1] || w[2] >= w[3] {
                return Err("--cropwindow is empty: it covers no pixels".into());
            }
            desc.film.cropwindow = w;
        }
    }
    if let Some(b) = &args.pixelbounds {
        let f = &desc.film;
        let b = [b[0], b[1], b[2], b[3]];
        match pixel_bounds_to_crop(b, f.xresolution, f.yresolution) {
            Some(c) => desc.film.cropwindow = c,
            None => {
                return Err(format!(
                    "--pixelbounds {} {} {} {} covers no pixel of the {}x{} image",
                    b[0], b[1], b[2], b[3], f.xresolution, f.yresolution
                ))
            }
        }
    }
    if let Some(out) = &args.outfile {
        desc.film.filename = out.clone();
    }
    if let Some(s) = args.partial_interval {
        if !(s.is_finite() && s >= 0.0) {
            return Err(format!(
                "--partial-interval must be a number of seconds, not {s}"
            ));
        }
    }
    Ok(())
}

/// The part of the frame the command line asks for (--tile/--tiles,
/// --spp-range), checked against the scene; None for the whole frame.
fn part_request(args: &Args, desc: &SceneDescription) -> Result<Option<PartKind>, String> {
    let env_number = |names: &[&str], flag: &str| -> Result<u32, String> {
        for n in names {
            if let Ok(v) = std::env::var(n) {
                return v.trim().parse().map_err(|_| {
                    format!("--{flag} env: ${n} is {v:?}, not a non-negative integer")
                });
            }
        }
        Err(format!(
            "--{flag} env: none of ${} is set",
            names.join(", $")
        ))
    };
    let number = |v: &str, names: &[&str], flag: &str| -> Result<u32, String> {
        if v == "env" {
            env_number(names, flag)
        } else {
            v.parse()
                .map_err(|_| format!("--{flag} takes a non-negative integer or `env`, not {v:?}"))
        }
    };
    let kind = match (&args.tile, &args.tiles, &args.spp_range) {
        (Some(k), Some(n), None) => {
            let k = number(k, &["SLURM_ARRAY_TASK_ID", "JOB_COMPLETION_INDEX"], "tile")?;
            let n = number(n, &["SLURM_ARRAY_TASK_COUNT"], "tiles")?;
            PartKind::Tile { index: k, count: n }
        }
        (None, None, Some(r)) => {
            let (a, b) = (r[0], r[1]);
            let spp = desc.sampler.pixel_samples;
            if a >= b || b > spp {
                return Err(format!(
                    "--spp-range {a} {b} is not a range of the {spp} samples per pixel (0 <= A < B <= {spp})"
                ));
            }
            PartKind::Samples { start: a, end: b }
        }
        (None, None, None) => return Ok(None),
        _ => return Err("--tile needs --tiles; --spp-range excludes them".into()),
    };
    if args.write_partial_images || args.partial_interval.is_some() || args.display_server.is_some()
    {
        return Err("--write-partial-images, --partial-interval and --display-server do not work with --tile or --spp-range".into());
    }
    if format_for_path(&desc.film.filename)? != ImageFormat::Exr {
        return Err(format!(
            "{}: a part is written as OpenEXR: give an .exr --outfile",
            desc.film.filename.display()
        ));
    }
    Ok(Some(kind))
}

/// Renders one part of the frame and writes it (atomically, replacing an
/// older copy: a rerun task overwrites its part).
fn render_part_cli(args: &Args, desc: &SceneDescription, kind: PartKind, started: Instant) -> i32 {
    let out = &desc.film.filename;
    let opts = RenderOptions {
        threads: args.threads.filter(|&n| n > 0),
        seed: args.seed,
        ..Default::default()
    };
    let stats = match render_part(desc, &opts, kind, out) {
        Ok(s) => s,
        Err(e) => return fail(e),
    };
    if !args.quiet {
        let ready = started.elapsed().saturating_sub(stats.render_time);
        eprintln!(
            "{}: {kind}, {} spp, {} threads; load + build + write {:.3} s (build {:.3} s), render {:.3} s, {} samples",
            out.display(),
            desc.sampler.pixel_samples,
            stats.threads,
            ready.as_secs_f64(),
            stats.build_time.as_secs_f64(),
            stats.render_time.as_secs_f64(),
            stats.samples
        );
    }
    0
}

/// Writes partial images on a thread of its own (at most one waiting), so a
/// slow disk never holds the render; joined before the final image is
/// written, so a late partial write cannot replace it.
struct PartialWriter {
    tx: Option<std::sync::mpsc::SyncSender<Image>>,
    thread: Option<std::thread::JoinHandle<(usize, Option<String>)>>,
    interval: Duration,
    last: Instant,
}

impl PartialWriter {
    fn new(path: PathBuf, interval: Duration) -> PartialWriter {
        let (tx, rx) = sync_channel::<Image>(1);
        let thread = std::thread::Builder::new()
            .name("pbrs-partial".into())
            .spawn(move || {
                let (mut n, mut err) = (0, None);
                for img in rx {
                    match write_image(&path, &img) {
                        Ok(()) => n += 1,
                        Err(e) => err = Some(e),
                    }
                }
                (n, err)
            })
            .ok();
        PartialWriter {
            tx: Some(tx),
            thread,
            interval,
            last: Instant::now(),
        }
    }

    fn chunk(&mut self, c: &ChunkDone) {
        if c.done == c.total || self.last.elapsed() < self.interval {
            return;
        }
        self.last = Instant::now();
        if let Some(tx) = &self.tx {
            if let Err(TrySendError::Disconnected(_)) = tx.try_send(c.film.image()) {
                self.tx = None;
            }
        }
    }

    /// Stops the thread: the count of partial images written, the last error.
    fn finish(mut self) -> (usize, Option<String>) {
        self.tx = None;
        self.thread
            .take()
            .and_then(|t| t.join().ok())
            .unwrap_or((0, None))
    }
}

pub fn run(args: &Args) -> i32 {
    let started = Instant::now();
    let label = scenes_label(args);
    let scenes = match load_scene_files_each(&args.scenes).and_then(|s| {
        if args.strict {
            strictly(s)
        } else {
            Ok(s)
        }
    }) {
        Ok(l) => l,
        Err(f) => {
            if args.warnings() {
                print_diagnostics(&f.warnings);
            }
            print_diagnostics(&f.errors);
            eprintln!("{label}: the scene was not loaded; no image was written");
            return 1;
        }
    };
    // Reading and parsing the scene files and everything they name
    // (meshes, textures, media): all scenes of the run together.
    let load_time = started.elapsed();
    if scenes.is_empty() && args.warnings() {
        eprintln!("warning: {label}: the scene is empty: nothing to render (as pbrt-v3)");
    }
    // pbrt-v3 renders at each WorldEnd: several world blocks (several
    // complete scene files) render one after the other.
    for loaded in scenes {
        if args.warnings() {
            print_diagnostics(&loaded.warnings);
        }
        let status = render_one(
            args,
            loaded.scene,
            loaded.film_has_cropwindow,
            started,
            load_time,
        );
        if status != 0 {
            return status;
        }
    }
    0
}

/// Renders one scene with the command line's overrides and writes its image.
fn render_one(
    args: &Args,
    mut desc: SceneDescription,
    film_has_cropwindow: bool,
    started: Instant,
    load_time: std::time::Duration,
) -> i32 {
    // Command-line overrides, validated before any work is done.
    // A value the flags cannot take is a usage error.
    let part = match apply_overrides(args, &mut desc, film_has_cropwindow)
        .and_then(|()| part_request(args, &desc))
    {
        Ok(p) => p,
        Err(e) => {
            eprintln!("error: {e}");
            return super::USAGE_ERROR;
        }
    };
    let out = desc.film.filename.clone();
    if let Err(e) = check_output_path(&out) {
        return fail(format!("cannot write {}: {e}", out.display()));
    }
    if let Some(kind) = part {
        return render_part_cli(args, &desc, kind, started);
    }

    let show_progress = !args.quiet && std::io::stderr().is_terminal();
    let bar = if show_progress {
        let b = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
        b.set_style(
            ProgressStyle::with_template("{spinner} rendering [{bar:40}] {percent:>3}% {elapsed_precise} elapsed, {eta} left")
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .progress_chars("=> "),
        );
        b
    } else {
        ProgressBar::hidden()
    };
    let opts = RenderOptions {
        // pbrt-v3: 0 threads means one per core.
        threads: args.threads.filter(|&n| n > 0),
        seed: args.seed,
        ..Default::default()
    };
    let mut partial = (args.write_partial_images || args.partial_interval.is_some()).then(|| {
        let s = args.partial_interval.unwrap_or(DEFAULT_PARTIAL_INTERVAL);
        PartialWriter::new(out.clone(), Duration::from_secs_f64(s))
    });
    let mut display: Option<Display> = None;
    let display_addr = args.display_server.clone();
    let title = format!("{} ({})", out.display(), std::process::id());
    let mut on_chunk = |c: &ChunkDone| {
        bar.set_length(c.total as u64);
        bar.set_position(c.done as u64);
        if let Some(addr) = &display_addr {
            let d = display
                .get_or_insert_with(|| Display::start(addr, title.clone(), c.film.pixel_bounds()));
            // The pixels the group's tiles cover, merged so far.
            for t in c.tiles {
                let (r, rgb) = c.film.region_rgb(*t);
                d.offer(r, rgb);
            }
        }
        if let Some(p) = &mut partial {
            p.chunk(c);
        }
    };
    let cuts = crate::scene::bounds::cuts();
    let result = render_observed(&desc, &opts, &mut on_chunk);
    bar.finish_and_clear();
    let cut = crate::scene::bounds::cut_warnings(cuts, crate::scene::bounds::cuts());
    if args.strict && !cut.is_empty() {
        return fail(format!(
            "{} (an error with --strict); no image was written",
            cut.join("; ")
        ));
    }
    if args.warnings() {
        for w in cut {
            eprintln!("warning: {w}");
        }
    }
    let partial_result = partial.map(PartialWriter::finish);
    let (image, stats) = match result {
        Ok(r) => r,
        Err(e) => return fail(e),
    };
    let metadata = if args.reproducible {
        Vec::new()
    } else {
        crate::image::meta::render_metadata(
            &scenes_label(args),
            desc.sampler.pixel_samples,
            desc.integrator.name(),
            args.seed,
            stats.render_time.as_secs_f64(),
        )
    };
    if let Err(e) = write_image_with(&out, &image, &metadata) {
        return fail(format!("cannot write {}: {e}", out.display()));
    }
    if let Some(d) = display {
        if let Some(e) = d.finish(&image) {
            if args.warnings() {
                eprintln!("warning: {e}: the live view stopped; the render went on");
            }
        }
    }
    if !args.quiet {
        let mem = peak_memory_bytes().map_or("unknown".to_string(), |b| {
            format!("{:.1} MiB", b as f64 / (1024.0 * 1024.0))
        });
        eprintln!(
            "{}: {}x{} px, {}, {} threads; load {:.2} s, build {:.2} s, render {:.2} s; {:.1} M rays ({:.1} M closest-hit + {:.1} M shadow), {:.2} Mrays/s; {} samples dropped (NaN {}, Inf {}, negative {}); peak memory {}",
            out.display(),
            image.width,
            image.height,
            match &desc.integrator {
                crate::integrators::IntegratorSettings::Mlt(m) =>
                    format!("{} mutations per pixel", m.mutations_per_pixel),
                _ => format!("{} spp", desc.sampler.pixel_samples),
            },
            stats.threads,
            load_time.as_secs_f64(),
            stats.build_time.as_secs_f64(),
            stats.render_time.as_secs_f64(),
            stats.rays.total() as f64 / 1e6,
            stats.rays.closest as f64 / 1e6,
            stats.rays.shadow as f64 / 1e6,
            stats.mrays_per_sec(),
            stats.dropped_samples(),
            stats.nan_samples,
            stats.inf_samples,
            stats.negative_samples,
            mem
        );
    }
    if let Some((_, Some(e))) = &partial_result {
        if args.warnings() {
            eprintln!("warning: a partial image could not be written: {e}");
        }
    }
    if args.stats {
        eprintln!("statistics:");
        eprintln!(
            "  times: load {:.3} s (scene text and the files it names), build {:.3} s (BVH {:.3} s on {} thread{}; lights, film), render {:.3} s",
            load_time.as_secs_f64(),
            stats.build_time.as_secs_f64(),
            stats.bvh_time.as_secs_f64(),
            stats.threads,
            if stats.threads == 1 { "" } else { "s" },
            stats.render_time.as_secs_f64()
        );
        for n in desc
            .skipped
            .iter()
            .map(|s| format!("left out: {s}"))
            .chain(stats.notes.iter().cloned())
        {
            eprintln!("  {n}");
        }
        eprintln!("  samples: {}", stats.samples);
        eprintln!(
            "  rays: {} closest-hit, {} shadow",
            stats.rays.closest, stats.rays.shadow
        );
        if let Some((n, _)) = partial_result {
            eprintln!("  partial images written: {n}");
        }
    }
    0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quick_changes_what_pbrt_v3_changes() {
        let text = r#"Film "image" "integer xresolution" [ 130 ] "integer yresolution" [ 7 ]
Sampler "stratified" "integer xsamples" [ 3 ] "integer ysamples" [ 5 ]
WorldBegin
LightSource "infinite" "rgb L" [ 1 1 1 ] "integer nsamples" [ 6 ]
AttributeBegin
AreaLightSource "diffuse" "integer nsamples" [ 9 ]
Shape "sphere"
AttributeEnd
ObjectBegin "o"
AreaLightSource "diffuse" "integer nsamples" [ 3 ]
Shape "sphere"
ObjectEnd
ObjectInstance "o"
WorldEnd
"#;
        let mut d = crate::loader::load_scene_str(text, std::path::Path::new("q.pbrt"))
            .unwrap_or_else(|f| panic!("{f:?}"))
            .scene;
        apply_quick(&mut d);
        assert_eq!((d.film.xresolution, d.film.yresolution), (32, 1));
        assert_eq!(d.sampler.pixel_samples, 1);
        assert!(matches!(
            d.sampler.kind,
            SamplerKind::Stratified {
                xsamples: 1,
                ysamples: 1,
                ..
            }
        ));
        assert_eq!(d.shapes[0].area_light.unwrap().n_samples, 2);
        let inf = d.lights.iter().find_map(|l| match l {
            Light::Infinite(i) => Some(i.n_samples),
            _ => None,
        });
        assert_eq!(inf, Some(1));
        // The random sampler keeps its count (pbrt-v3's RandomSampler has no
        // quick-render case).
        let text = "Sampler \"random\" \"integer pixelsamples\" [ 8 ]\nWorldBegin\nWorldEnd\n";
        let mut d = crate::loader::load_scene_str(text, std::path::Path::new("r.pbrt"))
            .unwrap_or_else(|f| panic!("{f:?}"))
            .scene;
        apply_quick(&mut d);
        assert_eq!(d.sampler.pixel_samples, 8);
        assert_eq!((d.film.xresolution, d.film.yresolution), (320, 180));
    }

    #[test]
    fn pixel_bounds_map_to_exact_pixels() {
        for res in [1u32, 3, 7, 64, 1000, 1280, 4097] {
            for (a, b) in [
                (0i64, 1i64),
                (1, 2),
                (0, res as i64),
                (res as i64 / 3, res as i64 / 2 + 1),
            ] {
                if a >= b || b > res as i64 {
                    continue;
                }
                let c = pixel_bounds_to_crop([a, b, a, b], res, res).unwrap();
                // As the film computes them (f32).
                let p0 = (res as f32 * c[0]).ceil() as i64;
                let p1 = (res as f32 * c[1]).ceil() as i64;
                assert_eq!((p0, p1), (a, b), "res {res}");
            }
        }
        assert!(pixel_bounds_to_crop([5, 5, 0, 1], 10, 10).is_none());
        assert!(pixel_bounds_to_crop([20, 30, 0, 1], 10, 10).is_none());
    }
}
