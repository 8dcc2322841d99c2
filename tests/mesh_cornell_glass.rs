//! The seed's glass-dragon variant (`scenes/cornell-dragon-glass.pbrt`). It has
//! no pbrt-v3 reference: `scenes/references/cornell-dragon-glass-128-pbrs.pfm`
//! is a pbrs render at 128×128 with 4096 spp and sampler seed 7 (independent
//! of the seed-0 render checked here). Regenerate it with
//! `cargo test --test mesh_cornell_glass -- --ignored`.

mod common;
use common::*;
use pbrs::render::driver::{render, RenderOptions};
use pbrs::render::film::compare::block_error;
use pbrs::render::film::io::{read_image, write_image};

const SCENE: &str = "scenes/cornell-dragon-glass.pbrt";
const REFERENCE: &str = "scenes/references/cornell-dragon-glass-128-pbrs.pfm";

#[test]
fn cornell_dragon_glass_agrees_with_pbrs_reference() {
    let (img, stats) = render_at(load(SCENE), 128, 64, None);
    assert_eq!(stats.dropped_samples(), 0, "NaN/Inf/negative samples");
    let pbrs_reference = read_image(&repo().join(REFERENCE)).expect("reference");
    // No pbrt-v3 figures exist for this scene, so the bound borrows the matte
    // dragon's: pbrt-v3's own 64-spp block error on cornell-dragon, times 2 as
    // for the pbrt-v3 comparisons, times 2 again for the glass caustics'
    // extra noise (this render: about 0.016 against a bound of about 0.035).
    let matte = block_error(
        &pbrt_64("dezeming-cornell-dragon"),
        &reference("dezeming-cornell-dragon"),
    );
    let b = Bounds {
        max_relative_mse: f64::INFINITY,
        max_block_error: 4.0 * matte,
        max_mean_difference: 0.01,
    };
    assert_matches("cornell-dragon-glass", &img, &pbrs_reference, b);
}

#[test]
#[ignore = "regenerates the pbrs reference (minutes)"]
fn regenerate_cornell_dragon_glass_reference() {
    let mut desc = load(SCENE);
    desc.film.xresolution = 128;
    desc.film.yresolution = 128;
    desc.sampler.pixel_samples = 4096;
    let (img, _) = render(
        &desc,
        &RenderOptions {
            threads: None,
            seed: 7,
        },
        &|_, _| {},
    )
    .expect("render");
    write_image(&repo().join(REFERENCE), &img).expect("write");
}
