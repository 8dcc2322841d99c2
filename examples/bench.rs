//! Benchmark: renders scenes and prints wall time, rays, Mrays/s, ns per ray,
//! peak memory, and the error against the scene's converged pbrt-v3 reference
//! (the render is box-downsampled to 128×128 first), so that a speed-up that
//! costs accuracy shows.
//!
//! cargo run --release --example bench -- [--spp N] [--res N] [--threads N]
//!     [--baseline PBRS_BINARY] [SCENE ...]
//!
//! Each scene runs in its own process so that peak memory is per scene.
//! With `--baseline`, another pbrs build (e.g. one of an earlier commit,
//! `git worktree add /tmp/base COMMIT && cargo build --release` there) renders
//! each scene right before this one, at the scene's own resolution, and the
//! table gains its wall time and the ratio: on a shared, noisy machine the
//! ratio of two runs made side by side means more than either time alone.

use pbrs::loader::load_scene;
use pbrs::render::driver::{peak_memory_bytes, render, RenderOptions};
use pbrs::render::film::compare::compare;
use pbrs::render::film::io::read_image;
use pbrs::render::film::Image;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

const DEFAULT_SCENES: [&str; 4] = [
    "scenes/cornell-path.pbrt",
    "scenes/cornell-direct.pbrt",
    "scenes/cornell-glass.pbrt",
    "scenes/cornell-dragon.pbrt",
];

/// Reference stem for a scene file (see scenes/README.md).
fn reference_stem(scene: &Path) -> Option<&'static str> {
    match scene.file_stem()?.to_str()? {
        "cornell-path" => Some("cornell-path"),
        "cornell-direct" => Some("cornell-direct"),
        "cornell-glass" => Some("cornell-glass"),
        "cornell-box" => Some("bitterli-cornell-box"),
        "cornell-dragon" => Some("dezeming-cornell-dragon"),
        _ => None,
    }
}

struct Opts {
    spp: u32,
    res: u32,
    threads: Option<usize>,
    scenes: Vec<PathBuf>,
    child: bool,
    baseline: Option<PathBuf>,
}

fn parse() -> Result<Opts, String> {
    let mut o = Opts {
        spp: 64,
        res: 512,
        threads: Some(2),
        scenes: Vec::new(),
        child: false,
        baseline: None,
    };
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut num = |name: &str| -> Result<u64, String> {
            args.next()
                .and_then(|v| v.parse().ok())
                .ok_or(format!("{name} needs a positive number"))
        };
        match a.as_str() {
            "--spp" => o.spp = num("--spp")? as u32,
            "--res" => o.res = num("--res")? as u32,
            "--threads" => o.threads = Some(num("--threads")? as usize),
            "--child" => o.child = true,
            "--baseline" => {
                o.baseline = Some(PathBuf::from(
                    args.next().ok_or("--baseline needs a pbrs binary")?,
                ))
            }
            s if s.starts_with("--") => return Err(format!("unknown option {s}")),
            s => o.scenes.push(PathBuf::from(s)),
        }
    }
    if o.scenes.is_empty() {
        o.scenes = DEFAULT_SCENES.iter().map(PathBuf::from).collect();
    }
    Ok(o)
}

/// Box-downsample by an integer factor.
fn downsample(img: &Image, f: u32) -> Image {
    let mut out = Image::new(img.width / f, img.height / f);
    for y in 0..out.height {
        for x in 0..out.width {
            let mut s = glam::Vec3::ZERO;
            for dy in 0..f {
                for dx in 0..f {
                    s += img.pixel(x * f + dx, y * f + dy);
                }
            }
            out.set_pixel(x, y, s / (f * f) as f32);
        }
    }
    out
}

fn child(o: &Opts) -> Result<(), String> {
    let start = Instant::now();
    let scene = &o.scenes[0];
    let mut desc = load_scene(scene)
        .map_err(|f| format!("{}: {} errors", scene.display(), f.errors.len()))?
        .scene;
    desc.film.xresolution = o.res;
    desc.film.yresolution = o.res;
    desc.sampler.pixel_samples = o.spp;
    let (img, stats) = render(
        &desc,
        &RenderOptions {
            threads: o.threads,
            seed: 0,
            ..Default::default()
        },
        &|_, _| {},
    )?;
    let wall = start.elapsed().as_secs_f64();
    let mut err = (f64::NAN, f64::NAN);
    if let Some(stem) = reference_stem(scene) {
        let ref_path = Path::new("scenes/references").join(format!("{stem}-128-16384.pfm"));
        if let (Ok(r), true) = (read_image(&ref_path), o.res.is_multiple_of(128)) {
            let c = compare(&downsample(&img, o.res / 128), &r);
            err = (c.relative_mse, c.block_error);
        }
    }
    println!(
        "RESULT {wall} {} {} {} {} {} {} {}",
        stats.rays.closest,
        stats.rays.shadow,
        stats.render_time.as_secs_f64(),
        peak_memory_bytes().unwrap_or(0),
        err.0,
        err.1,
        stats.threads
    );
    Ok(())
}

fn main() {
    let o = match parse() {
        Ok(o) => o,
        Err(e) => {
            eprintln!("bench: {e}");
            std::process::exit(2);
        }
    };
    if o.child {
        if let Err(e) = child(&o) {
            eprintln!("bench: {e}");
            std::process::exit(1);
        }
        return;
    }
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string())
        })
        .unwrap_or_default();
    println!(
        "machine: {} cores, {cpu}",
        std::thread::available_parallelism().map_or(0, |n| n.get())
    );
    println!("{}×{}, {} spp, threads {:?}; error: downsampled to 128×128 against the converged pbrt-v3 reference", o.res, o.res, o.spp, o.threads);
    println!();
    let base_cols = if o.baseline.is_some() {
        (" baseline wall s | ratio |", "---|---|")
    } else {
        ("", "")
    };
    println!("| scene | wall s | render s | rays M (closest + shadow) | Mrays/s | ns/ray | peak MiB | rel. MSE | block err |{}", base_cols.0);
    println!("|---|---|---|---|---|---|---|---|---|{}", base_cols.1);
    let exe = std::env::current_exe().expect("current exe");
    for scene in &o.scenes {
        let base_wall = o.baseline.as_ref().and_then(|b| run_baseline(b, scene, &o));
        let mut cmd = Command::new(&exe);
        cmd.arg("--child").arg(scene).args([
            "--spp",
            &o.spp.to_string(),
            "--res",
            &o.res.to_string(),
        ]);
        if let Some(t) = o.threads {
            cmd.args(["--threads", &t.to_string()]);
        }
        let out = match cmd.output() {
            Ok(out) => out,
            Err(e) => {
                eprintln!("bench: {e}");
                continue;
            }
        };
        let text = String::from_utf8_lossy(&out.stdout);
        let Some(line) = text.lines().find(|l| l.starts_with("RESULT ")) else {
            eprintln!(
                "bench: {} failed: {}",
                scene.display(),
                String::from_utf8_lossy(&out.stderr)
            );
            continue;
        };
        let v: Vec<f64> = line
            .split_whitespace()
            .skip(1)
            .map(|x| x.parse().unwrap_or(f64::NAN))
            .collect();
        let (wall, closest, shadow, render_s, mem, rel, block) =
            (v[0], v[1], v[2], v[3], v[4], v[5], v[6]);
        let rays = closest + shadow;
        let base = match base_wall {
            Some(b) => format!(" {b:.2} | {:.2} |", wall / b),
            None if o.baseline.is_some() => " failed | |".to_string(),
            None => String::new(),
        };
        println!(
            "| {} | {:.2} | {:.2} | {:.1} ({:.1} + {:.1}) | {:.2} | {:.0} | {:.1} | {:.5} | {:.5} |{base}",
            scene.file_stem().map(|s| s.to_string_lossy().to_string()).unwrap_or_default(),
            wall,
            render_s,
            rays / 1e6,
            closest / 1e6,
            shadow / 1e6,
            rays / render_s / 1e6,
            render_s * 1e9 / rays * v[7],
            mem / 1048576.0,
            rel,
            block
        );
    }
}

/// Wall time of the baseline binary rendering `scene` (its own resolution;
/// the same spp and threads), output to a temporary file.
fn run_baseline(bin: &Path, scene: &Path, o: &Opts) -> Option<f64> {
    let out = std::env::temp_dir().join(format!("pbrs-bench-baseline-{}.exr", std::process::id()));
    let mut cmd = Command::new(bin);
    cmd.arg(scene)
        .args(["--spp", &o.spp.to_string(), "--quiet", "--outfile"])
        .arg(&out);
    if let Some(t) = o.threads {
        cmd.args(["--threads", &t.to_string()]);
    }
    let start = Instant::now();
    let status = cmd.output().ok()?.status;
    let wall = start.elapsed().as_secs_f64();
    let _ = std::fs::remove_file(&out);
    status.success().then_some(wall)
}
