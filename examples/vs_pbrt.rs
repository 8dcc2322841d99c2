//! pbrs beside pbrt-v3 on the same scene files: the whole-process wall time
//! of each, run alternately, and their ratio.
//!
//! cargo run --release --example vs_pbrt -- --pbrt PBRT_BINARY [--threads N]
//!     [--runs N] SCENE ...
//!
//! Each scene renders as it is (its resolution, samples and integrator) with
//! `--nthreads N --quiet --outfile TMP.exr` (default 2 threads), which both
//! renderers take, from the scene's folder; pbrs and pbrt-v3 alternate,
//! pbrs first, `--runs` times (default 5). pbrs runs as a child process of
//! this program calling pbrs's command line (`pbrs::cli::run`), so its time
//! includes process start as pbrt-v3's does and its code is always this
//! build's. Per scene: the minimum time of each, the ratio of the minima, and
//! the median and range of the pairs' ratios (on a shared machine the range
//! says how far one ratio can be trusted). Speed is compared in ratios of runs
//! made side by side: a machine's speed drifts between days, for both.

use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// The child mode: the rest of the arguments are pbrs's command line.
const AS_PBRS: &str = "--as-pbrs";

struct Opts {
    pbrt: PathBuf,
    threads: u32,
    runs: u32,
    scenes: Vec<PathBuf>,
}

fn parse() -> Result<Opts, String> {
    let mut o = Opts {
        pbrt: PathBuf::new(),
        threads: 2,
        runs: 5,
        scenes: Vec::new(),
    };
    let mut args = std::env::args().skip(1);
    let number = |v: Option<String>, what: &str| -> Result<u32, String> {
        v.and_then(|s| s.parse().ok())
            .filter(|&n| n > 0)
            .ok_or(format!("{what} needs a positive whole number"))
    };
    while let Some(a) = args.next() {
        match a.as_str() {
            "--pbrt" => o.pbrt = PathBuf::from(args.next().ok_or("--pbrt needs pbrt-v3's binary")?),
            "--threads" => o.threads = number(args.next(), "--threads")?,
            "--runs" => o.runs = number(args.next(), "--runs")?,
            s if s.starts_with("--") => return Err(format!("unknown option {s}")),
            _ => o.scenes.push(PathBuf::from(a)),
        }
    }
    if o.pbrt.as_os_str().is_empty() {
        return Err("--pbrt PBRT_BINARY is required".into());
    }
    // Runs start in each scene's folder: a path to the binary is made
    // absolute first (a bare name is looked up in PATH).
    if o.pbrt.components().count() > 1 {
        o.pbrt =
            std::fs::canonicalize(&o.pbrt).map_err(|e| format!("{}: {e}", o.pbrt.display()))?;
    }
    if o.scenes.is_empty() {
        return Err("no scene given".into());
    }
    Ok(o)
}

fn main() {
    let mut argv: Vec<OsString> = std::env::args_os().collect();
    if argv.get(1).is_some_and(|a| a == AS_PBRS) {
        // pbrs's command line: its program name, then the rest.
        argv.drain(..2);
        argv.insert(0, OsString::from("pbrs"));
        std::process::exit(pbrs::cli::run(argv));
    }
    let o = match parse() {
        Ok(o) => o,
        Err(e) => {
            eprintln!("vs_pbrt: {e}\nusage: vs_pbrt --pbrt PBRT_BINARY [--threads N] [--runs N] SCENE ...");
            std::process::exit(2);
        }
    };
    let exe = std::env::current_exe().expect("current exe");
    println!(
        "{} threads, {} alternating runs each, whole-process wall time",
        o.threads, o.runs
    );
    println!();
    println!("| scene | pbrs s (min) | pbrt-v3 s (min) | ratio of minima | median pair ratio | pair ratios |");
    println!("|---|---|---|---|---|---|");
    for scene in &o.scenes {
        let mut pairs = Vec::new();
        let mut failed = None;
        for _ in 0..o.runs {
            let mut pbrs = Command::new(&exe);
            pbrs.arg(AS_PBRS);
            let p = run(pbrs, scene, &o, "pbrs");
            let v = run(Command::new(&o.pbrt), scene, &o, "pbrt-v3");
            match (p, v) {
                (Ok(p), Ok(v)) => pairs.push((p, v)),
                (Err(e), _) | (_, Err(e)) => {
                    failed = Some(e);
                    break;
                }
            }
        }
        let name = scene.display();
        if let Some(e) = failed {
            println!("| {name} | failed: {e} | | | | |");
            continue;
        }
        let min = |f: fn(&(f64, f64)) -> f64| pairs.iter().map(f).fold(f64::INFINITY, f64::min);
        let (p, v) = (min(|x| x.0), min(|x| x.1));
        let mut ratios: Vec<f64> = pairs.iter().map(|(p, v)| p / v).collect();
        ratios.sort_by(f64::total_cmp);
        let n = ratios.len();
        let median = if n % 2 == 1 {
            ratios[n / 2]
        } else {
            (ratios[n / 2 - 1] + ratios[n / 2]) / 2.0
        };
        println!(
            "| {name} | {p:.3} | {v:.3} | {:.3} | {median:.3} | {:.3}–{:.3} |",
            p / v,
            ratios[0],
            ratios[n - 1]
        );
    }
}

/// One render of `scene` by `cmd` (pbrs or pbrt-v3) from the scene's
/// folder: its wall time.
fn run(mut cmd: Command, scene: &Path, o: &Opts, who: &str) -> Result<f64, String> {
    let dir = scene
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let file = scene
        .file_name()
        .ok_or(format!("{} is not a file", scene.display()))?;
    let out = std::env::temp_dir().join(format!("vs-pbrt-{who}-{}.exr", std::process::id()));
    cmd.current_dir(dir)
        .args(["--nthreads", &o.threads.to_string(), "--quiet", "--outfile"])
        .arg(&out)
        .arg(file);
    let start = Instant::now();
    let output = cmd.output().map_err(|e| format!("{who}: {e}"))?;
    let wall = start.elapsed().as_secs_f64();
    let _ = std::fs::remove_file(&out);
    if !output.status.success() {
        let err = String::from_utf8_lossy(&output.stderr);
        let last = err.lines().last().unwrap_or("").to_string();
        return Err(format!("{who} exited with {}: {last}", output.status));
    }
    Ok(wall)
}
