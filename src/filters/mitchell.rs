//! `mitchell`: Mitchell and Netravali's cubic (pbrt-v3's
//! src/filters/mitchell.cpp), with negative lobes.
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `xwidth`, `ywidth` | float | 2 | radius per axis |
//! | `B`, `C` | float | 1/3 | the cubic's parameters |

use super::{radius, widths, Filter, FilterKind};
use crate::scene::{ParamSpec, Support};
use glam::Vec2;

const DEFAULT_RADIUS: f32 = 2.0;
const W: [ParamSpec; 2] = widths(DEFAULT_RADIUS);
pub const PARAMS: &[ParamSpec] = &[
    W[0],
    W[1],
    ParamSpec::float("B", 1.0 / 3.0, "the cubic's B"),
    ParamSpec::float("C", 1.0 / 3.0, "the cubic's C"),
];

pub const KIND: FilterKind = FilterKind {
    name: "mitchell",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "Mitchell–Netravali cubic (negative lobes)",
    build: |p, r| {
        Filter::Mitchell(Mitchell {
            radius: radius(p, DEFAULT_RADIUS, r),
            b: p.float("B"),
            c: p.float("C"),
        })
    },
};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mitchell {
    pub radius: Vec2,
    pub b: f32,
    pub c: f32,
}

#[inline]
fn mitchell_1d(x: f32, b: f32, c: f32) -> f32 {
    let x = x.abs();
    if x > 1.0 {
        ((-b - 6.0 * c) * x * x * x
            + (6.0 * b + 30.0 * c) * x * x
            + (-12.0 * b - 48.0 * c) * x
            + (8.0 * b + 24.0 * c))
            * (1.0 / 6.0)
    } else {
        ((12.0 - 9.0 * b - 6.0 * c) * x * x * x
            + (-18.0 + 12.0 * b + 6.0 * c) * x * x
            + (6.0 - 2.0 * b))
            * (1.0 / 6.0)
    }
}

impl Mitchell {
    #[inline]
    pub fn evaluate(&self, p: Vec2) -> f32 {
        mitchell_1d(2.0 * p.x / self.radius.x, self.b, self.c)
            * mitchell_1d(2.0 * p.y / self.radius.y, self.b, self.c)
    }

    pub fn describe(&self) -> String {
        format!(
            "mitchell, radius {} {}, B {}, C {}",
            self.radius.x, self.radius.y, self.b, self.c
        )
    }
}
