//! The Cornell box (scenes/cornell-path.pbrt at 128×128, 64 spp) with each
//! of pbrt-v3's Sobol', (0,2)-sequence and max-min-distance samplers: the
//! relative MSE against the converged reference within 1.25× pbrt-v3's own
//! with the same sampler (scenes/references/cornell-path-SAMPLER-128-64.pfm,
//! rendered by pbrt-v3), the image mean within 1%; and the pixel samplers'
//! images the same for any thread count.

mod common;

use common::*;
use pbrs::image::compare::compare;
use pbrs::render::driver::{render, RenderOptions};
use pbrs::scene::SamplerKind;

fn with_sampler(kind: SamplerKind) -> pbrs::scene::SceneDescription {
    let mut d = load("scenes/cornell-path.pbrt");
    d.sampler.kind = kind;
    d
}

#[test]
fn cornell_box_noise_matches_pbrt_v3s_with_the_same_sampler() {
    let converged = reference("cornell-path");
    let mut report = Vec::new();
    let mut failed = Vec::new();
    for (name, kind) in [
        ("sobol", SamplerKind::Sobol),
        ("02sequence", SamplerKind::ZeroTwoSequence { dimensions: 4 }),
        ("maxmindist", SamplerKind::MaxMinDist { dimensions: 4 }),
    ] {
        let pbrt = compare(&pbrt_64(&format!("cornell-path-{name}")), &converged);
        let (img, stats) = render_seeded_wh(with_sampler(kind), 128, 128, 64, 0);
        assert_eq!(stats.dropped_samples(), 0);
        let ours = compare(&img, &converged);
        let ratio = ours.relative_mse / pbrt.relative_mse;
        report.push(format!(
            "{name}: relative MSE {:.5} (pbrt-v3 {:.5}, ratio {ratio:.3}), block error {:.5} (pbrt-v3 {:.5})",
            ours.relative_mse, pbrt.relative_mse, ours.block_error, pbrt.block_error
        ));
        let bounds = Bounds {
            max_relative_mse: 1.25 * pbrt.relative_mse,
            max_block_error: 2.0 * pbrt.block_error,
            max_mean_difference: 0.01,
        };
        if !within(&img, &converged, bounds) {
            failed.push(name);
            assert_matches(&format!("cornell-path-{name}"), &img, &converged, bounds);
        }
    }
    println!("{}", report.join("\n"));
    assert!(failed.is_empty(), "{failed:?}\n{}", report.join("\n"));
}

/// The pixel samplers replay pbrt-v3's tile RNG: one thread or two, the
/// same bytes.
#[test]
fn pixel_sampler_images_do_not_depend_on_threads() {
    for kind in [
        SamplerKind::ZeroTwoSequence { dimensions: 4 },
        SamplerKind::MaxMinDist { dimensions: 2 },
    ] {
        let mut d = with_sampler(kind);
        d.film.xresolution = 40;
        d.film.yresolution = 36;
        d.sampler.pixel_samples = 4;
        let run = |threads| {
            render(
                &d,
                &RenderOptions {
                    threads: Some(threads),
                    ..Default::default()
                },
                &|_, _| {},
            )
            .unwrap()
            .0
        };
        let (a, b) = (run(1), run(2));
        assert_eq!(a.data, b.data, "{kind:?}");
    }
}
