//! Every kind of `filters::FILTERS`, loaded from a scene statement
//! with its default widths and with given ones, evaluated against pbrt-v3's
//! formula written out here independently (src/filters/*.cpp). A kind of the
//! table without a case here fails.

use glam::Vec2;
use pbrs::filters::{Filter, FILTERS};
use pbrs::loader::load_scene_str;
use std::path::Path;

/// pbrt-v3's filter formulas in f64: the value at `p` for radius `r`.
fn reference(name: &str) -> Option<fn(Vec2, Vec2) -> f64> {
    fn gauss(d: f64, r: f64) -> f64 {
        ((-2.0 * d * d).exp() - (-2.0 * r * r).exp()).max(0.0)
    }
    fn mitchell(x: f64) -> f64 {
        let (b, c) = (1.0 / 3.0, 1.0 / 3.0);
        let x = x.abs();
        if x > 1.0 {
            ((-b - 6.0 * c) * x.powi(3)
                + (6.0 * b + 30.0 * c) * x * x
                + (-12.0 * b - 48.0 * c) * x
                + (8.0 * b + 24.0 * c))
                / 6.0
        } else {
            ((12.0 - 9.0 * b - 6.0 * c) * x.powi(3)
                + (-18.0 + 12.0 * b + 6.0 * c) * x * x
                + (6.0 - 2.0 * b))
                / 6.0
        }
    }
    fn sinc(x: f64) -> f64 {
        let x = x.abs();
        if x < 1e-5 {
            1.0
        } else {
            (std::f64::consts::PI * x).sin() / (std::f64::consts::PI * x)
        }
    }
    fn lanczos(x: f64, r: f64) -> f64 {
        if x.abs() > r {
            0.0
        } else {
            sinc(x) * sinc(x / 3.0)
        }
    }
    let f: fn(Vec2, Vec2) -> f64 = match name {
        "box" => |_, _| 1.0,
        "gaussian" => |p, r| gauss(p.x as f64, r.x as f64) * gauss(p.y as f64, r.y as f64),
        "triangle" => |p, r| {
            (r.x as f64 - (p.x as f64).abs()).max(0.0) * (r.y as f64 - (p.y as f64).abs()).max(0.0)
        },
        "mitchell" => {
            |p, r| mitchell(2.0 * p.x as f64 / r.x as f64) * mitchell(2.0 * p.y as f64 / r.y as f64)
        }
        "sinc" => |p, r| lanczos(p.x as f64, r.x as f64) * lanczos(p.y as f64, r.y as f64),
        _ => return None,
    };
    Some(f)
}

fn load(statement: &str) -> Filter {
    let text = format!("{statement}\nWorldBegin\nWorldEnd\n");
    load_scene_str(&text, Path::new("filter.pbrt"))
        .unwrap_or_else(|e| panic!("{statement}: {e:?}"))
        .scene
        .filter
}

#[test]
fn every_filter_kind_matches_pbrt_v3s_formula() {
    for k in FILTERS {
        let f =
            reference(k.name).unwrap_or_else(|| panic!("filter \"{}\" has no test case", k.name));
        let default = k.param("xwidth").map(|s| match s.kind {
            pbrs::scene::ParamKind::Float(d) => d,
            other => panic!("{}: xwidth is {other:?}", k.name),
        });
        let default = default.unwrap_or_else(|| panic!("{}: no xwidth", k.name));
        for (statement, radius) in [
            (format!("PixelFilter \"{}\"", k.name), Vec2::splat(default)),
            (
                format!(
                    "PixelFilter \"{}\" \"float xwidth\" 1.5 \"float ywidth\" 2.5",
                    k.name
                ),
                Vec2::new(1.5, 2.5),
            ),
        ] {
            let filter = load(&statement);
            assert_eq!(filter.radius(), radius, "{statement}");
            for i in 0..=8 {
                for j in 0..=8 {
                    let p = Vec2::new(i as f32 / 8.0, j as f32 / 8.0) * radius;
                    let (got, want) = (filter.evaluate(p) as f64, f(p, radius));
                    assert!(
                        (got - want).abs() <= 1e-5 * want.abs().max(1.0),
                        "{statement} at {p}: {got} against pbrt-v3's {want}"
                    );
                }
            }
            assert!(
                filter.describe().starts_with(k.name),
                "{}",
                filter.describe()
            );
        }
    }
}

#[test]
fn no_filter_statement_is_pbrt_v3s_box() {
    let text = "WorldBegin\nWorldEnd\n";
    let s = load_scene_str(text, Path::new("f.pbrt")).unwrap().scene;
    assert_eq!(s.filter, Filter::default());
    assert_eq!(s.filter.radius(), Vec2::splat(0.5));
}

#[test]
fn bad_filters_are_located_errors() {
    for (statement, what) in [
        (
            "PixelFilter \"gaussian\" \"float xwidth\" -1",
            "filter width -1 2 must be positive",
        ),
        (
            "PixelFilter \"box\" \"float ywidth\" 0",
            "filter width 0.5 0 must be positive",
        ),
        ("PixelFilter \"gausian\"", "did you mean \"gaussian\"?"),
        ("PixelFilter \"lanczos\"", "unknown filter \"lanczos\""),
    ] {
        let text = format!("{statement}\nWorldBegin\nWorldEnd\n");
        let Err(err) = load_scene_str(&text, Path::new("bad.pbrt")) else {
            panic!("{statement}: loaded");
        };
        let msg = format!("{err:?}");
        assert!(msg.contains(what), "{statement}: {msg}");
        assert!(
            msg.contains("bad.pbrt:1:"),
            "{statement}: not located: {msg}"
        );
    }
}
