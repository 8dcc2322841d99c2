//! How sensitive `pbrs test` is, and how often it cries wolf: the Cornell box
//! (`scenes/cornell-path.pbrt`'s scene, `path` maxdepth 8, Halton) at
//! 128×128, 64 spp, goldens written by `pbrs test --update` (seeds 0 and 1).
//!
//! ```sh
//! cargo run --release --example golden_detection -- [--renders 100] [--seeds 5] [--res 128] [--spp 64]
//! ```
//!
//! 1. False alarms: the unchanged scene re-rendered with `--renders` fresh
//!    seeds (1000, 1001, …); the fraction that fails, and the largest of
//!    each figure (× noise, σ) seen.
//! 2. Detection: the light's emission scaled by 1 + d and the red wall's
//!    reflectance by 1 − d for a list of d, each rendered with `--seeds`
//!    fresh seeds; the fraction flagged. The smallest d flagged by every
//!    seed is the detection threshold the README reports.
//!
//! Everything goes through `pbrs::cli::golden::check`, the code of `pbrs test`.

use pbrs::cli::golden::{check, Outcome, TestArgs};
use std::path::{Path, PathBuf};

fn scene(root: &Path, light: f64, red: f64, res: u32, spp: u32) -> String {
    let common = std::fs::read_to_string(root.join("scenes/cornell-common.inc")).unwrap();
    let cube = std::fs::read_to_string(root.join("scenes/unitcube.inc")).unwrap();
    let l = format!("[{} {} {}]", 17.0 * light, 12.0 * light, 4.0 * light);
    let r = format!("[{} {} {}]", 0.63 * red, 0.065 * red, 0.05 * red);
    let common = common
        .replace("[17 12 4]", &l)
        .replace("[0.63 0.065 0.05]", &r);
    format!(
        "Scale -1 1 1\nLookAt 0 1 6.8  0 1 0  0 1 0\nCamera \"perspective\" \"float fov\" [19.5]\n\
         Film \"image\" \"integer xresolution\" [{res}] \"integer yresolution\" [{res}] \"string filename\" \"out.exr\"\n\
         Sampler \"halton\" \"integer pixelsamples\" [{spp}]\nIntegrator \"path\" \"integer maxdepth\" [8]\n\
         WorldBegin\n{common}\nAttributeBegin\nMaterial \"matte\" \"rgb Kd\" [0.725 0.71 0.68]\n\
         AttributeBegin\nTranslate 0.33 0.3 0.37\nRotate -17 0 1 0\nScale 0.6 0.6 0.6\n{cube}\nAttributeEnd\n\
         AttributeBegin\nTranslate -0.34 0.6 -0.29\nRotate 17 0 1 0\nScale 0.6 1.2 0.6\n{cube}\nAttributeEnd\n\
         AttributeEnd\nWorldEnd\n"
    )
}

fn args(dir: &Path, seed: u64, update: bool) -> TestArgs {
    TestArgs {
        dir: dir.to_path_buf(),
        update,
        seed: Some(seed),
        threads: None,
        junit: None,
        report: None,
        quiet: true,
    }
}

/// Whether the scene passed, and its figures.
fn run(dir: &Path, seed: u64) -> (bool, [f64; 3]) {
    let r = check(&args(dir, seed, false)).expect("pbrs test");
    let r = &r[0];
    match &r.outcome {
        Outcome::Passed(_) | Outcome::Failed(_) => {
            (matches!(r.outcome, Outcome::Passed(_)), r.ratios().unwrap())
        }
        o => panic!("{o:?}"),
    }
}

fn main() {
    let mut renders = 100u64;
    let mut seeds = 5u64;
    let (mut res, mut spp) = (128u32, 64u32);
    let argv: Vec<String> = std::env::args().skip(1).collect();
    let mut it = argv.iter();
    while let Some(a) = it.next() {
        let mut v = || it.next().and_then(|s| s.parse::<u64>().ok()).expect(a);
        match a.as_str() {
            "--renders" => renders = v(),
            "--seeds" => seeds = v(),
            "--res" => res = v() as u32,
            "--spp" => spp = v() as u32,
            _ => panic!("unknown argument {a}"),
        }
    }
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let dir = std::env::temp_dir().join(format!("pbrs-golden-detection-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("cornell.pbrt");
    std::fs::write(&file, scene(&root, 1.0, 1.0, res, spp)).unwrap();
    let t0 = std::time::Instant::now();
    check(&args(&dir, 0, true)).expect("update");
    println!(
        "golden: {res}×{res}, {spp} spp, {:.1} s",
        t0.elapsed().as_secs_f64()
    );

    let t0 = std::time::Instant::now();
    let (mut fails, mut worst) = (0, [0.0f64; 3]);
    for k in 0..renders {
        let (ok, r) = run(&dir, 1000 + k);
        if !ok {
            fails += 1;
            println!("false alarm: seed {} {r:?}", 1000 + k);
        }
        for i in 0..3 {
            worst[i] = worst[i].max(r[i]);
        }
    }
    println!(
        "false alarms: {fails} of {renders} fresh-seed re-renders ({:.1} s); largest rel. MSE {:.2}× noise (tolerance 2), block error {:.2}× (2), mean {:.2} σ (6)",
        t0.elapsed().as_secs_f64(),
        worst[0],
        worst[1],
        worst[2]
    );

    let steps = [
        0.001, 0.0015, 0.002, 0.0025, 0.005, 0.0075, 0.01, 0.0125, 0.015, 0.02, 0.03, 0.05,
    ];
    println!("| change d | light × (1 + d): flagged | red wall Kd × (1 − d): flagged |");
    println!("|---|---|---|");
    let mut first = [None, None];
    for d in steps {
        let mut cells = Vec::new();
        for (which, (light, red)) in [(1.0 + d, 1.0), (1.0, 1.0 - d)].into_iter().enumerate() {
            std::fs::write(&file, scene(&root, light, red, res, spp)).unwrap();
            let mut flagged = 0;
            let mut mean_sigma = 0.0;
            for k in 0..seeds {
                let (ok, r) = run(&dir, 2000 + k);
                flagged += u64::from(!ok);
                mean_sigma += r[2] / seeds as f64;
            }
            if flagged == seeds && first[which].is_none() {
                first[which] = Some(d);
            }
            cells.push(format!("{flagged}/{seeds} (mean {mean_sigma:.1} σ)"));
        }
        println!("| {:.2}% | {} | {} |", 100.0 * d, cells[0], cells[1]);
    }
    let pct = |x: Option<f64>| {
        x.map_or("none of those tried".to_string(), |d| {
            format!("{:.2}%", 100.0 * d)
        })
    };
    println!(
        "smallest change flagged by every seed: light {}, red wall {}",
        pct(first[0]),
        pct(first[1])
    );
    let _ = std::fs::remove_dir_all(&dir);
}
