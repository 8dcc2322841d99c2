//! BVH build cost on degenerate input: coincident triangles (one triangle
//! indexed again and again) build with a counted work within a small
//! multiple of n·log2(n), where PLOC's n·k degradation would exceed it by far;
//! the result still finds the right hits.

mod common;

use common::*;
use pbrs::integrators::RenderScene;

fn coincident_scene(n: usize, extra: &str) -> String {
    let idx = "0 1 2 ".repeat(n);
    format!(
        r#"LookAt 0 0 5 0 0 0 0 1 0
Camera "perspective" "float fov" 30
Film "image" "integer xresolution" 16 "integer yresolution" 16 "string filename" "x.exr"
Sampler "halton" "integer pixelsamples" 1
WorldBegin
LightSource "point" "point from" [0 0 5] "rgb I" [10 10 10]
Material "matte"
Shape "trianglemesh" "point P" [-1 -1 0 1 -1 0 0 1 0] "integer indices" [{idx}]
{extra}
WorldEnd
"#
    )
}

fn log2(n: usize) -> f64 {
    (n as f64).log2()
}

#[test]
fn coincident_triangles_build_in_n_log_n_work() {
    let mut per = Vec::new();
    for n in [5_000usize, 20_000, 80_000] {
        let l = load_text(&coincident_scene(n, ""));
        let scene = RenderScene::new(&l.scene);
        let w = scene.aggregate.build_work;
        assert!(w.bounded, "{n}: the bounded builder should be used");
        assert_eq!(w.largest_coincident, n);
        let bound = 12.0 * n as f64 * log2(n);
        // PLOC on coincident boxes makes n passes over n nodes: n²/2.
        assert!(
            (w.work as f64) < bound && (w.work as f64) < (n * n) as f64 / 100.0,
            "{n} coincident triangles: work {} (bound {bound})",
            w.work
        );
        per.push(w.work as f64 / (n as f64 * log2(n)));
    }
    // Work per n·log n does not grow with n (a quadratic build would 4× a step).
    assert!(per[2] < 1.5 * per[0], "work / (n log n): {per:?}");
}

#[test]
fn a_few_coincident_copies_keep_ploc_and_all_scenes_render() {
    // Two copies of a triangle: PLOC as before.
    let l = load_text(&coincident_scene(2, ""));
    let scene = RenderScene::new(&l.scene);
    assert!(!scene.aggregate.build_work.bounded);
    // Coincident plus collinear slivers and a huge triangle: the render sees
    // the coincident triangle where it is (the centre pixel is lit).
    let mut extra = String::from("Shape \"trianglemesh\" \"point P\" [");
    for i in 0..200 {
        let x = i as f32 * 0.01;
        extra += &format!("{x} 5 -3 {} 5 -3 {} 5.0001 -3 ", x + 0.01, x + 0.02);
    }
    extra += "] \"integer indices\" [";
    for i in 0..200 {
        extra += &format!("{} {} {} ", 3 * i, 3 * i + 1, 3 * i + 2);
    }
    extra += "]\nShape \"trianglemesh\" \"point P\" [-1e7 -1e7 -1e6 1e7 -1e7 -1e6 0 1e7 -1e6] \"integer indices\" [0 1 2]\n";
    let l = load_text(&coincident_scene(3000, &extra));
    let (img, _) = render_at(l.scene, 16, 1, None);
    let centre = img.pixel(8, 8);
    assert!(centre.x > 0.0, "centre pixel {centre:?}");
}

/// The memory budget names the amount and what needs it, and lets through
/// what fits.
#[test]
fn memory_budget_names_the_amount() {
    use pbrs::scene::memory::{available_memory_bytes, check_budget};
    if available_memory_bytes().is_none() {
        return; // not Linux: no budget known
    }
    let e = check_budget("the mesh's 1e12 vertices", 1 << 50).unwrap_err();
    assert!(
        e.contains("the mesh's 1e12 vertices needs 1048576.0 GiB") && e.contains("available"),
        "{e}"
    );
    assert!(check_budget("a small thing", 1 << 20).is_ok());
}
