//! Textures, bump mapping and alpha cutouts against pbrt-v3 itself: each
//! case of `tests/inputs/textures-pbrt/cases.txt` rendered by pbrs and
//! compared pixel by pixel with pbrt-v3's render of the same file (see
//! that folder's README: one sample at each pixel centre, a distant light,
//! so a pixel is a texture value times a cosine, without noise).

use pbrs::image::io::read_image;
use pbrs::loader::load_scene_str;
use pbrs::render::driver::{render, RenderOptions};
use std::path::PathBuf;

const QUAD: &str = "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] \"point P\" [-3 -3 0 3 -3 0 3 3 0 -3 3 0] \"point2 uv\" [0 0 1 0 1 1 0 1]";

fn dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/inputs/textures-pbrt")
}

#[test]
fn renders_agree_with_pbrt_v3() {
    let template = std::fs::read_to_string(dir().join("template.pbrt")).unwrap();
    let cases = std::fs::read_to_string(dir().join("cases.txt")).unwrap();
    let kd = format!("Material \"matte\" \"texture Kd\" \"t\"\n{QUAD}");
    let mut failures = Vec::new();
    let mut n = 0;
    for line in cases.lines() {
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let mut parts = line.splitn(3, '|');
        let (name, fov, world) = (
            parts.next().unwrap(),
            parts.next().unwrap(),
            parts.next().unwrap(),
        );
        let world = world
            .replace("\\n", "\n")
            .replace("KD", &kd)
            .replace("QUAD", QUAD);
        let text = template
            .replace("FOV", fov)
            .replace("WORLD", &world)
            .replace("OUT", "unused.pfm");
        let scene = load_scene_str(&text, &dir().join(format!("{name}.pbrt")))
            .unwrap_or_else(|f| panic!("{name}: {:?}", f.errors));
        assert!(scene.warnings.is_empty(), "{name}: {:?}", scene.warnings);
        let (img, _) = render(&scene.scene, &RenderOptions::default(), &|_, _| {}).unwrap();
        let reference = read_image(&dir().join(format!("{name}.pfm"))).unwrap();
        assert_eq!((img.width, img.height), (reference.width, reference.height));
        // Float rounding differs (camera rays, transforms, the order of the
        // shading products); where a texture is discontinuous (check and dot
        // edges, the seams of wrapped coordinates) a pixel centre may fall
        // on either side, so a few pixels may differ outright.
        let far = img
            .data
            .iter()
            .zip(&reference.data)
            .filter(|(a, b)| (*a - *b).abs() > 1e-4 * b.abs().max(0.01))
            .count();
        let mean = |d: &[f32]| d.iter().map(|&v| v as f64).sum::<f64>() / d.len() as f64;
        let (ma, mb) = (mean(&img.data), mean(&reference.data));
        if far * 100 > img.data.len() || (ma - mb).abs() > 2e-3 * mb.abs().max(0.01) {
            failures.push(format!(
                "{name}: {far} of {} channels differ, mean {ma} vs pbrt-v3 {mb}",
                img.data.len()
            ));
        }
        n += 1;
    }
    assert!(n >= 17, "{n} cases");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
