//! Reconstruction filters with pbrt-v3's formulas (filters/*.cpp). `radius`
//! is pbrt's `xwidth`/`ywidth` (a half-width); `evaluate` is only meaningful
//! for `|p| <= radius` (the film never asks outside).

use crate::scene::FilterDesc;
use glam::Vec2;
use std::f32::consts::PI;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Filter {
    Box {
        radius: Vec2,
    },
    Gaussian {
        radius: Vec2,
        alpha: f32,
        /// `exp(-alpha r^2)` per axis, subtracted so the filter reaches 0 at the radius.
        exp: Vec2,
    },
    Triangle {
        radius: Vec2,
    },
    Mitchell {
        radius: Vec2,
        b: f32,
        c: f32,
    },
    LanczosSinc {
        radius: Vec2,
        tau: f32,
    },
}

#[inline]
fn gaussian(d: f32, alpha: f32, expv: f32) -> f32 {
    ((-alpha * d * d).exp() - expv).max(0.0)
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

impl Filter {
    pub fn new(desc: &FilterDesc) -> Filter {
        match *desc {
            FilterDesc::Box { radius } => Filter::Box { radius },
            FilterDesc::Gaussian { radius, alpha } => Filter::Gaussian {
                radius,
                alpha,
                exp: Vec2::new(
                    (-alpha * radius.x * radius.x).exp(),
                    (-alpha * radius.y * radius.y).exp(),
                ),
            },
            FilterDesc::Triangle { radius } => Filter::Triangle { radius },
            FilterDesc::Mitchell { radius, b, c } => Filter::Mitchell { radius, b, c },
            FilterDesc::LanczosSinc { radius, tau } => Filter::LanczosSinc { radius, tau },
        }
    }

    #[inline]
    pub fn radius(&self) -> Vec2 {
        match *self {
            Filter::Box { radius }
            | Filter::Gaussian { radius, .. }
            | Filter::Triangle { radius }
            | Filter::Mitchell { radius, .. }
            | Filter::LanczosSinc { radius, .. } => radius,
        }
    }

    /// Filter value at offset `p` from the pixel centre.
    #[inline]
    pub fn evaluate(&self, p: Vec2) -> f32 {
        match *self {
            Filter::Box { .. } => 1.0,
            Filter::Gaussian { alpha, exp, .. } => {
                gaussian(p.x, alpha, exp.x) * gaussian(p.y, alpha, exp.y)
            }
            Filter::Triangle { radius } => {
                (radius.x - p.x.abs()).max(0.0) * (radius.y - p.y.abs()).max(0.0)
            }
            Filter::Mitchell { radius, b, c } => {
                mitchell_1d(2.0 * p.x / radius.x, b, c) * mitchell_1d(2.0 * p.y / radius.y, b, c)
            }
            Filter::LanczosSinc { radius, tau } => {
                windowed_sinc(p.x, radius.x, tau) * windowed_sinc(p.y, radius.y, tau)
            }
        }
    }
}
