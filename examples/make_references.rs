//! Regenerates the pbrs-made converged references named in
//! `scenes/references/golden.txt` (kind `pbrs`): 128×128 at 4096 spp.
//! Tests never rewrite references; this is the one deliberate way.
//!
//! cargo run --release --example make_references [-- NAME ...]

#[allow(dead_code)]
#[path = "../tests/common/golden.rs"]
mod golden;

use golden::{manifest, Check, PBRS_REFERENCE_RES, PBRS_REFERENCE_SPP};
use pbrs::image::io::write_image;
use pbrs::loader::load_scene;
use pbrs::render::driver::{render, RenderOptions};
use std::path::Path;

fn main() {
    let only: Vec<String> = std::env::args().skip(1).collect();
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    for e in manifest(repo) {
        let Check::Pbrs(name) = &e.check else {
            continue;
        };
        if !only.is_empty() && !only.contains(name) {
            continue;
        }
        let mut desc = match load_scene(&repo.join(&e.scene)) {
            Ok(l) => l.scene,
            Err(f) => {
                eprintln!("{}: {} errors", e.scene, f.errors.len());
                std::process::exit(1);
            }
        };
        desc.film.xresolution = PBRS_REFERENCE_RES;
        desc.film.yresolution = PBRS_REFERENCE_RES;
        desc.sampler.pixel_samples = PBRS_REFERENCE_SPP;
        // A seed no test uses, so tests compare against independent samples.
        let (img, stats) = render(
            &desc,
            &RenderOptions {
                threads: None,
                seed: 12345,
                ..Default::default()
            },
            &|_, _| {},
        )
        .unwrap();
        let out = repo.join(format!("scenes/references/{name}-128-pbrs.pfm"));
        write_image(&out, &img).unwrap();
        println!(
            "{}: {} spp in {:.1} s -> {}",
            e.scene,
            PBRS_REFERENCE_SPP,
            stats.render_time.as_secs_f64(),
            out.display()
        );
    }
}
