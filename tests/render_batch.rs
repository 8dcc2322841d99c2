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

use pbrs::scene::{SamplerKind, SceneDescription};

fn both_ways(mut desc: SceneDescription, res: u32, spp: u32, what: &str) {
    desc.film.xresolution = res;
    desc.film.yresolution = res;
    desc.sampler.pixel_samples = spp;
    let (fast, _) = common::assert_fast_is_scalar(&desc, what);
    let batched = |n: &String| n.starts_with("batched:");
    assert_eq!(
        fast.notes.iter().any(batched),
        !matches!(desc.sampler.kind, SamplerKind::Stratified { .. }),
        "{what}: {:?}",
        fast.notes
    );
}

/// Scenes of the repository at `res`×`res` and `spp` samples per pixel
/// (counts that leave a pixel's last batch part-full on purpose).
fn scenes(list: &[(&str, u32, u32)]) {
    for &(path, res, spp) in list {
        both_ways(common::load(path), res, spp, path);
    }
}

#[test]
fn path_cornell_and_glass() {
    scenes(&[
        ("scenes/cornell-path.pbrt", 32, 19),
        ("scenes/cornell-glass.pbrt", 32, 16),
    ]);
}

#[test]
fn directlighting_and_whitted() {
    scenes(&[
        ("scenes/cornell-direct.pbrt", 32, 7),
        ("scenes/materials-direct.pbrt", 32, 4),
        ("scenes/materials-whitted.pbrt", 32, 4),
    ]);
}

#[test]
fn volpath_subsurface_and_media() {
    scenes(&[
        ("scenes/fog/fog.pbrt", 24, 5),
        ("scenes/subsurface/subsurface.pbrt", 24, 4),
    ]);
}

#[test]
fn motion_blur_and_textures() {
    scenes(&[
        ("scenes/motion/motion-blur.pbrt", 24, 6),
        ("scenes/motion/motion-camera.pbrt", 24, 6),
        ("scenes/textures-env/textures-env.pbrt", 24, 4),
    ]);
}

#[test]
fn every_sampler_and_a_crop_window() {
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
