//! Benchmark: renders scenes and prints wall time, rays, Mrays/s, ns per ray,
//! peak memory, and the error against the scene's converged pbrt-v3 reference
//! (the render is box-downsampled to 128×128 first), so that a speed-up that
//! costs accuracy shows.
//!
//! cargo run --release --example bench -- [--spp N] [--res N] [--threads N]
//!     [--baseline PBRS_BINARY] [--mitsuba DIR [--python PY]] [--runs N]
//!     [SCENE ...]
//!
//! Each scene runs in its own process so that peak memory is per scene.
//! With `--baseline`, another pbrs build (e.g. one of an earlier commit,
//! `git worktree add /tmp/base COMMIT && cargo build --release` there) renders
//! each scene right before this one, at the scene's own resolution, and the
//! table gains its wall time and the ratio: on a shared, noisy machine the
//! ratio of two runs made side by side means more than either time alone.
//!
//! With `--mitsuba DIR`, Mitsuba 3's `llvm_ad_rgb` variant renders the
//! scene's equivalent `DIR/<stem>.xml` (the Mitsuba scenes of the Cornell
//! boxes, with their `render.py`) right after each pbrs run, at the same spp
//! and threads, and the table gains its whole-process wall time, its error
//! against the same reference, the time ratio at equal spp and the ratio at
//! equal error, `(t_pbrs · relMSE_pbrs) / (t_mitsuba · relMSE_mitsuba)` (the
//! time each would need for the same relative MSE, as MSE ∝ 1/spp). One
//! untimed Mitsuba run per scene comes first, so that its kernels are
//! compiled and cached. `--python` names the interpreter that has `mitsuba`
//! (default: `DIR/venv/bin/python` if present, else `python3`);
//! `DRJIT_LIBLLVM_PATH` is set to Debian's libLLVM 19 if unset and present.
//! `--runs N` repeats pbrs, baseline and Mitsuba alternately N times and
//! reports each one's minimum wall time.

use pbrs::image::compare::compare;
use pbrs::image::io::read_image;
use pbrs::image::Image;
use pbrs::loader::load_scene;
use pbrs::render::driver::{peak_memory_bytes, render, RenderOptions};
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
    mitsuba: Option<PathBuf>,
    python: Option<PathBuf>,
    runs: u32,
}

fn parse() -> Result<Opts, String> {
    let mut o = Opts {
        spp: 64,
        res: 512,
        threads: Some(2),
        scenes: Vec::new(),
        child: false,
        baseline: None,
        mitsuba: None,
        python: None,
        runs: 1,
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
            "--mitsuba" => {
                o.mitsuba = Some(PathBuf::from(
                    args.next()
                        .ok_or("--mitsuba needs the folder of the Mitsuba scenes")?,
                ))
            }
            "--python" => {
                o.python = Some(PathBuf::from(
                    args.next().ok_or("--python needs an interpreter")?,
                ))
            }
            "--runs" => o.runs = (num("--runs")? as u32).max(1),
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

/// Relative MSE and block error of `img` (box-downsampled to 128×128)
/// against the scene's converged pbrt-v3 reference; NaN without one.
fn reference_error(img: &Image, scene: &Path) -> (f64, f64) {
    let Some(stem) = reference_stem(scene) else {
        return (f64::NAN, f64::NAN);
    };
    let ref_path = Path::new("scenes/references").join(format!("{stem}-128-16384.pfm"));
    match read_image(&ref_path) {
        Ok(r) if img.width == img.height && img.width.is_multiple_of(128) => {
            let c = compare(&downsample(img, img.width / 128), &r);
            (c.relative_mse, c.block_error)
        }
        _ => (f64::NAN, f64::NAN),
    }
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
    let err = reference_error(&img, scene);
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
    let o = &match parse() {
        Ok(o) => o,
        Err(e) => {
            eprintln!("bench: {e}");
            std::process::exit(2);
        }
    };
    if o.child {
        if let Err(e) = child(o) {
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
    let mut extra_head = String::new();
    let mut extra_rule = String::new();
    if o.baseline.is_some() {
        extra_head += " baseline wall s | ratio |";
        extra_rule += "---|---|";
    }
    if o.mitsuba.is_some() {
        extra_head += " Mitsuba wall s | Mitsuba rel. MSE | pbrs / Mitsuba | at equal error |";
        extra_rule += "---|---|---|---|";
    }
    if o.runs > 1 {
        println!("wall times: minimum of {} alternating runs", o.runs);
    }
    println!("| scene | wall s | render s | rays M (closest + shadow) | Mrays/s | ns/ray | peak MiB | rel. MSE | block err |{extra_head}");
    println!("|---|---|---|---|---|---|---|---|---|{extra_rule}");
    let exe = std::env::current_exe().expect("current exe");
    let mitsuba = o.mitsuba.as_ref().map(|dir| Mitsuba::new(dir, o));
    for scene in &o.scenes {
        let mts_xml = mitsuba.as_ref().and_then(|m| m.scene(scene, o));
        if let (Some(m), Some(xml)) = (&mitsuba, &mts_xml) {
            // Compiles (or loads the cached) kernels: not timed.
            let _ = m.run(xml, o);
        }
        let mut best: Option<Vec<f64>> = None;
        let mut base_wall: Option<f64> = None;
        let mut mts: Option<(f64, (f64, f64))> = None;
        for _ in 0..o.runs {
            if let Some(b) = &o.baseline {
                if let Some(w) = run_baseline(b, scene, o) {
                    base_wall = Some(base_wall.map_or(w, |x: f64| x.min(w)));
                }
            }
            if let Some(v) = run_child(&exe, scene, o) {
                if best.as_ref().is_none_or(|b| v[0] < b[0]) {
                    best = Some(v);
                }
            }
            if let (Some(m), Some(xml)) = (&mitsuba, &mts_xml) {
                if let Some((w, img)) = m.run(xml, o) {
                    let err = reference_error(&img, scene);
                    if mts.is_none_or(|(b, _)| w < b) {
                        mts = Some((w, err));
                    }
                }
            }
        }
        let Some(v) = best else {
            continue;
        };
        let (wall, closest, shadow, render_s, mem, rel, block) =
            (v[0], v[1], v[2], v[3], v[4], v[5], v[6]);
        let rays = closest + shadow;
        let mut extra = match base_wall {
            Some(b) => format!(" {b:.2} | {:.2} |", wall / b),
            None if o.baseline.is_some() => " failed | |".to_string(),
            None => String::new(),
        };
        if mitsuba.is_some() {
            extra += &match (&mts_xml, mts) {
                (Some(_), Some((w, (m_rel, _)))) => format!(
                    " {w:.2} | {m_rel:.3e} | {:.2} | {:.2} |",
                    wall / w,
                    (wall * rel) / (w * m_rel)
                ),
                (Some(_), None) => " failed | | | |".to_string(),
                (None, _) => " — | | | |".to_string(),
            };
        }
        println!(
            "| {} | {:.2} | {:.2} | {:.1} ({:.1} + {:.1}) | {:.2} | {:.0} | {:.1} | {:.3e} | {:.5} |{extra}",
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

/// One pbrs render of `scene` in a child process: its RESULT figures.
fn run_child(exe: &Path, scene: &Path, o: &Opts) -> Option<Vec<f64>> {
    let mut cmd = Command::new(exe);
    cmd.arg("--child")
        .arg(scene)
        .args(["--spp", &o.spp.to_string(), "--res", &o.res.to_string()]);
    if let Some(t) = o.threads {
        cmd.args(["--threads", &t.to_string()]);
    }
    let out = match cmd.output() {
        Ok(out) => out,
        Err(e) => {
            eprintln!("bench: {e}");
            return None;
        }
    };
    let text = String::from_utf8_lossy(&out.stdout);
    let Some(line) = text.lines().find(|l| l.starts_with("RESULT ")) else {
        eprintln!(
            "bench: {} failed: {}",
            scene.display(),
            String::from_utf8_lossy(&out.stderr)
        );
        return None;
    };
    Some(
        line.split_whitespace()
            .skip(1)
            .map(|x| x.parse().unwrap_or(f64::NAN))
            .collect(),
    )
}

/// Mitsuba 3 (`llvm_ad_rgb`) rendering the equivalent scenes of a folder
/// with their `render.py`.
struct Mitsuba {
    dir: PathBuf,
    python: PathBuf,
    out: PathBuf,
}

impl Mitsuba {
    fn new(dir: &Path, o: &Opts) -> Mitsuba {
        let venv = dir.join("venv/bin/python");
        let python = o.python.clone().unwrap_or_else(|| {
            if venv.exists() {
                venv
            } else {
                PathBuf::from("python3")
            }
        });
        Mitsuba {
            dir: dir.to_path_buf(),
            python,
            out: std::env::temp_dir()
                .join(format!("pbrs-bench-mitsuba-{}.exr", std::process::id())),
        }
    }

    /// The equivalent of `scene` (`DIR/<stem>.xml`), if there is one and the
    /// resolution is the Mitsuba scenes' own 512×512.
    fn scene(&self, scene: &Path, o: &Opts) -> Option<PathBuf> {
        let xml = self
            .dir
            .join(format!("{}.xml", scene.file_stem()?.to_str()?));
        if !xml.exists() {
            return None;
        }
        if o.res != 512 {
            eprintln!(
                "bench: the Mitsuba scenes are 512×512; not run at --res {}",
                o.res
            );
            return None;
        }
        Some(xml)
    }

    /// Whole-process wall time of one render, and its image.
    fn run(&self, xml: &Path, o: &Opts) -> Option<(f64, Image)> {
        let mut cmd = Command::new(&self.python);
        cmd.current_dir(&self.dir)
            .arg("render.py")
            .arg("llvm_ad_rgb")
            .arg(xml)
            .arg(&self.out)
            .args(["--spp", &o.spp.to_string(), "--quiet"])
            .args([
                "--threads",
                &o.threads
                    .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
                    .to_string(),
            ]);
        let llvm = Path::new("/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1");
        if std::env::var_os("DRJIT_LIBLLVM_PATH").is_none() && llvm.exists() {
            cmd.env("DRJIT_LIBLLVM_PATH", llvm);
        }
        let start = Instant::now();
        let out = cmd.output();
        let wall = start.elapsed().as_secs_f64();
        match out {
            Ok(out) if out.status.success() => {}
            Ok(out) => {
                eprintln!(
                    "bench: Mitsuba failed on {}: {}",
                    xml.display(),
                    String::from_utf8_lossy(&out.stderr)
                );
                return None;
            }
            Err(e) => {
                eprintln!("bench: cannot run {}: {e}", self.python.display());
                return None;
            }
        }
        let img = read_image(&self.out).ok();
        let _ = std::fs::remove_file(&self.out);
        Some((wall, img?))
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
