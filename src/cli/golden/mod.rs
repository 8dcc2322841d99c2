//! `pbrs test DIR`: golden-image regression tests for a folder of scenes.
//!
//! Each scene is rendered (all threads, one scene at a time) and judged
//! against its golden `DIR/golden/NAME.exr` by [`crate::image::verdict`], the
//! verdict of the project's own golden test. A golden is the mean of two
//! renders with seeds s and s + 1 (`--update`, s = `--seed`, default 0; a
//! test render's default seed is s + 2); its header
//! records the noise of one render measured from the two ([`Noise`]), so
//! the bounds are multiples of the noise expected between a fresh render
//! and the golden. Nothing but `--update` writes goldens.

use crate::image::io::{check_output_path, write_image_with};
use crate::image::meta::{read_any, render_metadata};
use crate::image::verdict::{judge, nonfinite_pixels, Bounds, Noise, Verdict};
use crate::image::Image;
use crate::loader::{load_scene, print_diagnostics};
use crate::render::driver::{render_observed, ChunkDone, RenderOptions};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Instant;

pub mod manifest;
mod report;

use manifest::SceneEntry;

/// Header keys of a golden's noise estimate.
const KEY_NOISE: &str = "pbrsGoldenNoise";
const KEY_RENDERS: &str = "pbrsGoldenRenders";

/// Check the scenes of a folder against their golden images.
#[derive(clap::Args, Debug, Clone)]
pub struct TestArgs {
    /// The folder: its top-level .pbrt files, or those DIR/golden.toml lists;
    /// goldens live in DIR/golden/.
    #[arg(value_name = "DIR")]
    pub dir: PathBuf,
    /// Render and write the goldens (two renders, seeds s and s + 1) instead
    /// of checking against them.
    #[arg(long)]
    pub update: bool,
    /// Sampler seed of the test renders; default: two more than the
    /// golden's first seed, a render independent of the golden's two. With
    /// --update: the seed of the golden's first render (default 0).
    #[arg(long, value_name = "N")]
    pub seed: Option<u64>,
    /// Worker threads; absent or 0: all cores. Images do not depend on it.
    #[arg(long = "nthreads", visible_alias = "threads", value_name = "N")]
    pub threads: Option<usize>,
    /// Write JUnit XML (one test case per scene) to FILE.
    #[arg(long, value_name = "FILE")]
    pub junit: Option<PathBuf>,
    /// Write an HTML report (golden, render and difference of each failing
    /// scene) into DIR.
    #[arg(long, value_name = "DIR")]
    pub report: Option<PathBuf>,
    /// Print only failures, errors and the summary line.
    #[arg(long, short = 'q')]
    pub quiet: bool,
}

/// What happened to one scene.
#[derive(Clone, Debug)]
pub enum Outcome {
    Passed(Verdict),
    Failed(Verdict),
    Updated,
    /// Bad input: the scene, the golden or the render failed (the message).
    Error(String),
}

pub struct SceneResult {
    pub entry: SceneEntry,
    pub outcome: Outcome,
    pub seconds: f64,
    /// The verdict's bounds at tolerance 1 (the expected noise), for ratios.
    pub unit: Option<Bounds>,
    /// Render and golden of a failed scene, for the report.
    pub images: Option<(Image, Image)>,
}

impl SceneResult {
    /// The verdict's figures as multiples of the expected noise: relative
    /// MSE, block error, and the mean difference in standard deviations.
    pub fn ratios(&self) -> Option<[f64; 3]> {
        let v = match &self.outcome {
            Outcome::Passed(v) | Outcome::Failed(v) => v,
            _ => return None,
        };
        let u = self.unit.unwrap_or(v.bounds);
        let c = &v.comparison;
        Some([
            c.relative_mse / u.max_relative_mse,
            c.block_error / u.max_block_error,
            v.mean_difference / u.max_mean_difference,
        ])
    }
}

pub fn run(args: &TestArgs) -> i32 {
    let t0 = Instant::now();
    for out in args.junit.iter() {
        if let Err(e) = check_writable(out) {
            eprintln!("error: --junit {e}");
            return 2;
        }
    }
    let results = match check(args) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: {e}");
            return 2;
        }
    };
    let status = report::status(&results);
    report::print_table(&results, t0.elapsed().as_secs_f64(), args.quiet);
    let mut extra = 0;
    if let Some(f) = &args.junit {
        if let Err(e) = report::write_junit(f, &args.dir, &results) {
            eprintln!("error: {e}");
            extra = 2;
        }
    }
    if let Some(d) = &args.report {
        match report::write_html(d, &args.dir, &results) {
            Ok(p) if !args.quiet => eprintln!("report: {}", p.display()),
            Ok(_) => {}
            Err(e) => {
                eprintln!("error: {e}");
                extra = 2;
            }
        }
    }
    status.max(extra)
}

/// Renders and judges (or, with `--update`, writes the goldens of) every
/// scene of the folder, printing a line per scene; an error when the folder
/// or its golden.toml is unusable.
pub fn check(args: &TestArgs) -> Result<Vec<SceneResult>, String> {
    let entries = manifest::scenes(&args.dir)?;
    let golden_dir = args.dir.join("golden");
    let bar = progress_bar(args.quiet);
    let mut results = Vec::new();
    for (k, entry) in entries.iter().enumerate() {
        bar.set_message(format!("{}/{} {}", k + 1, entries.len(), entry.name));
        let t = Instant::now();
        let mut r = SceneResult {
            entry: entry.clone(),
            outcome: Outcome::Updated,
            seconds: 0.0,
            unit: None,
            images: None,
        };
        r.outcome = match run_scene(args, entry, &golden_dir, &bar, &mut r) {
            Ok(o) => o,
            Err(e) => Outcome::Error(e),
        };
        r.seconds = t.elapsed().as_secs_f64();
        bar.suspend(|| report::print_line(&r, args.quiet));
        results.push(r);
    }
    bar.finish_and_clear();
    Ok(results)
}

fn check_writable(path: &Path) -> Result<(), String> {
    // check_output_path wants an image extension; probe the directory alone
    // (made first: CI's report folders often do not exist yet).
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    check_output_path(&dir.join(".pbrs-probe.png"))
        .map_err(|_| format!("{}: cannot write in {}", path.display(), dir.display()))
}

fn progress_bar(quiet: bool) -> ProgressBar {
    if quiet || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let b = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
    b.set_style(
        ProgressStyle::with_template("{spinner} {msg:30} [{bar:30}] {percent:>3}% {elapsed}")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    b
}

/// Loads, renders and judges (or updates) one scene.
fn run_scene(
    args: &TestArgs,
    entry: &SceneEntry,
    golden_dir: &Path,
    bar: &ProgressBar,
    result: &mut SceneResult,
) -> Result<Outcome, String> {
    let file = &entry.file;
    let mut loaded = match load_scene(file) {
        Ok(l) => l,
        Err(f) => {
            bar.suspend(|| print_diagnostics(&f.errors));
            return Err(format!("{}: the scene did not load", file.display()));
        }
    };
    if !args.quiet && !loaded.warnings.is_empty() {
        // A warning (a missing texture rendered grey, say) may explain a failure.
        bar.suspend(|| print_diagnostics(&loaded.warnings));
    }
    let desc = &mut loaded.scene;
    if let Some(spp) = entry.settings.spp {
        desc.sampler.pixel_samples = spp;
    }
    if let Some((w, h)) = entry.settings.resolution {
        desc.film.xresolution = w;
        desc.film.yresolution = h;
    }
    let golden_path = golden_dir.join(format!("{}.exr", entry.name));
    let render = |seed: u64| -> Result<(Image, f64), String> {
        let opts = RenderOptions {
            threads: args.threads.filter(|&n| n > 0),
            seed,
            ..Default::default()
        };
        let mut on_chunk = |c: &ChunkDone| {
            bar.set_length(c.total as u64);
            bar.set_position(c.done as u64);
        };
        let (img, stats) = render_observed(desc, &opts, &mut on_chunk)
            .map_err(|e| format!("{}: {e}", file.display()))?;
        Ok((img, stats.render_time.as_secs_f64()))
    };
    let meta = |seed: u64, secs: f64| {
        render_metadata(
            &file.display().to_string(),
            desc.sampler.pixel_samples,
            desc.integrator.name(),
            seed,
            secs,
        )
    };
    if args.update {
        let seed = args.seed.unwrap_or(0);
        let (a, ta) = render(seed)?;
        let (b, tb) = render(seed.wrapping_add(1))?;
        let golden = Image {
            data: a
                .data
                .iter()
                .zip(&b.data)
                .map(|(x, y)| 0.5 * (x + y))
                .collect(),
            ..a.clone()
        };
        let bad = nonfinite_pixels(&golden);
        if bad > 0 {
            return Err(format!(
                "{}: the render has {bad} non-finite pixels; no golden written",
                file.display()
            ));
        }
        let noise = Noise::measure(&a, &b);
        let mut m = meta(seed, ta + tb);
        m.push((KEY_RENDERS.into(), "2".into()));
        m.push((KEY_NOISE.into(), noise_text(&noise)));
        std::fs::create_dir_all(golden_dir)
            .map_err(|e| format!("{}: {e}", golden_dir.display()))?;
        write_image_with(&golden_path, &golden, &m)?;
        return Ok(Outcome::Updated);
    }
    let (golden, noise, renders, golden_seed) = read_golden(&golden_path)?;
    let expect = (golden.width, golden.height);
    // The golden averages seeds s and s + 1: by default a third seed, so the
    // render's noise is independent of the golden's, as the bounds assume.
    let (img, _) = render(args.seed.unwrap_or(golden_seed.wrapping_add(2)))?;
    if (img.width, img.height) != expect {
        return Err(format!(
            "{}: the golden is {}×{} but the render is {}×{} (run pbrs test --update if the change is meant)",
            golden_path.display(),
            expect.0,
            expect.1,
            img.width,
            img.height
        ));
    }
    let s = &entry.settings;
    let bounds = noise.bounds(renders, s.tolerance, s.mean_tolerance);
    result.unit = Some(noise.bounds(renders, 1.0, 1.0));
    let v = judge(&img, &golden, bounds);
    if v.passed() {
        Ok(Outcome::Passed(v))
    } else {
        result.images = Some((img, golden));
        Ok(Outcome::Failed(v))
    }
}

fn noise_text(n: &Noise) -> String {
    format!(
        "relative_mse={:e} block_error={:e} mean_sigma={:e},{:e},{:e}",
        n.relative_mse, n.block_error, n.mean_sigma[0], n.mean_sigma[1], n.mean_sigma[2]
    )
}

fn parse_noise(t: &str) -> Option<Noise> {
    let mut n = Noise {
        relative_mse: f64::NAN,
        block_error: f64::NAN,
        mean_sigma: [f64::NAN; 3],
    };
    for kv in t.split_whitespace() {
        let (k, v) = kv.split_once('=')?;
        match k {
            "relative_mse" => n.relative_mse = v.parse().ok()?,
            "block_error" => n.block_error = v.parse().ok()?,
            "mean_sigma" => {
                let s: Vec<f64> = v
                    .split(',')
                    .map(str::parse)
                    .collect::<Result<_, _>>()
                    .ok()?;
                n.mean_sigma = s.try_into().ok()?;
            }
            _ => {}
        }
    }
    let all = [
        n.relative_mse,
        n.block_error,
        n.mean_sigma[0],
        n.mean_sigma[1],
        n.mean_sigma[2],
    ];
    all.iter().all(|x| x.is_finite() && *x >= 0.0).then_some(n)
}

/// The golden image, its noise, the number of renders it averages and the
/// seed of the first.
fn read_golden(path: &Path) -> Result<(Image, Noise, f64, u64), String> {
    if !path.exists() {
        return Err(format!(
            "{}: no golden (run pbrs test --update to make it)",
            path.display()
        ));
    }
    let f = read_any(path)?;
    let noise = f.get(KEY_NOISE).and_then(parse_noise).ok_or_else(|| {
        format!(
            "{}: not a pbrs golden (no valid {KEY_NOISE} attribute; run pbrs test --update)",
            path.display()
        )
    })?;
    let renders = f
        .get(KEY_RENDERS)
        .and_then(|r| r.parse::<f64>().ok())
        .filter(|r| *r >= 1.0)
        .unwrap_or(1.0);
    let seed = f
        .get(crate::image::meta::KEY_SEED)
        .and_then(|s| s.parse().ok())
        .unwrap_or(0);
    Ok((f.image, noise, renders, seed))
}
