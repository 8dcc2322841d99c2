//! Many lights: n small emissive triangles (facing down) over a floor, 64×64
//! pixels, 4 spp, the path integrator (maxdepth 3), with each light sample
//! strategy: set-up time (scene build and light distribution; `spatial`
//! builds its voxels lazily, so their cost shows in the render time), render
//! time, and relative MSE against a converged reference at equal spp. The
//! reference is a pbrs render of the same scene with strategy "bvh" at 256
//! spp (every strategy has the same expected image; bvh converges fastest).
//!
//! cargo run --release --example many_lights [-- N...]   (default 10 1000 100000)
//!
//! Strategies whose render would exceed a time limit at large n are still
//! run: the table says what they cost.

use pbrs::image::compare::compare;
use pbrs::image::Image;
use pbrs::loader::load_scene_str;
use pbrs::render::driver::{render, RenderOptions};
use std::fmt::Write;
use std::path::Path;
use std::time::Instant;

fn scene(n: usize, spp: u32, strategy: &str) -> String {
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut rnd = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    // Total emitted power constant in n: each triangle's area is 1/n of 1.
    let s = (2.0 / n as f32).sqrt().min(0.5);
    let mut p = String::with_capacity(n * 60);
    let mut idx = String::with_capacity(n * 24);
    for i in 0..n {
        let x = rnd() * 16.0 - 8.0;
        let z = rnd() * 16.0 - 8.0;
        let y = 0.5 + rnd() * 2.5;
        let _ = write!(p, "{x} {y} {z} {} {y} {z} {x} {y} {} ", x + s, z + s);
        let b = 3 * i;
        let _ = write!(idx, "{b} {} {} ", b + 1, b + 2);
    }
    format!(
        r#"LookAt 0 6 8 0 0 0 0 1 0
Camera "perspective" "float fov" 50
Film "image" "integer xresolution" 64 "integer yresolution" 64 "string filename" "x.exr"
Sampler "halton" "integer pixelsamples" {spp}
Integrator "path" "string lightsamplestrategy" "{strategy}" "integer maxdepth" 3
WorldBegin
Material "matte" "rgb Kd" [0.5 0.5 0.5]
Shape "trianglemesh" "point P" [-10 0 -10 10 0 -10 10 0 10 -10 0 10] "integer indices" [0 1 2 0 2 3]
AttributeBegin
AreaLightSource "diffuse" "rgb L" [40 30 20]
Shape "trianglemesh" "point P" [{p}] "integer indices" [{idx}]
AttributeEnd
WorldEnd
"#
    )
}

fn run(n: usize, spp: u32, strategy: &str) -> (f64, f64, f64, Image) {
    let t = Instant::now();
    let text = scene(n, spp, strategy);
    let loaded = load_scene_str(&text, Path::new("many.pbrt")).expect("scene");
    let parse = t.elapsed().as_secs_f64();
    let (img, stats) =
        render(&loaded.scene, &RenderOptions::default(), &|_, _| {}).expect("render");
    (
        parse,
        stats.build_time.as_secs_f64(),
        stats.render_time.as_secs_f64(),
        img,
    )
}

fn main() {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let ns = if args.is_empty() {
        vec![10, 1000, 100_000]
    } else {
        args
    };
    println!(
        "{:>9} {:>8} {:>8} {:>9} {:>9} {:>10}",
        "lights", "strategy", "parse s", "set-up s", "render s", "rel. MSE"
    );
    for &n in &ns {
        let (_, _, _, reference) = run(n, 256, "bvh");
        for s in ["uniform", "power", "spatial", "bvh"] {
            let (parse, setup, render, img) = run(n, 4, s);
            let c = compare(&img, &reference);
            println!(
                "{n:>9} {s:>8} {parse:>8.2} {setup:>9.2} {render:>9.2} {:>10.4}",
                c.relative_mse
            );
        }
    }
}
