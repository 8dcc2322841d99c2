//! The render core against pbrt-v3: Cornell-box scenes at 128×128 and 64 spp
//! match their converged pbrt-v3 references within the noise pbrt-v3 itself
//! has at 64 spp (relative MSE ≤ 1.5×, block error ≤ 2×, means within 1%).

mod common;
use common::*;

fn check(scene: &str, stem: &str) {
    let (img, stats) = render_at(load(scene), 128, 64, None);
    assert_eq!(stats.dropped_samples(), 0, "NaN/Inf/negative samples");
    assert_matches(stem, &img, &reference(stem), Bounds::against_pbrt(stem));
}

#[test]
fn cornell_path_matches_pbrt() {
    check("scenes/cornell-path.pbrt", "cornell-path");
}

#[test]
fn cornell_glass_matches_pbrt() {
    check("scenes/cornell-glass.pbrt", "cornell-glass");
}

#[test]
fn bitterli_cornell_box_matches_pbrt() {
    check("scenes/cornell-box.pbrt", "bitterli-cornell-box");
}

#[test]
fn cornell_dragon_matches_pbrt() {
    check("scenes/cornell-dragon.pbrt", "dezeming-cornell-dragon");
}
