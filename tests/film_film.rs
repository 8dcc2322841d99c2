//! Filters, film bounds, tiles and sample accumulation.

use glam::{IVec2, Vec2, Vec3};
use pbrs::filters::{BoxFilter, Filter, Gaussian, LanczosSinc, Mitchell, Triangle};
use pbrs::geometry::Bounds2i;
use pbrs::render::film::{luminance, Film, FILTER_TABLE_WIDTH};
use pbrs::sampling::Pcg32;
use pbrs::scene::FilmDesc;
use rayon::prelude::*;

fn film_desc(w: u32, h: u32, crop: [f32; 4]) -> FilmDesc {
    FilmDesc {
        xresolution: w,
        yresolution: h,
        cropwindow: crop,
        filename: "out.exr".into(),
        scale: 1.0,
        max_sample_luminance: f32::INFINITY,
        diagonal: 35.0,
    }
}

const FULL: [f32; 4] = [0.0, 1.0, 0.0, 1.0];

fn all_filters() -> Vec<Filter> {
    vec![
        Filter::Box(BoxFilter {
            radius: Vec2::splat(0.5),
        }),
        Filter::Box(BoxFilter {
            radius: Vec2::new(1.0, 0.75),
        }),
        Filter::Gaussian(Gaussian::new(Vec2::splat(2.0), 2.0)),
        Filter::Triangle(Triangle {
            radius: Vec2::splat(2.0),
        }),
        Filter::Mitchell(Mitchell {
            radius: Vec2::splat(2.0),
            b: 1.0 / 3.0,
            c: 1.0 / 3.0,
        }),
        Filter::LanczosSinc(LanczosSinc {
            radius: Vec2::splat(4.0),
            tau: 3.0,
        }),
    ]
}

/// ∫∫ filter over its support (midpoint rule).
fn integral(f: &Filter) -> f64 {
    let r = f.radius();
    let n = 400;
    let mut s = 0.0f64;
    for j in 0..n {
        for i in 0..n {
            let p = Vec2::new(
                -r.x + 2.0 * r.x * (i as f32 + 0.5) / n as f32,
                -r.y + 2.0 * r.y * (j as f32 + 0.5) / n as f32,
            );
            s += f.evaluate(p) as f64;
        }
    }
    s * (4.0 * r.x as f64 * r.y as f64) / (n * n) as f64
}

#[test]
fn filter_values_and_integrals() {
    let b = Filter::Box(BoxFilter {
        radius: Vec2::new(1.0, 0.5),
    });
    assert_eq!(b.evaluate(Vec2::new(0.9, -0.4)), 1.0);
    assert!((integral(&b) - 2.0).abs() < 1e-6);

    let t = Filter::Triangle(Triangle {
        radius: Vec2::splat(2.0),
    });
    assert_eq!(t.evaluate(Vec2::ZERO), 4.0);
    assert_eq!(t.evaluate(Vec2::new(2.0, 0.0)), 0.0);
    assert!((integral(&t) - 16.0).abs() < 1e-3); // (r²)²

    let g = Filter::Gaussian(Gaussian::new(Vec2::splat(2.0), 2.0));
    let e = (-8.0f32).exp();
    assert!((g.evaluate(Vec2::ZERO) - (1.0 - e) * (1.0 - e)).abs() < 1e-6);
    assert_eq!(g.evaluate(Vec2::new(2.0, 0.0)), 0.0);
    // ≈ π/α for a wide Gaussian, minus the subtracted tail.
    assert!(
        (integral(&g) - std::f64::consts::PI / 2.0).abs() < 0.01,
        "{}",
        integral(&g)
    );

    // Mitchell–Netravali kernels integrate to 1 over [-2, 2] for any B, C;
    // pbrt scales the argument by 2/radius, so with radius 2 the integral is 1.
    for (bb, cc) in [(1.0 / 3.0, 1.0 / 3.0), (0.0, 0.5), (1.0, 0.0)] {
        let m = Filter::Mitchell(Mitchell {
            radius: Vec2::splat(2.0),
            b: bb,
            c: cc,
        });
        assert!(
            (integral(&m) - 1.0).abs() < 1e-3,
            "B={bb} C={cc}: {}",
            integral(&m)
        );
        assert!(m.evaluate(Vec2::new(2.0, 2.0)).abs() < 1e-6);
    }

    let l = Filter::LanczosSinc(LanczosSinc {
        radius: Vec2::splat(4.0),
        tau: 3.0,
    });
    assert_eq!(l.evaluate(Vec2::ZERO), 1.0);
    assert!(l.evaluate(Vec2::new(1.0, 0.0)).abs() < 1e-6);
    assert_eq!(l.evaluate(Vec2::new(4.5, 0.0)), 0.0);
    assert!((integral(&l) - 1.0).abs() < 0.05, "{}", integral(&l));
}

#[test]
fn filter_table_matches_pbrt_layout() {
    let d = Filter::Triangle(Triangle {
        radius: Vec2::new(2.0, 1.0),
    });
    let film = Film::new(&film_desc(8, 8, FULL), &d);
    let f = d;
    let t = film.filter_table();
    for y in 0..FILTER_TABLE_WIDTH {
        for x in 0..FILTER_TABLE_WIDTH {
            let p = Vec2::new((x as f32 + 0.5) * 2.0 / 16.0, (y as f32 + 0.5) * 1.0 / 16.0);
            assert_eq!(t[y * FILTER_TABLE_WIDTH + x], f.evaluate(p));
        }
    }
}

/// (resolution, crop window, expected pixel bounds)
type CropCase = ((u32, u32), [f32; 4], (IVec2, IVec2));

#[test]
fn crop_window_bounds_match_pbrt() {
    let b = Filter::Box(BoxFilter {
        radius: Vec2::splat(0.5),
    });
    let cases: [CropCase; 5] = [
        ((128, 128), FULL, (IVec2::ZERO, IVec2::new(128, 128))),
        (
            (128, 128),
            [0.25, 0.75, 0.1, 0.9],
            (IVec2::new(32, 13), IVec2::new(96, 116)),
        ),
        (
            (100, 50),
            [0.333, 0.667, 0.0, 1.0],
            (IVec2::new(34, 0), IVec2::new(67, 50)),
        ),
        (
            (640, 480),
            [0.5, 0.5, 0.0, 0.25],
            (IVec2::new(320, 0), IVec2::new(320, 120)),
        ),
        (
            (7, 3),
            [0.1, 0.9, 0.4, 0.6],
            (IVec2::new(1, 2), IVec2::new(7, 2)),
        ),
    ];
    for ((w, h), crop, (min, max)) in cases {
        let film = Film::new(&film_desc(w, h, crop), &b);
        assert_eq!(
            film.pixel_bounds(),
            Bounds2i::new(min, max),
            "{w}x{h} {crop:?}"
        );
        let img = film.image();
        assert_eq!(
            (img.width as i32, img.height as i32),
            ((max - min).x, (max - min).y)
        );
    }
}

#[test]
fn sample_bounds_and_tiles() {
    let box_ = Filter::Box(BoxFilter {
        radius: Vec2::splat(0.5),
    });
    let gauss = Filter::Gaussian(Gaussian::new(Vec2::splat(2.0), 2.0));
    let film = Film::new(&film_desc(128, 128, FULL), &box_);
    assert_eq!(
        film.sample_bounds(),
        Bounds2i::new(IVec2::ZERO, IVec2::new(128, 128))
    );
    let film = Film::new(&film_desc(128, 128, FULL), &gauss);
    assert_eq!(
        film.sample_bounds(),
        Bounds2i::new(IVec2::splat(-2), IVec2::splat(130))
    );
    let film = Film::new(&film_desc(100, 50, [0.333, 0.667, 0.0, 1.0]), &gauss);
    assert_eq!(
        film.sample_bounds(),
        Bounds2i::new(IVec2::new(32, -2), IVec2::new(69, 52))
    );

    let tiles = film.tiles(16);
    let sb = film.sample_bounds();
    assert_eq!(tiles.len(), 3 * 4);
    assert_eq!(
        tiles[0],
        Bounds2i::new(IVec2::new(32, -2), IVec2::new(48, 14))
    );
    assert_eq!(
        tiles[2],
        Bounds2i::new(IVec2::new(64, -2), IVec2::new(69, 14))
    );
    assert_eq!(tiles[3].min, IVec2::new(32, 14));
    // Tiles partition the sample bounds.
    let covered: i64 = tiles.iter().map(|t| t.area()).sum();
    assert_eq!(covered, sb.area());
    for p in sb.iter() {
        assert_eq!(tiles.iter().filter(|t| t.contains(p)).count(), 1);
    }
    // Tile pixel bounds as pbrt-v3's GetFilmTile.
    let t = film.tile(tiles[0]);
    // ceil(32 - 0.5 - 2) = 30 -> clipped to 34; floor(48 - 0.5 + 2) + 1 = 50.
    assert_eq!(
        t.pixel_bounds(),
        Bounds2i::new(IVec2::new(34, 0), IVec2::new(50, 16))
    );
}

fn splat_uniform(
    film: &Film,
    samples_per_pixel: u32,
    l: impl Fn(Vec2) -> Vec3 + Sync,
) -> Vec<pbrs::render::film::FilmTile> {
    film.tiles(16)
        .par_iter()
        .enumerate()
        .map(|(ti, &tb)| {
            let mut tile = film.tile(tb);
            let mut rng = Pcg32::with_sequence(ti as u64);
            for p in tb.iter() {
                for _ in 0..samples_per_pixel {
                    let pf = p.as_vec2() + Vec2::new(rng.uniform_f32(), rng.uniform_f32());
                    tile.add_sample(pf, l(pf), 1.0);
                }
            }
            tile
        })
        .collect()
}

#[test]
fn constant_radiance_is_reproduced_by_every_filter() {
    let c = Vec3::new(0.3, 0.5, 0.7);
    for fd in all_filters() {
        let mut film = Film::new(&film_desc(40, 24, [0.1, 0.95, 0.0, 1.0]), &fd);
        for tile in splat_uniform(&film, 16, |_| c) {
            film.merge_tile(tile);
        }
        let img = film.image();
        for px in img.data.chunks_exact(3) {
            for (v, e) in px.iter().zip(c.to_array()) {
                assert!((v - e).abs() < 1e-5 * e, "{fd:?}: {v} vs {e}");
            }
        }
    }
}

#[test]
fn box_filter_pixel_is_the_mean_of_its_samples() {
    let mut film = Film::new(
        &film_desc(4, 4, FULL),
        &Filter::Box(BoxFilter {
            radius: Vec2::splat(0.5),
        }),
    );
    let mut tile = film.tile(film.sample_bounds());
    tile.add_sample(Vec2::new(1.2, 2.7), Vec3::new(1.0, 2.0, 3.0), 1.0);
    tile.add_sample(Vec2::new(1.9, 2.1), Vec3::new(3.0, 2.0, 1.0), 1.0);
    tile.add_sample(Vec2::new(1.5, 2.5), Vec3::new(2.0, 2.0, 2.0), 0.5); // sample weight scales L only
    film.merge_tile(tile);
    let img = film.image();
    let p = img.pixel(1, 2);
    assert!(
        (p - Vec3::new(5.0 / 3.0, 5.0 / 3.0, 5.0 / 3.0))
            .abs()
            .max_element()
            < 1e-6,
        "{p}"
    );
    assert_eq!(img.pixel(0, 0), Vec3::ZERO);
    assert_eq!(film.pixel_sums(IVec2::new(1, 2)).weight, 3.0);
}

#[test]
fn add_sample_footprint_and_table_lookup() {
    let fd = Filter::Triangle(Triangle {
        radius: Vec2::splat(2.0),
    });
    let mut film = Film::new(&film_desc(16, 16, FULL), &fd);
    let mut tile = film.tile(film.sample_bounds());
    tile.add_sample(Vec2::new(5.5, 5.5), Vec3::ONE, 1.0);
    let table = *film.filter_table();
    // pDiscrete = 5: pixels 3..8 on each axis (floor(7) + 1 = 8).
    for y in 0..16 {
        for x in 0..16 {
            let w = tile.pixel_sums(IVec2::new(x, y)).weight;
            if (3..8).contains(&x) && (3..8).contains(&y) {
                let ix = (((x - 5) as f32 * 0.5 * 16.0).abs().floor() as usize).min(15);
                let iy = (((y - 5) as f32 * 0.5 * 16.0).abs().floor() as usize).min(15);
                assert_eq!(w, table[iy * 16 + ix] as f64, "({x},{y})");
            } else {
                assert_eq!(w, 0.0, "({x},{y})");
            }
        }
    }
    film.merge_tile(tile);
}

/// A box filter's table is one value, so splats skip the table offsets:
/// every pixel of the footprint (here 3×2, in a tile whose pixels start
/// away from the origin) gets weight 1 and the radiance, no other pixel
/// anything.
#[test]
fn box_footprint_in_an_offset_tile() {
    let fd = Filter::Box(BoxFilter {
        radius: Vec2::new(1.5, 1.0),
    });
    let mut film = Film::new(&film_desc(16, 16, FULL), &fd);
    assert!(film.filter_table().iter().all(|&w| w == 1.0));
    let mut tile = film.tile(Bounds2i::new(IVec2::new(3, 4), IVec2::new(9, 10)));
    let l = Vec3::new(1.0, 2.0, 4.0);
    // pDiscrete = (4.8, 6.3): x in 4..7, y in 6..8.
    tile.add_sample(Vec2::new(5.3, 6.8), l, 0.5);
    let b = tile.pixel_bounds();
    assert!(b.min.x > 0 && b.min.y > 0, "{b:?}");
    for y in b.min.y..b.max.y {
        for x in b.min.x..b.max.x {
            let s = tile.pixel_sums(IVec2::new(x, y));
            if (4..7).contains(&x) && (6..8).contains(&y) {
                assert_eq!(s.weight, 1.0, "({x},{y})");
                assert_eq!(s.contrib, [0.5, 1.0, 2.0], "({x},{y})");
            } else {
                assert_eq!(s.weight, 0.0, "({x},{y})");
                assert_eq!(s.contrib, [0.0; 3], "({x},{y})");
            }
        }
    }
    film.merge_tile(tile);
}

#[test]
fn max_sample_luminance_and_scale() {
    let mut d = film_desc(2, 2, FULL);
    d.max_sample_luminance = 1.0;
    d.scale = 2.0;
    let mut film = Film::new(
        &d,
        &Filter::Box(BoxFilter {
            radius: Vec2::splat(0.5),
        }),
    );
    let mut tile = film.tile(film.sample_bounds());
    let l = Vec3::new(10.0, 5.0, 1.0);
    tile.add_sample(Vec2::new(0.5, 0.5), l, 1.0);
    tile.add_sample(Vec2::new(1.5, 0.5), Vec3::new(0.1, 0.2, 0.3), 1.0);
    tile.add_sample(Vec2::new(0.5, 1.5), Vec3::new(f32::NAN, 1.0, 1.0), 1.0);
    film.merge_tile(tile);
    let img = film.image();
    let clamped = img.pixel(0, 0) / 2.0;
    assert!((luminance(clamped) - 1.0).abs() < 1e-5);
    assert!((clamped.normalize() - l.normalize()).length() < 1e-5);
    assert!((img.pixel(1, 0) - Vec3::new(0.2, 0.4, 0.6)).length() < 1e-6);
    assert_eq!(img.pixel(0, 1), Vec3::ZERO); // NaN radiance counts as black
}

#[test]
fn merging_is_deterministic_across_thread_counts() {
    let fd = Filter::Gaussian(Gaussian::new(Vec2::splat(2.0), 2.0));
    let render = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut film = Film::new(&film_desc(50, 40, FULL), &fd);
            let tiles = splat_uniform(&film, 4, |p| Vec3::new(p.x.sin().abs(), p.y * 0.01, 1.0));
            for t in tiles {
                film.merge_tile(t);
            }
            film.image()
        })
    };
    let a = render(1);
    let b = render(2);
    let c = render(2);
    assert_eq!(a.data, b.data);
    assert_eq!(b.data, c.data);
    // One tile over everything, same samples: same image up to summation order.
    let mut film = Film::new(&film_desc(50, 40, FULL), &fd);
    let mut whole = film.tile(film.sample_bounds());
    for (ti, tb) in film.tiles(16).into_iter().enumerate() {
        let mut rng = Pcg32::with_sequence(ti as u64);
        for p in tb.iter() {
            for _ in 0..4 {
                let pf = p.as_vec2() + Vec2::new(rng.uniform_f32(), rng.uniform_f32());
                whole.add_sample(pf, Vec3::new(pf.x.sin().abs(), pf.y * 0.01, 1.0), 1.0);
            }
        }
    }
    film.merge_tile(whole);
    let d = film.image();
    for (x, y) in a.data.iter().zip(&d.data) {
        assert!((x - y).abs() <= 1e-6 * y.abs().max(1e-3), "{x} vs {y}");
    }
}
