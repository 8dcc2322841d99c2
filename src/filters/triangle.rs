//! `triangle`: weight falling linearly to zero at the radius (pbrt-v3's
//! src/filters/triangle.cpp).
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `xwidth`, `ywidth` | float | 2 | radius per axis |

use super::{radius, widths, Filter, FilterKind};
use crate::scene::{ParamSpec, Support};
use glam::Vec2;

const DEFAULT_RADIUS: f32 = 2.0;
const W: [ParamSpec; 2] = widths(DEFAULT_RADIUS);
pub const PARAMS: &[ParamSpec] = &[W[0], W[1]];

pub const KIND: FilterKind = FilterKind {
    name: "triangle",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "a tent falling linearly to zero at the radius",
    build: |p, r| {
        Filter::Triangle(Triangle {
            radius: radius(p, DEFAULT_RADIUS, r),
        })
    },
};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    pub radius: Vec2,
}

impl Triangle {
    #[inline]
    pub fn evaluate(&self, p: Vec2) -> f32 {
        (self.radius.x - p.x.abs()).max(0.0) * (self.radius.y - p.y.abs()).max(0.0)
    }

    pub fn describe(&self) -> String {
        format!("triangle, radius {} {}", self.radius.x, self.radius.y)
    }
}
