//! The batched renderer (several samples in flight per thread, `path` and
//! `volpath` advancing all of a batch's paths one vertex at a time) gives the image of
//! the scalar loop bit for bit, with the same rays traced: each scene is
//! rendered both ways (`RenderOptions::scalar`) and compared pixel by pixel.
//! The scenes cover every integrator, specular and subsurface paths, media,
//! motion blur, ray differentials (textures), every sampler (the stratified
//! one renders with the one-sample loop either way: it computes a whole
//! pixel's samples when it starts one, which a copy per lane would repeat),
//! sample counts that do not fill the last batch of a pixel, and a crop
//! window.

mod common;

use pbrs::integrators::AmbientOcclusionSettings;
use pbrs::scene::{IntegratorSettings, SamplerKind, SceneDescription};

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

/// directlighting's batched camera vertices (Lambertian ones four at a
/// time, one light per pass): seven triangle lights (two packs, the
/// second part-full; one two-sided, one black), camera hits on glass, a
/// mirror, plastic, textured and bump-mapped matte (differentials), a
/// `Material "none"` sheet, cylinder instances (one moving) and an alpha
/// cut-out, with `maxdepth` 1 (no specular children, so no samples
/// skipped) and 5.
#[test]
fn directlighting_lanes_every_kind_of_camera_vertex() {
    for max_depth in [1, 5] {
        let integrator = format!(
            "Integrator \"directlighting\" \"string strategy\" \"all\" \"integer maxdepth\" [{max_depth}]"
        );
        let desc = common::load_text(&lanes_scene(&integrator)).scene;
        both_ways(desc, 24, 13, &format!("lanes, maxdepth {max_depth}"));
    }
}

/// The scene of `directlighting_lanes_every_kind_of_camera_vertex` with
/// the statement `integrator`.
fn lanes_scene(integrator: &str) -> String {
    format!(
        r#"
LookAt 0 1 4  0 0.8 0  0 1 0
Camera "perspective" "float fov" [45]
Film "image" "integer xresolution" [24] "integer yresolution" [24]
Sampler "halton" "integer pixelsamples" [16]
{integrator}
WorldBegin
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [8 6 4]
  Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
    "point P" [-0.5 1.9 -0.5  0.5 1.9 -0.5  0.5 1.9 0.5  -0.5 1.9 0.5]
AttributeEnd
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [2 3 5] "bool twosided" "true"
  Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
    "point P" [-1.5 0.2 -1  -1.5 0.2 0  -1.5 1.2 0  -1.5 1.2 -1]
AttributeEnd
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [0 0 0]
  Shape "trianglemesh" "integer indices" [0 1 2]
    "point P" [1.5 0.2 -1  1.5 0.2 0  1.5 1.2 0]
AttributeEnd
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [4 4 4]
  Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
    "point P" [1.4 0.2 0.5  1.4 0.2 1  1.4 1.2 1  1.4 1.2 0.5]
AttributeEnd
Material "matte" "rgb Kd" [0.6 0.6 0.6]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
  "point P" [-2 0 -2  2 0 -2  2 0 2  -2 0 2]
Texture "checks" "spectrum" "checkerboard" "float uscale" [8] "float vscale" [8]
  "rgb tex1" [0.8 0.2 0.2] "rgb tex2" [0.2 0.8 0.2]
AttributeBegin
  Material "matte" "texture Kd" "checks"
  Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
    "point P" [-2 0 -2  2 0 -2  2 2 -2  -2 2 -2] "float uv" [0 0 1 0 1 1 0 1]
AttributeEnd
Texture "bumps" "float" "wrinkled" "float scale" [4]
AttributeBegin
  Material "matte" "rgb Kd" [0.3 0.5 0.7] "texture bumpmap" "bumps"
  Translate -0.9 0.35 0
  Shape "sphere" "float radius" [0.35]
AttributeEnd
AttributeBegin
  Material "glass"
  Translate 0 0.35 0.3
  Shape "sphere" "float radius" [0.35]
AttributeEnd
AttributeBegin
  Material "mirror"
  Translate 0.9 0.35 0
  Shape "sphere" "float radius" [0.35]
AttributeEnd
AttributeBegin
  Material "plastic" "float roughness" [0.1]
  Translate 0.4 1.2 -0.6
  Shape "sphere" "float radius" [0.25]
AttributeEnd
AttributeBegin
  Material "none"
  Shape "trianglemesh" "integer indices" [0 1 2]
    "point P" [-1 0.1 1.5  0 0.1 1.5  -1 1.1 1.5]
AttributeEnd
ObjectBegin "post"
  Shape "cylinder" "float radius" [0.08] "float zmin" [0] "float zmax" [0.9]
ObjectEnd
AttributeBegin
  Translate 1.2 0 -0.9
  Rotate -90 1 0 0
  ObjectInstance "post"
AttributeEnd
AttributeBegin
  ActiveTransform StartTime
  Translate -1.3 0 -0.9
  ActiveTransform EndTime
  Translate -1.1 0 -0.8
  ActiveTransform All
  Rotate -90 1 0 0
  ObjectInstance "post"
AttributeEnd
Texture "cut" "float" "checkerboard" "float uscale" [3] "float vscale" [3]
  "float tex1" [1] "float tex2" [0]
AttributeBegin
  Material "matte" "rgb Kd" [0.7 0.7 0.2]
  Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
    "point P" [0.3 0.05 0.6  1.1 0.05 0.6  1.1 0.85 0.6  0.3 0.85 0.6]
    "float uv" [0 0 1 0 1 1 0 1] "texture alpha" "cut"
AttributeEnd
WorldEnd
"#
    )
}

/// ambientocclusion: the batch's camera rays as packets, each hemisphere's
/// shadow rays in groups traced as packets, against the scalar loop's
/// rays one by one: in the Cornell box (triangles only) and in the lanes
/// scene, whose spheres, cylinder instances (one moving), alpha cut-out
/// and `Material "none"` sheet the packet asks about ray by ray; sample
/// counts that leave a group part-full (1, 5, 16, 37).
#[test]
fn ambientocclusion_packets() {
    for n in [1, 5, 16, 37] {
        let mut desc = common::load("scenes/cornell-path.pbrt");
        desc.integrator = IntegratorSettings::AmbientOcclusion(AmbientOcclusionSettings {
            cos_sample: n != 5,
            n_samples: n,
        });
        both_ways(
            desc,
            24,
            5,
            &format!("ambientocclusion cornell, nsamples {n}"),
        );
    }
    let text = lanes_scene(
        "Integrator \"ambientocclusion\" \"integer nsamples\" [12] \"bool cossample\" \"false\"",
    );
    both_ways(
        common::load_text(&text).scene,
        24,
        7,
        "ambientocclusion, spheres",
    );
}

/// volpath's batch: homogeneous and heterogeneous media, the camera in a
/// medium, material-less boundaries (nested media, shadow rays through
/// them), subsurface exits in a medium, and a scene without media (glass).
#[test]
fn volpath_subsurface_and_media() {
    scenes(&[
        ("scenes/fog/fog.pbrt", 24, 5),
        ("scenes/fog/fog-spot.pbrt", 24, 5),
        ("scenes/grid/grid.pbrt", 24, 4),
        ("scenes/subsurface/subsurface.pbrt", 24, 4),
        ("scenes/subsurface/subsurface-fog.pbrt", 24, 3),
    ]);
    let mut desc = common::load("scenes/cornell-glass.pbrt");
    let IntegratorSettings::Path(settings) = desc.integrator else {
        panic!("cornell-glass renders with path: {:?}", desc.integrator)
    };
    desc.integrator = IntegratorSettings::VolPath(settings);
    both_ways(desc, 24, 9, "cornell-glass with volpath");
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
