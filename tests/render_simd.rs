//! The four-lane fast paths give the image of the scalar code bit for bit:
//! each scene is rendered both ways (`RenderOptions::scalar`) and compared
//! pixel by pixel, with the rays each traced.

mod common;

use pbrs::loader::load_scene_str;
use pbrs::render::driver::RenderStats;
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

/// directlighting "all" skips the estimates of an area light wholly behind
/// a surface (by its geometric normal) whose lobes only reflect, and the
/// BSDF samples outside the cone of the sphere around a light's box: the
/// image is the scalar code's, which computes every estimate. A disk, a sphere
/// and a two-sided quad light with several samples each, over plastic,
/// metal, substrate, bump-mapped plastic and meshes whose shading normals
/// lean away from their faces (plastic, matte and metal; one tilted
/// towards the sphere light below it, which BSDF samples in the shading
/// hemisphere aim at but whose value the geometric side makes 0), glass
/// for deeper vertices, and the (0,2)-sequence sampler's arrays.
#[test]
fn lights_behind_reflecting_surfaces_are_the_scalar_image() {
    let text = r#"
LookAt 0 2 -6  0 0.5 0  0 1 0
Camera "perspective" "float fov" [50]
Film "image" "integer xresolution" [40] "integer yresolution" [32]
Sampler "lowdiscrepancy" "integer pixelsamples" [8]
Integrator "directlighting" "integer maxdepth" [3]
WorldBegin
AttributeBegin
  AreaLightSource "area" "rgb L" [6 6 6] "integer nsamples" [4]
  Translate 1.5 2.5 0
  Rotate 120 1 0 0
  Shape "disk" "float radius" [0.6]
AttributeEnd
AttributeBegin
  AreaLightSource "area" "rgb L" [3 2 1] "integer nsamples" [2]
  Translate -2 0.8 1
  Shape "sphere" "float radius" [0.3]
AttributeEnd
AttributeBegin
  AreaLightSource "area" "rgb L" [1 2 3] "integer nsamples" [2] "bool twosided" "true"
  Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
    "point P" [0.5 0.1 2  1.5 0.1 2  1.5 1.1 2.2  0.5 1.1 2.2]
AttributeEnd
Material "plastic" "rgb Kd" [0.4 0.4 0.5] "float roughness" [0.2]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
  "point P" [-4 0 -4  4 0 -4  4 0 4  -4 0 4]
  "normal N" [-0.3 1 0  0.2 1 0.1  0 1 -0.3  0.1 1 0.3]
AttributeBegin
  Material "metal" "float roughness" [0.05]
  Translate -0.8 0.5 0
  Shape "sphere" "float radius" [0.5]
AttributeEnd
AttributeBegin
  Material "substrate" "float uroughness" [0.3] "float vroughness" [0.05]
  Translate 0.6 0.4 -0.6
  Shape "sphere" "float radius" [0.4]
AttributeEnd
Texture "bumps" "float" "wrinkled" "float scale" [4]
AttributeBegin
  Material "plastic" "rgb Kd" [0.6 0.3 0.2] "texture bumpmap" "bumps"
  Translate 0.2 0.35 1
  Shape "sphere" "float radius" [0.35]
AttributeEnd
AttributeBegin
  Material "glass"
  Translate -0.3 0.25 -1.3
  Shape "sphere" "float radius" [0.25]
AttributeEnd
AttributeBegin
  Material "matte" "rgb Kd" [0.3 0.6 0.3]
  Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
    "point P" [-2.5 0 1.5  -1 0 2.5  -1 1.5 2.5  -2.5 1.5 1.5]
    "normal N" [0.8 0 -1  -0.5 0.3 -1  0.6 -0.4 -1  -0.7 0.2 -1]
AttributeEnd
AttributeBegin
  Material "matte" "rgb Kd" [0.7 0.7 0.7]
  Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
    "point P" [-1.2 1.4 0.4  0 1.4 0.4  0 1.4 1.6  -1.2 1.4 1.6]
    "normal N" [-1 0.3 0  -1 0.2 0.1  -1 0.3 -0.1  -1 0.4 0]
AttributeEnd
AttributeBegin
  Material "metal" "float roughness" [0.3]
  Translate 0 0 0.8
  Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
    "point P" [-2.5 0 1.5  -1 0 2.5  -1 1.5 2.5  -2.5 1.5 1.5]
    "normal N" [0.8 0 -1  -0.5 0.3 -1  0.6 -0.4 -1  -0.7 0.2 -1]
AttributeEnd
WorldEnd
"#;
    let desc = common::load_text(text).scene;
    let (fast_stats, slow_stats) = common::assert_fast_image_is_scalar(&desc, "lights behind");
    // The skipped BSDF samples towards the sphere light trace no rays (its
    // density is the cone's, whatever the direction; the scalar code traces
    // them and finds something else first): fewer closest hits, the same
    // shadow rays.
    assert!(
        fast_stats.rays.closest < slow_stats.rays.closest,
        "{} {}",
        fast_stats.rays.closest,
        slow_stats.rays.closest
    );
    assert_eq!(fast_stats.rays.shadow, slow_stats.rays.shadow);
    let culls = |s: &RenderStats| s.notes.iter().any(|n| n.contains("behind"));
    assert!(culls(&fast_stats), "{:?}", fast_stats.notes);
    assert!(!culls(&slow_stats), "{:?}", slow_stats.notes);
}

/// directlighting traces a many-sample light's shadow rays side by side
/// (up to sixteen at a time, then adds each estimate in order): the image
/// is the one-by-one code's bit for bit, with the same rays. An
/// environment light of 37 samples (two full runs and a part-full one), a
/// disk light of 5 and a point light of 3 over triangles and spheres that
/// block some of the rays (the spheres answered by the any-hit callback),
/// plastic, matte and a mirror.
#[test]
fn many_sample_lights_shadow_rays_together_are_the_scalar_image() {
    let text = r#"
LookAt 0 3 -6  0 0.5 0  0 1 0
Camera "perspective" "float fov" [45]
Film "image" "integer xresolution" [32] "integer yresolution" [24]
Sampler "halton" "integer pixelsamples" [4]
Integrator "directlighting" "integer maxdepth" [3]
WorldBegin
LightSource "infinite" "rgb L" [0.5 0.6 0.8] "integer nsamples" [37]
LightSource "point" "point from" [1 3 -1] "rgb I" [4 4 4] "integer nsamples" [3]
AttributeBegin
  AreaLightSource "area" "rgb L" [5 4 3] "integer nsamples" [5]
  Translate -1 2.5 0.5
  Rotate 90 1 0 0
  Shape "disk" "float radius" [0.5]
AttributeEnd
Material "plastic" "rgb Kd" [0.5 0.4 0.3] "float roughness" [0.1]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
  "point P" [-4 0 -4  4 0 -4  4 0 4  -4 0 4]
AttributeBegin
  Material "matte" "rgb Kd" [0.3 0.6 0.3]
  Translate -0.7 0.6 0
  Shape "sphere" "float radius" [0.6]
AttributeEnd
AttributeBegin
  Material "mirror"
  Translate 0.9 0.4 -0.5
  Shape "sphere" "float radius" [0.4]
AttributeEnd
AttributeBegin
  Material "matte" "rgb Kd" [0.7 0.7 0.7]
  Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
    "point P" [0 1.2 0  1.5 1.2 0  1.5 1.2 1.5  0 1.2 1.5]
AttributeEnd
WorldEnd
"#;
    let desc = common::load_text(text).scene;
    let (fast_stats, slow_stats) = common::assert_fast_image_is_scalar(&desc, "many samples");
    assert_eq!(fast_stats.rays.shadow, slow_stats.rays.shadow);
    assert_eq!(fast_stats.rays.closest, slow_stats.rays.closest);
}

/// directlighting at plastic-like BSDFs lit by two to four delta lights
/// (points, a spot, a distant light; one behind the floor, one black)
/// takes the BSDF's values for all lights in one pass of lanes: textured
/// plastic, anisotropic uber with a mirror lobe that light sampling leaves
/// out, plastic without roughness remapping and matte (not such a BSDF)
/// give the scalar code's image bit for bit with the same rays, under the
/// (0,2)-sequence sampler's arrays and Halton's, and with five lights
/// (more than the lanes).
#[test]
fn delta_lights_at_glossy_bsdfs_are_the_scalar_image() {
    let scene = |sampler: &str, lights: &str| {
        format!(
            r#"
LookAt 0 3 -6  0 0.5 0  0 1 0
Camera "perspective" "float fov" [45]
Film "image" "integer xresolution" [32] "integer yresolution" [24]
Sampler "{sampler}" "integer pixelsamples" [4]
Integrator "directlighting" "integer maxdepth" [3]
WorldBegin
{lights}
Texture "checks" "spectrum" "checkerboard" "float uscale" [8] "float vscale" [8]
  "rgb tex1" [0.8 0.2 0.1] "rgb tex2" [0.1 0.3 0.7]
Material "plastic" "texture Kd" "checks" "rgb Ks" [0.5 0.5 0.5] "float roughness" [0.2]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
  "point P" [-4 0 -4  4 0 -4  4 0 4  -4 0 4] "float uv" [0 0 1 0 1 1 0 1]
AttributeBegin
  Material "uber" "rgb Kd" [0.3 0.6 0.3] "rgb Ks" [0.4 0.4 0.4] "rgb Kr" [0.2 0.2 0.2]
    "float uroughness" [0.05] "float vroughness" [0.4] "float index" [1.7]
  Translate -0.7 0.6 0
  Shape "sphere" "float radius" [0.6]
AttributeEnd
AttributeBegin
  Material "plastic" "rgb Kd" [0.2 0.2 0.6] "float roughness" [0.01] "bool remaproughness" "false"
  Translate 0.9 0.4 -0.5
  Shape "sphere" "float radius" [0.4]
AttributeEnd
AttributeBegin
  Material "matte" "rgb Kd" [0.7 0.7 0.7]
  Translate 0.2 0.3 1.2
  Shape "sphere" "float radius" [0.3]
AttributeEnd
WorldEnd
"#
        )
    };
    let point =
        |p: &str, i: &str| format!(r#"LightSource "point" "point from" [{p}] "rgb I" [{i}]"#);
    let two = [point("1 3 -1", "4 4 4"), point("-2 2 -2", "2 3 1")].join("\n");
    let four = [
        point("1 3 -1", "4 4 4"),
        point("0 -2 0", "5 5 5"),
        r#"LightSource "spot" "point from" [-2 3 -2] "point to" [0 0 0] "float coneangle" [25] "rgb I" [9 8 7]"#.to_string(),
        r#"LightSource "distant" "point from" [1 1 -1] "point to" [0 0 0] "rgb L" [0.7 0.7 0.6]"#.to_string(),
    ]
    .join("\n");
    let five = [four.clone(), point("0 2 2", "0 0 0")].join("\n");
    for (sampler, lights, what) in [
        ("lowdiscrepancy", &two, "two points, (0,2)"),
        ("halton", &two, "two points, halton"),
        ("lowdiscrepancy", &four, "four lights, (0,2)"),
        ("halton", &four, "four lights, halton"),
        ("lowdiscrepancy", &five, "five lights"),
    ] {
        let desc = common::load_text(&scene(sampler, lights)).scene;
        let (fast, slow) = common::assert_fast_is_scalar(&desc, what);
        assert!(fast.rays.shadow > 0, "{what}");
        assert_eq!(fast.samples, slow.samples, "{what}");
    }
}
