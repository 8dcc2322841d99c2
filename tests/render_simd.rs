//! The four-lane fast paths give the image of the scalar code bit for bit:
//! each scene is rendered both ways (`RenderOptions::scalar`) and compared
//! pixel by pixel, with the rays each traced.

mod common;

use pbrs::loader::load_scene_str;
use pbrs::scene::SceneDescription;

fn both_ways(desc: &SceneDescription, what: &str) {
    let (fast_stats, slow_stats) = common::assert_fast_is_scalar(desc, what);
    // The fast path was taken (and only when allowed).
    let packed =
        |s: &pbrs::render::driver::RenderStats| s.notes.iter().any(|n| n.contains("four-lane"));
    assert!(
        packed(&fast_stats),
        "{what}: no four-lane path: {:?}",
        fast_stats.notes
    );
    assert!(!packed(&slow_stats), "{what}");
}

#[test]
fn cornell_direct_is_the_scalar_image() {
    let mut desc = common::load("scenes/cornell-direct.pbrt");
    desc.film.xresolution = 64;
    desc.film.yresolution = 64;
    desc.sampler.pixel_samples = 8;
    both_ways(&desc, "cornell-direct");
}

/// Eleven triangle lights (three packs, the last one partly used): one
/// two-sided, one black, one facing away from most of the scene; matte,
/// Oren–Nayar (scalar path) and glass (vertices behind specular bounces),
/// with the sampler's arrays running out at depth 2 (maxdepth 3).
#[test]
fn many_triangle_lights_are_the_scalar_image() {
    let text = r#"
LookAt 0 1.5 -6  0 0.5 0  0 1 0
Camera "perspective" "float fov" [45]
Film "image" "integer xresolution" [48] "integer yresolution" [48] "string filename" "x.exr"
Sampler "halton" "integer pixelsamples" [8]
Integrator "directlighting" "string strategy" "all" "integer maxdepth" [3]
WorldBegin
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [4 3 2]
  Shape "trianglemesh" "integer indices" [0 1 2 0 2 3 4 5 6 4 6 7]
    "point P" [-1 3 -1  1 3 -1  1 3 1  -1 3 1   -3 2 0  -2 2 0  -2 3 0  -3 3 0]
AttributeEnd
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [1 2 5] "bool twosided" "true"
  Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
    "point P" [2 0.2 -1  3 0.2 -1  3 1.5 0  2 1.5 0]
AttributeEnd
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [0 0 0]
  Shape "trianglemesh" "integer indices" [0 1 2]
    "point P" [0 2 2  1 2 2  0 3 2]
AttributeEnd
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [6 6 6]
  Shape "trianglemesh" "integer indices" [0 2 1 0 3 2 4 5 6]
    "point P" [-1 0.01 -3  1 0.01 -3  1 0.01 -2  -1 0.01 -2   -2 0.5 1  -1 0.5 1  -1.5 1.2 1]
AttributeEnd
Material "matte" "rgb Kd" [0.7 0.6 0.5]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
  "point P" [-5 0 -5  5 0 -5  5 0 5  -5 0 5]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
  "point P" [-5 0 4  5 0 4  5 5 4  -5 5 4]
AttributeBegin
  Material "matte" "rgb Kd" [0.3 0.8 0.3] "float sigma" [20]
  Translate -1.2 0.6 0
  Shape "sphere" "float radius" [0.6]
AttributeEnd
AttributeBegin
  Material "glass"
  Translate 1.0 0.6 -0.5
  Shape "sphere" "float radius" [0.6]
AttributeEnd
WorldEnd
"#;
    let path = common::repo().join("scenes/inline-many-lights.pbrt");
    let desc = match load_scene_str(text, &path) {
        Ok(l) => l.scene,
        Err(f) => panic!("{:?}", f.errors),
    };
    both_ways(&desc, "many lights");
}
