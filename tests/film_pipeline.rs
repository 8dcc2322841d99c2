//! Samplers and film together, as the renderer uses them: tiles rendered in
//! parallel with one sampler clone each, merged in order.

use glam::{Vec2, Vec3};
use pbrs::filters::{BoxFilter, Filter, Gaussian};
use pbrs::image::Image;
use pbrs::render::film::Film;
use pbrs::samplers::Sampler;
use pbrs::scene::{FilmDesc, SamplerDesc, SamplerKind};
use rayon::prelude::*;

fn film_desc(w: u32, h: u32) -> FilmDesc {
    FilmDesc {
        xresolution: w,
        yresolution: h,
        cropwindow: [0.0, 1.0, 0.0, 1.0],
        filename: "out.pfm".into(),
        scale: 1.0,
        max_sample_luminance: f32::INFINITY,
        diagonal: 35.0,
    }
}

/// A smooth test image with a closed-form integral.
fn f(p: Vec2) -> Vec3 {
    let s = (p.x * 0.3).sin() * (p.y * 0.2).cos();
    Vec3::new(1.0 + s, 0.5 + 0.25 * s, 0.1 * p.x)
}

/// Exact mean of `f` over pixel (x, y).
fn pixel_mean(x: i32, y: i32) -> Vec3 {
    let (x0, x1, y0, y1) = (x as f64, x as f64 + 1.0, y as f64, y as f64 + 1.0);
    let ix = (-(0.3 * x1).cos() + (0.3 * x0).cos()) / 0.3;
    let iy = ((0.2 * y1).sin() - (0.2 * y0).sin()) / 0.2;
    let s = ix * iy;
    Vec3::new(
        (1.0 + s) as f32,
        (0.5 + 0.25 * s) as f32,
        (0.1 * (x0 + 0.5)) as f32,
    )
}

fn render(kind: SamplerKind, spp: u32, filter: Filter, threads: usize) -> Image {
    let mut film = Film::new(&film_desc(40, 30), &filter);
    let desc = SamplerDesc {
        kind,
        pixel_samples: spp,
        sample_pixel_center: false,
    };
    let proto = Sampler::new(&desc, film.sample_bounds(), 0);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let tiles = pool.install(|| {
        film.tiles(16)
            .par_iter()
            .map(|&tb| {
                let mut sampler = proto.clone();
                let mut tile = film.tile(tb);
                for p in tb.iter() {
                    for i in 0..sampler.samples_per_pixel() {
                        sampler.start_pixel_sample(p, i);
                        let cs = sampler.get_camera_sample(p);
                        // Some integrator-like use of more dimensions.
                        let _ = (sampler.get_2d(), sampler.get_1d());
                        tile.add_sample(cs.p_film, f(cs.p_film), 1.0);
                    }
                }
                tile
            })
            .collect::<Vec<_>>()
    });
    for t in tiles {
        film.merge_tile(t);
    }
    film.image()
}

/// (max, rms) error against the exact pixel means.
fn errors(img: &Image) -> (f32, f64) {
    let (mut max_err, mut sq) = (0.0f32, 0.0f64);
    for y in 0..30 {
        for x in 0..40 {
            let d = img.pixel(x as u32, y as u32) - pixel_mean(x, y);
            max_err = max_err.max(d.abs().max_element());
            sq += d.length_squared() as f64 / 3.0;
        }
    }
    (max_err, (sq / 1200.0).sqrt())
}

#[test]
fn box_filtered_image_converges_to_pixel_means() {
    let box_filter = Filter::Box(BoxFilter {
        radius: Vec2::splat(0.5),
    });
    let (h_max, h_rms) = errors(&render(SamplerKind::Halton, 64, box_filter, 2));
    let (r_max, r_rms) = errors(&render(SamplerKind::Random, 64, box_filter, 2));
    println!("64 spp: Halton max {h_max:.5} rms {h_rms:.6}; Random max {r_max:.5} rms {r_rms:.6}");
    assert!(h_max < 5e-3, "Halton max error {h_max}");
    assert!(r_max < 5e-2, "Random max error {r_max}");
    // Quasi-Monte Carlo beats Monte Carlo clearly on a smooth integrand.
    assert!(
        h_rms < 0.5 * r_rms,
        "Halton rms {h_rms} vs Random rms {r_rms}"
    );
}

#[test]
fn images_are_bit_identical_for_any_thread_count() {
    for kind in [
        SamplerKind::Halton,
        SamplerKind::Random,
        SamplerKind::Stratified {
            jitter: true,
            xsamples: 2,
            ysamples: 4,
        },
    ] {
        let filter = Filter::Gaussian(Gaussian::new(Vec2::splat(2.0), 2.0));
        let a = render(kind, 8, filter, 1);
        let b = render(kind, 8, filter, 2);
        let c = render(kind, 8, filter, 3);
        assert_eq!(a.data, b.data, "{kind:?}");
        assert_eq!(a.data, c.data, "{kind:?}");
        // And the image is close to the function.
        let p = a.pixel(20, 15);
        assert!(
            (p - pixel_mean(20, 15)).abs().max_element() < 0.1,
            "{kind:?}: {p}"
        );
    }
}
