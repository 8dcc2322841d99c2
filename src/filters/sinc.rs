//! `sinc`: a sinc windowed by a Lanczos sinc (pbrt-v3's
//! src/filters/sinc.cpp, `LanczosSincFilter`).
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `xwidth`, `ywidth` | float | 4 | radius per axis |
//! | `tau` | float | 3 | lobes of the window |

use super::{radius, widths, Filter, FilterKind};
use crate::scene::{ParamSpec, Support};
use glam::Vec2;
use std::f32::consts::PI;

const DEFAULT_RADIUS: f32 = 4.0;
const W: [ParamSpec; 2] = widths(DEFAULT_RADIUS);
pub const PARAMS: &[ParamSpec] = &[
    W[0],
    W[1],
    ParamSpec::float("tau", 3.0, "the Lanczos window's number of lobes"),
];

pub const KIND: FilterKind = FilterKind {
    name: "sinc",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "a Lanczos-windowed sinc (negative lobes)",
    build: |p, r| {
        Filter::LanczosSinc(LanczosSinc {
            radius: radius(p, DEFAULT_RADIUS, r),
            tau: p.float("tau"),
        })
    },
};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LanczosSinc {
    pub radius: Vec2,
    pub tau: f32,
}

#[inline]
fn sinc(x: f32) -> f32 {
    let x = x.abs();
    if x < 1e-5 {
        1.0
    } else {
        (PI * x).sin() / (PI * x)
    }
}

#[inline]
fn windowed_sinc(x: f32, radius: f32, tau: f32) -> f32 {
    let x = x.abs();
    if x > radius {
        0.0
    } else {
        sinc(x) * sinc(x / tau)
    }
}

impl LanczosSinc {
    #[inline]
    pub fn evaluate(&self, p: Vec2) -> f32 {
        windowed_sinc(p.x, self.radius.x, self.tau) * windowed_sinc(p.y, self.radius.y, self.tau)
    }

    pub fn describe(&self) -> String {
        format!(
            "sinc, radius {} {}, tau {}",
            self.radius.x, self.radius.y, self.tau
        )
    }
}
