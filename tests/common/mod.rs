//! Shared helpers for render tests: render a scene small, load references,
//! compare with noise-aware metrics, and leave images to look at on failure.
#![allow(dead_code)]

use pbrs::image::compare::{compare, false_colour_difference, Comparison};
use pbrs::image::io::{read_image, write_image};
use pbrs::image::verdict;
use pbrs::image::Image;
use pbrs::loader::load_scene;
use pbrs::render::driver::{render, RenderOptions, RenderStats};
use pbrs::scene::SceneDescription;
use std::path::{Path, PathBuf};

pub fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Loads a scene of the repository (path relative to the repository root).
pub fn load(rel: &str) -> SceneDescription {
    let path = repo().join(rel);
    match load_scene(&path) {
        Ok(l) => l.scene,
        Err(f) => panic!("{rel} failed to load: {:?}", f.errors),
    }
}

/// Renders a description at `res`×`res` with `spp` samples per pixel.
pub fn render_at(
    mut desc: SceneDescription,
    res: u32,
    spp: u32,
    threads: Option<usize>,
) -> (Image, RenderStats) {
    desc.film.xresolution = res;
    desc.film.yresolution = res;
    desc.sampler.pixel_samples = spp;
    render(
        &desc,
        &RenderOptions {
            threads,
            ..Default::default()
        },
        &|_, _| {},
    )
    .expect("render failed")
}

/// The file of a converged pbrt-v3 reference: `STEM-128-SPP.pfm` in
/// `scenes/references/` with the highest SPP (the Cornell boxes have 16384,
/// the feature scenes 2048; "128" names the resolution set, and a few
/// scenes of it are not square).
pub fn reference_path(stem: &str) -> PathBuf {
    let dir = repo().join("scenes/references");
    let prefix = format!("{stem}-128-");
    let best = std::fs::read_dir(&dir)
        .expect("scenes/references")
        .filter_map(|e| {
            let name = e.ok()?.file_name().into_string().ok()?;
            let spp: u32 = name
                .strip_prefix(&prefix)?
                .strip_suffix(".pfm")?
                .parse()
                .ok()?;
            (spp > 64).then_some((spp, name))
        })
        .max();
    match best {
        Some((_, name)) => dir.join(name),
        None => panic!("no converged reference {prefix}*.pfm"),
    }
}

/// A converged pbrt-v3 reference from `scenes/references/`.
pub fn reference(stem: &str) -> Image {
    read_image(&reference_path(stem)).expect("reference")
}

/// pbrt-v3's own render at 64 spp (the noise to expect).
pub fn pbrt_64(stem: &str) -> Image {
    read_image(
        &repo()
            .join("scenes/references")
            .join(format!("{stem}-128-64.pfm")),
    )
    .expect("pbrt-v3 64 spp")
}

/// Acceptance bounds for a render compared with a converged reference
/// (judged by `pbrs::image::verdict`, the verdict `pbrs test` uses).
#[derive(Clone, Copy, Debug)]
pub struct Bounds {
    pub max_relative_mse: f64,
    pub max_block_error: f64,
    /// Largest relative difference of the per-channel image means.
    pub max_mean_difference: f64,
}

impl Bounds {
    /// The render-core criteria: relative MSE within 1.5× and block error
    /// within 2× of pbrt-v3's own at equal spp, mean within 1%.
    pub fn against_pbrt(stem: &str) -> Bounds {
        let c = compare(&pbrt_64(stem), &reference(stem));
        Bounds {
            max_relative_mse: 1.5 * c.relative_mse,
            max_block_error: 2.0 * c.block_error,
            max_mean_difference: 0.01,
        }
    }
}

/// Directory for images of failing comparisons.
pub fn output_dir(name: &str) -> PathBuf {
    let d = repo().join("target").join("test-output").join(name);
    let _ = std::fs::create_dir_all(&d);
    d
}

impl From<Bounds> for verdict::Bounds {
    fn from(b: Bounds) -> verdict::Bounds {
        verdict::Bounds {
            max_relative_mse: b.max_relative_mse,
            max_block_error: b.max_block_error,
            max_mean_difference: b.max_mean_difference,
        }
    }
}

/// Whether `img` is within `b` of `reference` (and has no non-finite pixel).
pub fn within(img: &Image, reference: &Image, b: impl Into<verdict::Bounds>) -> bool {
    verdict::judge(img, reference, b.into()).passed()
}

/// Compares and asserts; on failure writes render, reference and a
/// false-colour difference image next to the test output.
pub fn assert_matches(
    name: &str,
    img: &Image,
    reference: &Image,
    b: impl Into<verdict::Bounds>,
) -> Comparison {
    let v = verdict::judge(img, reference, b.into());
    eprintln!("{name}: {}", v.summary());
    let c = v.comparison;
    if !v.passed() {
        let d = output_dir(name);
        let _ = write_image(&d.join("render.exr"), img);
        let _ = write_image(&d.join("render.png"), img);
        let _ = write_image(&d.join("reference.png"), reference);
        let _ = write_image(
            &d.join("difference.png"),
            &false_colour_difference(img, reference),
        );
        panic!(
            "{name} does not match its reference (images in {})",
            d.display()
        );
    }
    c
}

pub fn exists(p: &Path) -> bool {
    p.exists()
}

/// Renders with an explicit seed (independent scrambling per seed).
pub fn render_seeded(
    desc: SceneDescription,
    res: u32,
    spp: u32,
    seed: u64,
) -> (Image, RenderStats) {
    render_seeded_wh(desc, res, res, spp, seed)
}

/// [`render_seeded`] at `width`×`height`.
pub fn render_seeded_wh(
    mut desc: SceneDescription,
    width: u32,
    height: u32,
    spp: u32,
    seed: u64,
) -> (Image, RenderStats) {
    desc.film.xresolution = width;
    desc.film.yresolution = height;
    desc.sampler.pixel_samples = spp;
    render(
        &desc,
        &RenderOptions {
            threads: None,
            seed,
            ..Default::default()
        },
        &|_, _| {},
    )
    .expect("render failed")
}

/// Pixel-wise mean of images of the same size.
pub fn average(images: &[Image]) -> Image {
    let mut out = images[0].clone();
    for (i, v) in out.data.iter_mut().enumerate() {
        *v = images.iter().map(|im| im.data[i] as f64).sum::<f64>() as f32 / images.len() as f32;
    }
    out
}

/// `img` at half its width and height, each pixel the mean of the 2×2 it
/// covers (a converged reference taken down to a test's smaller film).
pub fn halved(img: &Image) -> Image {
    let (w, h) = (img.width / 2, img.height / 2);
    let mut r = Image::new(w, h);
    for y in 0..h {
        for x in 0..w {
            for c in 0..3 {
                let v = |dx: u32, dy: u32| {
                    img.data[(((2 * y + dy) * img.width + 2 * x + dx) * 3 + c) as usize]
                };
                r.data[((y * w + x) * 3 + c) as usize] =
                    (v(0, 0) + v(1, 0) + v(0, 1) + v(1, 1)) / 4.0;
            }
        }
    }
    r
}

/// The materials of `Material {decl}` (after the named materials it refers
/// to, in the scene's order, linked as the renderer links them) and the
/// index of the statement's own, loaded through the real scene loader.
///
/// `decl` may start with other statements (`MakeNamedMaterial` lines): then
/// its last line is a whole `Material` statement.
pub fn materials_of(decl: &str) -> (Vec<pbrs::materials::Material>, usize) {
    let text = if decl.contains('\n') {
        format!("WorldBegin\n{decl}\nShape \"sphere\"\nWorldEnd\n")
    } else {
        format!("WorldBegin\nMaterial {decl}\nShape \"sphere\"\nWorldEnd\n")
    };
    let l = pbrs::loader::load_scene_str(&text, &repo().join("mem.pbrt"))
        .unwrap_or_else(|f| panic!("{decl}: {:?}", f.errors));
    let first = l.scene.shapes[0].material.0 as usize;
    let mut m: Vec<_> = l
        .scene
        .materials
        .iter()
        .map(pbrs::materials::Material::new)
        .collect();
    pbrs::materials::link_materials(&mut m);
    (m, first)
}

/// The BSDF of `Material {decl}` at a point with normals +z and, when the
/// material needs them, dp/du = +x and dp/dv = +y. The materials are leaked
/// (the BSDF may refer to them); for tabulated materials, whose tables are
/// large, use [`bsdf_of`] with materials the test keeps.
pub fn material_bsdf(decl: &str, multiple_lobes: bool) -> pbrs::materials::Bsdf<'static> {
    let (materials, first) = materials_of(decl);
    bsdf_of(Vec::leak(materials), first, multiple_lobes)
}

/// The BSDF of `materials[first]` (the others are what it may refer to) at
/// the point of [`material_bsdf`].
pub fn bsdf_of(
    materials: &[pbrs::materials::Material],
    first: usize,
    multiple_lobes: bool,
) -> pbrs::materials::Bsdf<'_> {
    use glam::{Vec2, Vec3};
    use pbrs::accel::SurfaceHit;
    use pbrs::materials::{BsdfContext, ShadingContext};
    use pbrs::shapes::{DiffGeom, SurfacePoint};
    let hit = SurfaceHit {
        point: SurfacePoint {
            p: Vec3::ZERO,
            p_error: Vec3::ZERO,
            n: Vec3::Z,
            ns: Vec3::Z,
        },
        material: 0,
        light: None,
        time: 0.0,
    };
    let geom = DiffGeom {
        uv: Vec2::new(0.5, 0.5),
        dpdu: Vec3::X,
        dpdv: Vec3::Y,
        shading_dpdu: Vec3::X,
        shading_dpdv: Vec3::Y,
        ..DiffGeom::ZERO
    };
    let ctx = BsdfContext {
        materials,
        multiple_lobes,
    };
    materials[first].bsdf(
        &ShadingContext {
            hit: &hit,
            geom: &geom,
        },
        &ctx,
    )
}

/// The errors of `body` wrapped in a world block, loaded as if from the file
/// `path` (which need not exist), when it must not load under `--strict`
/// (an error, or a warning of something pbrt-v3 renders through): each
/// message, then its rendered report (with the location).
pub fn world_errors(path: &Path, body: &str) -> String {
    match pbrs::loader::load_scene_str(&format!("WorldBegin\n{body}\nWorldEnd\n"), path)
        .and_then(|s| pbrs::loader::strictly(vec![s]))
    {
        Ok(_) => panic!("loaded, but should not: {body}"),
        Err(f) => f
            .errors
            .iter()
            .map(|e| format!("{e}\n{e:?}"))
            .collect::<Vec<_>>()
            .join("\n"),
    }
}

/// A scene given as text (as if from the file `mem.pbrt`), which must load.
pub fn load_text(text: &str) -> pbrs::loader::LoadedScene {
    pbrs::loader::load_scene_str(text, Path::new("mem.pbrt")).unwrap_or_else(|f| panic!("{f:?}"))
}

/// A loaded scene's warnings, one message per line.
pub fn warning_text(s: &pbrs::loader::LoadedScene) -> String {
    s.warnings
        .iter()
        .map(|w| w.to_string())
        .collect::<Vec<_>>()
        .join("\n")
}

/// The errors of a scene given as text (as if from `mem.pbrt`) that must not
/// load under `--strict` (an error, or a warning of something pbrt-v3
/// renders through), one message per line.
pub fn error_text(text: &str) -> String {
    match pbrs::loader::load_scene_str(text, Path::new("mem.pbrt"))
        .and_then(|s| pbrs::loader::strictly(vec![s]))
    {
        Ok(_) => panic!("loaded, but should not:\n{text}"),
        Err(f) => f
            .errors
            .iter()
            .map(|e| e.to_string())
            .collect::<Vec<_>>()
            .join("\n"),
    }
}

/// Renders `desc` with the fast paths (four-lane light estimate, batches)
/// and with `RenderOptions::scalar`, both on two threads, and asserts that
/// the images are the same bit for bit, with some light in them. Returns
/// both statistics (fast, scalar).
pub fn assert_fast_image_is_scalar(
    desc: &SceneDescription,
    what: &str,
) -> (RenderStats, RenderStats) {
    let run = |scalar: bool| {
        render(
            desc,
            &RenderOptions {
                threads: Some(2),
                scalar,
                ..Default::default()
            },
            &|_, _| {},
        )
        .expect("render failed")
    };
    let (fast, fast_stats) = run(false);
    let (slow, slow_stats) = run(true);
    assert_eq!(fast.width, slow.width, "{what}");
    let differ = fast
        .data
        .iter()
        .zip(&slow.data)
        .filter(|(a, b)| a.to_bits() != b.to_bits())
        .count();
    assert_eq!(
        differ, 0,
        "{what}: {differ} values differ from the scalar code"
    );
    assert_eq!(fast_stats.samples, slow_stats.samples, "{what}");
    let sum: f64 = fast.data.iter().map(|&v| v as f64).sum();
    assert!(sum > 0.0, "{what}: a black image proves nothing");
    (fast_stats, slow_stats)
}

/// [`assert_fast_image_is_scalar`], with the same ray counts too.
pub fn assert_fast_is_scalar(desc: &SceneDescription, what: &str) -> (RenderStats, RenderStats) {
    let (fast_stats, slow_stats) = assert_fast_image_is_scalar(desc, what);
    assert_eq!(fast_stats.rays.closest, slow_stats.rays.closest, "{what}");
    assert_eq!(fast_stats.rays.shadow, slow_stats.rays.shadow, "{what}");
    (fast_stats, slow_stats)
}

/// `desc` rendered with `threads` threads and the default seed.
pub fn render_threads(desc: &SceneDescription, threads: usize) -> Image {
    render(
        desc,
        &RenderOptions {
            threads: Some(threads),
            ..Default::default()
        },
        &|_, _| {},
    )
    .expect("render")
    .0
}

/// Means of `b`×`b` blocks of pixels (all channels).
pub fn block_means(img: &Image, b: u32) -> Vec<f64> {
    let (nx, ny) = (img.width / b, img.height / b);
    let mut out = vec![0.0; (nx * ny) as usize];
    for y in 0..ny * b {
        for x in 0..nx * b {
            let i = ((y * img.width + x) * 3) as usize;
            let s: f64 = img.data[i..i + 3].iter().map(|&v| v as f64).sum();
            out[((y / b) * nx + x / b) as usize] += s / (3 * b * b) as f64;
        }
    }
    out
}

/// Asserts that `a` and `b` are the same image bit for bit (`what` names
/// the two renders in the failure).
pub fn assert_bit_identical(a: &Image, b: &Image, what: &str) {
    assert_eq!(
        (a.width, a.height),
        (b.width, b.height),
        "{what}: sizes differ"
    );
    assert!(
        a.data
            .iter()
            .zip(&b.data)
            .all(|(x, y)| x.to_bits() == y.to_bits()),
        "{what} differ"
    );
}

/// A 24×24 view from inside a sphere of radius 1 whose material-less
/// boundary has fog inside (σs 1.5, σa `sigma_a`) and vacuum outside, the
/// camera in the fog; `integrator` is the `Integrator` statement's
/// arguments, `world` what the world holds besides the sphere.
pub fn fog_sphere(integrator: &str, spp: u32, sigma_a: f32, world: &str) -> String {
    format!(
        r#"
LookAt 0 0 0.5  0 0 -1  0 1 0
Camera "perspective" "float fov" [70]
Film "image" "integer xresolution" [24] "integer yresolution" [24]
Sampler "random" "integer pixelsamples" [{spp}]
Integrator {integrator}
MakeNamedMedium "fog" "string type" "homogeneous"
  "rgb sigma_a" [{sigma_a} {sigma_a} {sigma_a}] "rgb sigma_s" [1.5 1.5 1.5]
MediumInterface "" "fog"
WorldBegin
AttributeBegin
  MediumInterface "fog" ""
  Material ""
  Shape "sphere" "float radius" 1
AttributeEnd
{world}
WorldEnd
"#
    )
}
