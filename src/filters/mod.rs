//! Pixel reconstruction filters, as pbrt-v3 has them (src/filters/*.cpp):
//! one file per kind, each opening with its parameters, and one table,
//! [`FILTERS`], that the loader (parsing, "did you mean"), `--check`,
//! `grammar/REFERENCE.md` and the tests read. [`Filter`] is the closed set;
//! it only delegates to the files.
//!
//! A filter's `radius` is pbrt's `xwidth`/`ywidth` (a half-width);
//! `evaluate` is only meaningful for `|p| <= radius` (the film never asks
//! outside).

mod r#box;
mod gaussian;
mod mitchell;
mod sinc;
mod triangle;

pub use gaussian::Gaussian;
pub use mitchell::Mitchell;
pub use r#box::BoxFilter;
pub use sinc::LanczosSinc;
pub use triangle::Triangle;

use crate::scene::{Kind, ParamSpec, ParamValues, Report};
use glam::Vec2;

/// What a filter kind builds from its parameters.
pub type FilterBuild = fn(&ParamValues, &mut dyn Report) -> Filter;

/// One filter kind: its pbrt-v3 name, its parameters, its builder.
pub type FilterKind = Kind<FilterBuild>;

/// Every filter pbrt-v3's `MakeFilter` knows (an unknown one is fatal
/// there, and an error here).
pub static FILTERS: &[FilterKind] = &[
    r#box::KIND,
    gaussian::KIND,
    mitchell::KIND,
    sinc::KIND,
    triangle::KIND,
];

macro_rules! filters {
    ($($(#[$doc:meta])* $variant:ident($ty:ty),)*) => {
        /// A filter ready to weigh samples; each variant is one file of
        /// this module.
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub enum Filter {
            $($(#[$doc])* $variant($ty),)*
        }
        $(impl From<$ty> for Filter {
            fn from(f: $ty) -> Filter {
                Filter::$variant(f)
            }
        })*
        impl Filter {
            /// The radius per axis (pbrt's `xwidth`, `ywidth`).
            #[inline]
            pub fn radius(&self) -> Vec2 {
                match self { $(Filter::$variant(f) => f.radius,)* }
            }
            /// The filter's value at offset `p` from the pixel centre.
            #[inline]
            pub fn evaluate(&self, p: Vec2) -> f32 {
                match self { $(Filter::$variant(f) => f.evaluate(p),)* }
            }
            /// Its kind and parameters, for `--check`, `--stats` and the
            /// settings a farm part records.
            pub fn describe(&self) -> String {
                match self { $(Filter::$variant(f) => f.describe(),)* }
            }
        }
    };
}

filters! {
    Box(BoxFilter),
    Gaussian(Gaussian),
    Mitchell(Mitchell),
    LanczosSinc(LanczosSinc),
    Triangle(Triangle),
}

impl Default for Filter {
    /// pbrt-v3's filter when the scene names none: a box of radius 0.5.
    fn default() -> Filter {
        Filter::Box(BoxFilter {
            radius: Vec2::splat(0.5),
        })
    }
}

/// `xwidth` and `ywidth` with a kind's default radius (a line of its
/// parameter table each).
const fn widths(default: f32) -> [ParamSpec; 2] {
    [
        ParamSpec::float("xwidth", default, "radius in x (pbrt's name; a half-width)"),
        ParamSpec::float("ywidth", default, "radius in y"),
    ]
}

/// The radius every kind reads: both widths positive and finite, as
/// pbrt-v3 requires; otherwise an error, and the kind's default.
fn radius(p: &ParamValues, default: f32, report: &mut dyn Report) -> Vec2 {
    let r = Vec2::new(p.float("xwidth"), p.float("ywidth"));
    if r.x > 0.0 && r.y > 0.0 && r.is_finite() {
        return r;
    }
    let at = if r.x > 0.0 && r.x.is_finite() {
        "ywidth"
    } else {
        "xwidth"
    };
    report.error(
        Some(at),
        format!("filter width {} {} must be positive", r.x, r.y),
        "bad filter width",
    );
    Vec2::splat(default)
}
