//! The batched renderer (several samples in flight per thread, `path`
//! advancing all of a batch's paths one vertex at a time) gives the image of
//! the scalar loop bit for bit, with the same rays traced: each scene is
//! rendered both ways (`RenderOptions::scalar`) and compared pixel by pixel.
//! The scenes cover every integrator, specular and subsurface paths, media,
//! motion blur, ray differentials (textures), every sampler (the stratified
//! one renders with the one-sample loop either way: it computes a whole
//! pixel's samples when it starts one, which a copy per lane would repeat),
//! sample counts that do not fill the last batch of a pixel, and a crop
//! window.

mod common;

use pbrs::render::driver::{render, RenderOptions};
use pbrs::scene::SceneDescription;

fn both_ways(mut desc: SceneDescription, res: u32, spp: u32, what: &str) {
    desc.film.xresolution = res;
    desc.film.yresolution = res;
    desc.sampler.pixel_samples = spp;
    let run = |scalar: bool| {
        render(
            &desc,
            &RenderOptions {
                threads: Some(2),
                scalar,
                ..Default::default()
            },
            &|_, _| {},
        )
        .expect("render failed")
    };
    let (batched, b_stats) = run(false);
    let (scalar, s_stats) = run(true);
    assert_eq!(batched.width, scalar.width);
    let differ = batched
        .data
        .iter()
        .zip(&scalar.data)
        .filter(|(a, b)| a.to_bits() != b.to_bits())
        .count();
    assert_eq!(
        differ, 0,
        "{what}: {differ} values differ from the scalar loop"
    );
    assert_eq!(b_stats.rays.closest, s_stats.rays.closest, "{what}");
    assert_eq!(b_stats.rays.shadow, s_stats.rays.shadow, "{what}");
    assert_eq!(b_stats.samples, s_stats.samples, "{what}");
    let sum: f64 = batched.data.iter().map(|&v| v as f64).sum();
    assert!(sum > 0.0, "{what}: a black image proves nothing");
}

#[test]
fn path_cornell_and_glass() {
    both_ways(
        common::load("scenes/cornell-path.pbrt"),
        32,
        19,
        "cornell-path",
    );
    both_ways(
        common::load("scenes/cornell-glass.pbrt"),
        32,
        16,
        "cornell-glass",
    );
}

#[test]
fn directlighting_and_whitted() {
    both_ways(
        common::load("scenes/cornell-direct.pbrt"),
        32,
        7,
        "cornell-direct",
    );
    both_ways(
        common::load("scenes/materials-direct.pbrt"),
        32,
        4,
        "materials-direct",
    );
    both_ways(
        common::load("scenes/materials-whitted.pbrt"),
        32,
        4,
        "materials-whitted",
    );
}

#[test]
fn volpath_subsurface_and_media() {
    both_ways(common::load("scenes/fog/fog.pbrt"), 24, 5, "fog");
    both_ways(
        common::load("scenes/subsurface/subsurface.pbrt"),
        24,
        4,
        "subsurface",
    );
}

#[test]
fn motion_blur_and_textures() {
    both_ways(
        common::load("scenes/motion/motion-blur.pbrt"),
        24,
        6,
        "motion-blur",
    );
    both_ways(
        common::load("scenes/motion/motion-camera.pbrt"),
        24,
        6,
        "motion-camera",
    );
    both_ways(
        common::load("scenes/textures-env/textures-env.pbrt"),
        24,
        4,
        "textures-env",
    );
}

#[test]
fn every_sampler_and_a_crop_window() {
    use pbrs::scene::SamplerKind;
    for (kind, name) in [
        (SamplerKind::Random, "random"),
        (
            SamplerKind::Stratified {
                jitter: true,
                xsamples: 2,
                ysamples: 3,
            },
            "stratified",
        ),
    ] {
        let mut desc = common::load("scenes/cornell-path.pbrt");
        desc.sampler.kind = kind;
        both_ways(desc, 24, 6, name);
    }
    let mut desc = common::load("scenes/cornell-path.pbrt");
    desc.film.cropwindow = [0.2, 0.7, 0.1, 0.55];
    both_ways(desc, 40, 9, "crop window");
}
