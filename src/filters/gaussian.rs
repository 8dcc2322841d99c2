//! `gaussian`: a Gaussian falling to zero at the radius (pbrt-v3's
//! src/filters/gaussian.cpp: `exp(-alpha d²)` minus its value at the
//! radius, per axis, clamped at 0).
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `xwidth`, `ywidth` | float | 2 | radius per axis |
//! | `alpha` | float | 2 | falloff rate |

use super::{radius, widths, Filter, FilterKind};
use crate::scene::{ParamSpec, Support};
use glam::Vec2;

const DEFAULT_RADIUS: f32 = 2.0;
const W: [ParamSpec; 2] = widths(DEFAULT_RADIUS);
pub const PARAMS: &[ParamSpec] = &[
    W[0],
    W[1],
    ParamSpec::float("alpha", 2.0, "falloff rate of exp(-alpha d²)"),
];

pub const KIND: FilterKind = FilterKind {
    name: "gaussian",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "a Gaussian shifted to reach zero at the radius",
    build: |p, r| {
        Filter::Gaussian(Gaussian::new(
            radius(p, DEFAULT_RADIUS, r),
            p.float("alpha"),
        ))
    },
};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gaussian {
    pub radius: Vec2,
    pub alpha: f32,
    /// `exp(-alpha r²)` per axis, subtracted so the filter reaches 0 at the radius.
    pub exp: Vec2,
}

#[inline]
fn gaussian(d: f32, alpha: f32, expv: f32) -> f32 {
    ((-alpha * d * d).exp() - expv).max(0.0)
}

impl Gaussian {
    pub fn new(radius: Vec2, alpha: f32) -> Gaussian {
        Gaussian {
            radius,
            alpha,
            exp: Vec2::new(
                (-alpha * radius.x * radius.x).exp(),
                (-alpha * radius.y * radius.y).exp(),
            ),
        }
    }

    #[inline]
    pub fn evaluate(&self, p: Vec2) -> f32 {
        gaussian(p.x, self.alpha, self.exp.x) * gaussian(p.y, self.alpha, self.exp.y)
    }

    pub fn describe(&self) -> String {
        format!(
            "gaussian, radius {} {}, alpha {}",
            self.radius.x, self.radius.y, self.alpha
        )
    }
}
