//! Shape benchmark: BVH build and trace speed for a scene of 10,000 curves,
//! and for a motion-blurred scene against its static version.
//!
//! cargo run --release --example shapes_bench [-- curves|motion] [--write DIR]
//!
//! Each case generates its scene as pbrt-v3 text (`--write DIR` saves the
//! files, so that pbrt-v3 can render the same scenes), loads it, builds the
//! render scene and renders it on all cores, and prints the load time, the
//! BVH build time, the render time and the ray throughput. The motion case
//! renders the same 400 shapes twice: still, then each moving over the
//! shutter (`ActiveTransform EndTime`), and prints the ratios. Timings on a
//! shared machine drift: compare ratios within one run.

use pbrs::loader::load_scene_str;
use pbrs::render::driver::{render, RenderOptions, RenderStats};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// A small deterministic generator (the scenes must be the same every run).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Camera, film and lights shared by both scenes: a floor under a square
/// area light (facing down), seen from the front and above.
fn header(res: u32, spp: u32) -> String {
    format!(
        r#"LookAt 0 0.9 2.4  0 0.25 0  0 1 0
Camera "perspective" "float fov" [35]
Film "image" "integer xresolution" [{res}] "integer yresolution" [{res}]
Sampler "halton" "integer pixelsamples" [{spp}]
Integrator "path" "integer maxdepth" [5]
WorldBegin
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [8 8 8]
  Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
    "point P" [-0.5 2 -0.5  0.5 2 -0.5  0.5 2 0.5  -0.5 2 0.5]
AttributeEnd
Material "matte" "rgb Kd" [0.6 0.6 0.6]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
  "point P" [-3 0 -3  3 0 -3  3 0 3  -3 0 3]
"#
    )
}

/// 10,000 flat curves (pbrt-v3's default type, `splitdepth` 3) rising from
/// the floor like a patch of hair, each a cubic Bézier bent by a random
/// amount, 4 mm wide at the root and 1 mm at the tip.
fn curves_scene(n: usize) -> String {
    let mut s = header(256, 16);
    s.push_str("Material \"matte\" \"rgb Kd\" [0.5 0.3 0.1]\n");
    let mut r = Lcg(1);
    for _ in 0..n {
        let (x, z) = (r.next() * 1.6 - 0.8, r.next() * 1.2 - 0.6);
        let (bx, bz) = (r.next() * 0.3 - 0.15, r.next() * 0.3 - 0.15);
        let h = 0.3 + 0.3 * r.next();
        let p = [
            (x, 0.0, z),
            (x + bx * 0.3, h / 3.0, z + bz * 0.3),
            (x + bx * 0.8, 2.0 * h / 3.0, z + bz * 0.8),
            (x + bx, h, z + bz),
        ];
        s.push_str("Shape \"curve\" \"point P\" [");
        for (x, y, z) in p {
            s.push_str(&format!(" {x:.5} {y:.5} {z:.5}"));
        }
        s.push_str(" ] \"float width0\" [0.004] \"float width1\" [0.001]\n");
    }
    s.push_str("WorldEnd\n");
    s
}

/// 200 spheres and 200 unit boxes on a 20×20 grid; with `moving`, each
/// moves (spheres translate, boxes turn and translate) over the shutter.
fn motion_scene(moving: bool) -> String {
    let mut s = header(256, 16).replace(
        "Camera \"perspective\"",
        "Camera \"perspective\" \"float shutteropen\" [0] \"float shutterclose\" [1]",
    );
    let mut r = Lcg(2);
    for j in 0..20 {
        for i in 0..20 {
            let (x, z) = (-0.95 + 0.1 * i as f64, -0.95 + 0.1 * j as f64);
            let (dx, dz) = (r.next() * 0.1 - 0.05, r.next() * 0.1 - 0.05);
            s.push_str("AttributeBegin\n");
            s.push_str(&format!("  Translate {x} 0.03 {z}\n"));
            if moving {
                s.push_str("  ActiveTransform EndTime\n");
                s.push_str(&format!("  Translate {dx:.4} 0 {dz:.4}\n"));
                if (i + j) % 2 == 1 {
                    s.push_str("  Rotate 60 0 1 0\n");
                }
                s.push_str("  ActiveTransform All\n");
            }
            if (i + j) % 2 == 0 {
                s.push_str("  Shape \"sphere\" \"float radius\" [0.03]\n");
            } else {
                s.push_str(
                    "  Scale 0.05 0.05 0.05\n  Shape \"trianglemesh\" \
                     \"integer indices\" [0 2 1 0 3 2 4 5 6 4 6 7 0 1 5 0 5 4 3 7 6 3 6 2 0 4 7 0 7 3 1 2 6 1 6 5]\n    \
                     \"point P\" [-0.5 -0.5 -0.5 0.5 -0.5 -0.5 0.5 0.5 -0.5 -0.5 0.5 -0.5 \
                     -0.5 -0.5 0.5 0.5 -0.5 0.5 0.5 0.5 0.5 -0.5 0.5 0.5]\n",
                );
            }
            s.push_str("AttributeEnd\n");
        }
    }
    s.push_str("WorldEnd\n");
    s
}

struct Run {
    load: Duration,
    stats: RenderStats,
}

fn run(name: &str, text: &str, write: Option<&Path>) -> Run {
    let file = match write {
        Some(dir) => {
            let f = dir.join(format!("{name}.pbrt"));
            std::fs::write(&f, text).expect("write the scene");
            f
        }
        None => PathBuf::from(format!("{name}.pbrt")),
    };
    let t = Instant::now();
    let loaded = match load_scene_str(text, &file) {
        Ok(l) => l,
        Err(f) => panic!("{name}: {:?}", f.errors),
    };
    let load = t.elapsed();
    let (_, stats) = render(&loaded.scene, &RenderOptions::default(), &|_, _| {}).expect("render");
    println!(
        "{name:>14}: parse+load {:6.3} s, build {:6.3} s, render {:6.2} s, {:5.2} Mrays/s ({} rays)",
        load.as_secs_f64(),
        stats.build_time.as_secs_f64(),
        stats.render_time.as_secs_f64(),
        stats.mrays_per_sec(),
        stats.rays.total()
    );
    Run { load, stats }
}

fn main() {
    let mut args = std::env::args().skip(1);
    let mut case = None;
    let mut write = None;
    while let Some(a) = args.next() {
        match a.as_str() {
            "--write" => write = args.next().map(PathBuf::from),
            "curves" | "motion" => case = Some(a),
            other => {
                eprintln!("usage: shapes_bench [curves|motion] [--write DIR] (not {other})");
                std::process::exit(2);
            }
        }
    }
    let write = write.as_deref();
    if let Some(dir) = write {
        std::fs::create_dir_all(dir).expect("create the --write folder");
    }
    println!("256x256, 16 spp, path tracer (maxdepth 5), all cores");
    if case.as_deref() != Some("motion") {
        run("curves-10000", &curves_scene(10_000), write);
    }
    if case.as_deref() != Some("curves") {
        let still = run("motion-still", &motion_scene(false), write);
        let moving = run("motion-moving", &motion_scene(true), write);
        let ratio = |a: Duration, b: Duration| a.as_secs_f64() / b.as_secs_f64();
        println!(
            "moving / still: load {:.2}, build {:.2}, render {:.2}",
            ratio(moving.load, still.load),
            ratio(moving.stats.build_time, still.stats.build_time),
            ratio(moving.stats.render_time, still.stats.render_time)
        );
    }
}
