//! The image infinite light through the whole pipeline: scenes loaded with
//! in-memory image files, rendered. Furnaces (a constant-valued map renders
//! its value, through every integrator), importance sampling against
//! uniform sampling of the same map (same expected image: `pdf_li` is
//! consistent with `sample_li` in the MIS weights), pbrt-v3's raw reading
//! of 8-bit maps, the per-scene cache and located errors for bad files.

use glam::Vec3;
use pbrs::image::Image;
use pbrs::lang::FileLoader;
use pbrs::loader::{load_scene_with, LoadFailure, LoadedScene};
use pbrs::render::driver::{render, RenderOptions};
use pbrs::scene::{Light, SceneDescription};
use std::collections::HashMap;
use std::io::Cursor;
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

/// Files served from memory by name; counts the reads.
struct Files(HashMap<String, Vec<u8>>, Arc<AtomicUsize>);

impl FileLoader for Files {
    fn load(&self, path: &Path) -> Result<Vec<u8>, String> {
        self.1.fetch_add(1, Ordering::Relaxed);
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        self.0
            .get(&name)
            .cloned()
            .ok_or_else(|| "No such file".into())
    }
}

fn exr(w: usize, h: usize, f: impl Fn(usize, usize) -> Vec3 + Sync) -> Vec<u8> {
    use exr::prelude::*;
    let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
        let v = f(x, y);
        (v.x, v.y, v.z)
    });
    let mut c = Cursor::new(Vec::new());
    Image::from_channels((w, h), channels)
        .write()
        .non_parallel()
        .to_buffered(&mut c)
        .unwrap();
    c.into_inner()
}

fn png(w: u32, h: u32, v: u8) -> Vec<u8> {
    use image::ImageEncoder;
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(
            &vec![v; (w * h * 3) as usize],
            w,
            h,
            image::ExtendedColorType::Rgb8,
        )
        .unwrap();
    out
}

fn load_with(text: &str, files: &[(&str, Vec<u8>)]) -> (Result<LoadedScene, LoadFailure>, usize) {
    let reads = Arc::new(AtomicUsize::new(0));
    let map = files
        .iter()
        .map(|(n, b)| (n.to_string(), b.clone()))
        .collect();
    let r = load_scene_with(
        text,
        Path::new("/mem/scene.pbrt"),
        Box::new(Files(map, reads.clone())),
    );
    (r, reads.load(Ordering::Relaxed))
}

fn scene(text: &str, files: &[(&str, Vec<u8>)]) -> SceneDescription {
    match load_with(text, files).0 {
        Ok(s) => s.scene,
        Err(e) => panic!("{e:?}"),
    }
}

fn render_spp(desc: &SceneDescription, spp: u32, seed: u64) -> Image {
    let mut d = desc.clone();
    d.sampler.pixel_samples = spp;
    render(
        &d,
        &RenderOptions {
            seed,
            ..Default::default()
        },
        &|_, _| {},
    )
    .unwrap()
    .0
}

fn mean(img: &Image) -> Vec3 {
    let n = (img.width * img.height) as f64;
    let mut s = [0.0f64; 3];
    for p in img.data.chunks(3) {
        for c in 0..3 {
            s[c] += p[c] as f64;
        }
    }
    Vec3::new((s[0] / n) as f32, (s[1] / n) as f32, (s[2] / n) as f32)
}

/// A white (albedo 1) matte sphere filling most of the view, in a sky of
/// one value: every pixel sees that value (the sphere is convex, so one
/// bounce always escapes).
fn furnace(integrator: &str, light: &str) -> String {
    format!(
        "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" [30]\n\
         Film \"image\" \"integer xresolution\" [24] \"integer yresolution\" [24]\n\
         Sampler \"halton\" \"integer pixelsamples\" [16]\nIntegrator {integrator}\n\
         WorldBegin\nAttributeBegin\nRotate -90 1 0 0\nRotate 33 0 0 1\n{light}\nAttributeEnd\n\
         Material \"matte\" \"rgb Kd\" [1 1 1]\nShape \"sphere\" \"float radius\" [1]\nWorldEnd\n"
    )
}

#[test]
fn furnace_with_a_constant_map_renders_its_value() {
    let value = Vec3::new(0.7, 0.5, 0.3);
    // 6 × 3: not a power of two, so the map is resampled first (a constant
    // stays constant); L and scale multiply it.
    let map = exr(6, 3, |_, _| value);
    let light = "LightSource \"infinite\" \"string mapname\" \"sky.exr\" \"rgb L\" [2 1 1] \"rgb scale\" [0.5 1 1]";
    for integrator in [
        "\"path\" \"integer maxdepth\" [5]",
        "\"directlighting\"",
        "\"directlighting\" \"string strategy\" \"one\"",
        "\"whitted\"",
    ] {
        let desc = scene(&furnace(integrator, light), &[("sky.exr", map.clone())]);
        let img = render_spp(&desc, 16, 1);
        let m = mean(&img);
        let err = ((m - value) / value).abs().max_element();
        println!("{integrator}: mean {m}, relative error {err}");
        assert!(err < 0.01, "{integrator}: mean {m}, want {value}");
        // Not just on average: pixel by pixel (each a 16-sample estimate),
        // with no bias anywhere (the background is exact, the sphere noisy).
        let rel: Vec<f32> = img
            .data
            .chunks(3)
            .map(|p| {
                ((Vec3::new(p[0], p[1], p[2]) - value) / value)
                    .abs()
                    .max_element()
            })
            .collect();
        let rms = (rel.iter().map(|r| r * r).sum::<f32>() / rel.len() as f32).sqrt();
        let worst = rel.iter().cloned().fold(0.0, f32::max);
        println!("{integrator}: per-pixel relative error rms {rms}, worst {worst}");
        // Whitted samples the light alone (no MIS): noisier.
        let (max_rms, max_worst) = if integrator == "\"whitted\"" {
            (0.25, 1.2)
        } else {
            (0.05, 0.3)
        };
        assert!(
            rms < max_rms && worst < max_worst,
            "{integrator}: rms {rms}, worst {worst}"
        );
    }
}

/// pbrt-v3 reads an environment map's 8-bit values raw (no sRGB decoding):
/// a PNG of 128s is a sky of 128/255, not of its linear value 0.216.
#[test]
fn png_maps_are_read_raw_as_pbrt_v3_does() {
    let light = "LightSource \"infinite\" \"string mapname\" \"sky.png\"";
    let desc = scene(&furnace("\"path\"", light), &[("sky.png", png(4, 2, 128))]);
    let m = mean(&render_spp(&desc, 16, 2));
    assert!(
        (m - Vec3::splat(128.0 / 255.0)).abs().max_element() < 0.005,
        "{m}"
    );
}

/// A non-uniform map with a bright spot, over a diffuse plane and sphere:
/// importance sampling and uniform sampling of the same map give the same
/// image (within noise), and importance sampling is less noisy.
#[test]
fn importance_and_uniform_sampling_agree() {
    let map = exr(32, 16, |x, y| {
        let sun = if (x, y) == (9, 4) { 400.0 } else { 0.0 };
        Vec3::new(0.3 + sun, 0.4 + 0.5 * sun, 0.6 + (y as f32) * 0.02)
    });
    let text = |sampling: &str| {
        format!(
            "LookAt 0 2 6  0 0.5 0  0 1 0\nCamera \"perspective\" \"float fov\" [40]\n\
             Film \"image\" \"integer xresolution\" [16] \"integer yresolution\" [16]\n\
             Sampler \"halton\" \"integer pixelsamples\" [64]\nIntegrator \"path\" \"integer maxdepth\" [3]\n\
             WorldBegin\nAttributeBegin\nRotate -90 1 0 0\n\
             LightSource \"infinite\" \"string mapname\" \"sky.exr\" \"string sampling\" \"{sampling}\"\nAttributeEnd\n\
             Material \"matte\" \"rgb Kd\" [0.6 0.6 0.6]\nTranslate 0 1 0\nShape \"sphere\" \"float radius\" [1]\n\
             Translate 0 -1 0\nShape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3]\n\
             \"point P\" [-5 0 -5  5 0 -5  5 0 5  -5 0 5]\nWorldEnd\n"
        )
    };
    let files = [("sky.exr", map)];
    let is = scene(&text("map"), &files);
    let un = scene(&text("uniform"), &files);
    // Several independent renders give a mean and its spread per strategy.
    let stats = |desc: &SceneDescription| {
        let means: Vec<Vec3> = (0..6)
            .map(|s| mean(&render_spp(desc, 64, 10 + s)))
            .collect();
        let m = means.iter().sum::<Vec3>() / means.len() as f32;
        let var =
            means.iter().map(|v| (*v - m) * (*v - m)).sum::<Vec3>() / (means.len() - 1) as f32;
        (m, (var / means.len() as f32).powf(0.5))
    };
    let (m_is, se_is) = stats(&is);
    let (m_un, se_un) = stats(&un);
    println!("importance {m_is} ± {se_is}, uniform {m_un} ± {se_un}");
    let diff = (m_is - m_un).abs();
    let tol = 4.0 * (se_is * se_is + se_un * se_un).powf(0.5) + 0.002 * m_is;
    assert!(diff.cmple(tol).all(), "means differ: {diff} > {tol}");
    assert!(
        se_is.x < se_un.x,
        "importance sampling is not less noisy: {se_is} vs {se_un}"
    );
}

#[test]
fn one_file_is_read_once_for_several_lights() {
    let map = exr(4, 2, |_, _| Vec3::ONE);
    let text = "WorldBegin\nLightSource \"infinite\" \"string mapname\" \"sky.exr\"\n\
                LightSource \"infinite\" \"string mapname\" \"sky.exr\" \"rgb L\" [2 2 2]\n\
                LightSource \"infinite\" \"string mapname\" \"./sky.exr\"\nWorldEnd\n";
    let (r, reads) = load_with(text, &[("sky.exr", map)]);
    let s = r.unwrap().scene;
    let maps: Vec<_> = s
        .lights
        .iter()
        .map(|l| match l {
            Light::Infinite(i) => i.map.clone(),
            _ => panic!(),
        })
        .collect();
    // "./sky.exr" is another path to the loader; what matters is that
    // repeated names are not read again.
    assert!(reads <= 2, "{reads} reads");
    // The lights are built from the same map (the second times L = 2).
    assert_eq!(maps[0].size(), (4, 2));
    for d in [Vec3::X, Vec3::new(0.3, -0.5, 0.8).normalize()] {
        assert_eq!(maps[1].le(d), 2.0 * maps[0].le(d));
        assert_eq!(maps[2].le(d), maps[0].le(d));
    }
}

/// A map that cannot be read: a located warning naming the file and why,
/// and the light renders without it (constant `L`, as pbrt-v3).
#[test]
fn bad_maps_are_located_warnings_naming_the_file() {
    let good = exr(8, 4, |_, _| Vec3::ONE);
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        ("missing.exr", Vec::new(), "No such file"),
        ("cut.exr", good[..good.len() / 2].to_vec(), ""),
        ("zero.exr", Vec::new(), "empty"),
        ("junk.png", b"\x89PNG\r\n\x1a\nnot really".to_vec(), ""),
        (
            "huge.pfm",
            b"PF\n100000 100000\n-1\n\0\0\0\0".to_vec(),
            "more than pbrs reads",
        ),
        ("sky.jpg", b"\xff\xd8\xff".to_vec(), "not supported"),
    ];
    for (name, bytes, what) in cases {
        let text = format!(
            "WorldBegin\n\nLightSource \"infinite\" \"string mapname\" \"{name}\"\nWorldEnd\n"
        );
        let files: Vec<(&str, Vec<u8>)> = if name == "missing.exr" {
            vec![]
        } else {
            vec![(name, bytes)]
        };
        let Ok(loaded) = load_with(&text, &files).0 else {
            panic!("{name}: not loaded");
        };
        let msg: String = loaded.warnings.iter().map(|w| format!("{w}\n")).collect();
        assert!(
            msg.contains("rendered as without \"mapname\""),
            "{name}: {msg}"
        );
        assert!(
            matches!(&loaded.scene.lights[..], [Light::Infinite(i)] if i.map.le(glam::Vec3::X) == glam::Vec3::ONE),
            "{name}: not the constant light"
        );
        assert!(msg.contains("scene.pbrt:3:"), "{name}: not located: {msg}");
        assert!(msg.contains(name), "{name}: file not named: {msg}");
        assert!(msg.contains(what), "{name}: {msg}");
    }
}

#[test]
fn float_scale_is_ignored_as_pbrt_v3_does() {
    let text =
        "WorldBegin\nLightSource \"infinite\" \"rgb L\" [1 1 1] \"float scale\" [3]\nWorldEnd\n";
    let r = load_with(text, &[]).0.unwrap();
    let Light::Infinite(light) = &r.scene.lights[0] else {
        panic!()
    };
    let radiance = light.map.le(Vec3::Z);
    assert!(
        (radiance - Vec3::ONE).abs().max_element() < 1e-6,
        "{radiance}"
    );
    let w: Vec<String> = r.warnings.iter().map(|w| w.to_string()).collect();
    assert!(w.iter().any(|w| w.contains("scale")), "{w:?}");
}
