//! `box`: every sample within the radius weighs the same (pbrt-v3's
//! default filter, src/filters/box.cpp).
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `xwidth`, `ywidth` | float | 0.5 | radius per axis |

use super::{radius, widths, Filter, FilterKind};
use crate::scene::{ParamSpec, Support};
use glam::Vec2;

const DEFAULT_RADIUS: f32 = 0.5;
const W: [ParamSpec; 2] = widths(DEFAULT_RADIUS);
pub const PARAMS: &[ParamSpec] = &[W[0], W[1]];

pub const KIND: FilterKind = FilterKind {
    name: "box",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "equal weight within the radius",
    build: |p, r| {
        Filter::Box(BoxFilter {
            radius: radius(p, DEFAULT_RADIUS, r),
        })
    },
};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoxFilter {
    pub radius: Vec2,
}

impl BoxFilter {
    #[inline]
    pub fn evaluate(&self, _: Vec2) -> f32 {
        1.0
    }

    pub fn describe(&self) -> String {
        format!("box, radius {} {}", self.radius.x, self.radius.y)
    }
}
