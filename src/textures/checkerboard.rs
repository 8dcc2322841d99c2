//! `checkerboard`: alternating `tex1` and `tex2` on the unit squares of the
//! 2D mapping's (s, t), or on the unit cubes of the 3D mapping's point.
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `dimension` | integer | 2 | 2 or 3 (else an error: the texture is not defined, as pbrt-v3) |
//! | `tex1` | texture of the texture's type | 1 | where ⌊s⌋ + ⌊t⌋ (+ ⌊z⌋) is even |
//! | `tex2` | texture of the texture's type | 0 | where it is odd |
//! | `aamode` | string | `closedform` | 2D only: `closedform` (box-filtered over the differentials' footprint, pbrt-v3's closed form) or `none` (point sampled) |
//! | mapping | see `mapping.rs` | uv | 2D; 3D uses the statement's transform |

use super::{
    Class, Mapping2D, Mapping3D, MappingUse, Support, TexBuild, TexBuilder, TexValue, Texture,
    TextureClass,
};
use crate::materials::ShadingContext;
use crate::scene::{ParamSpec, Tex};
use glam::Vec2;

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::int("dimension", 2, "2 (squares over (s, t)) or 3 (cubes)"),
    ParamSpec::same_tex("tex1", 1.0, "even squares"),
    ParamSpec::same_tex("tex2", 0.0, "odd squares"),
    ParamSpec::choice(
        "aamode",
        "closedform",
        &["closedform", "none"],
        "2D antialiasing: closed-form box filter or none",
    ),
];

pub const CLASS: TextureClass = TextureClass {
    name: "checkerboard",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "tex1 and tex2 alternating on unit squares (2D) or cubes (3D)",
    build: TexBuild {
        mapping: MappingUse::ByDimension,
        float: Some(build::<f32>),
        spectrum: Some(build::<glam::Vec3>),
    },
};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AaMode {
    None,
    ClosedForm,
}

pub struct Checkerboard2D<T> {
    pub mapping: Mapping2D,
    pub tex1: Tex<T>,
    pub tex2: Tex<T>,
    pub aa: AaMode,
}

pub struct Checkerboard3D<T> {
    pub mapping: Mapping3D,
    pub tex1: Tex<T>,
    pub tex2: Tex<T>,
}

fn build<T: TexValue>(b: &mut TexBuilder) -> Result<Tex<T>, String> {
    let dim = b.params.int("dimension");
    let (tex1, tex2) = (b.tex::<T>("tex1"), b.tex::<T>("tex2"));
    let class = match dim {
        2 => Class::Checkerboard2D(Checkerboard2D {
            mapping: b.mapping2d,
            tex1,
            tex2,
            aa: match b.params.string("aamode") {
                "none" => AaMode::None,
                _ => AaMode::ClosedForm,
            },
        }),
        3 => Class::Checkerboard3D(Checkerboard3D {
            mapping: b.mapping3d,
            tex1,
            tex2,
        }),
        _ => {
            return Err(format!(
                "{dim} dimensional checkerboard texture not supported (as pbrt-v3: \"dimension\" must be 2 or 3)"
            ))
        }
    };
    Ok(Texture::new_handle(b.name, class))
}

/// True where ⌊s⌋ + ⌊t⌋ is even (C++'s `%`, which keeps the sign).
#[inline]
fn even(st: Vec2) -> bool {
    (st.x.floor() as i32).wrapping_add(st.y.floor() as i32) % 2 == 0
}

/// pbrt-v3's integral of the 0/1 square wave of period 2 from 0 to `x`.
#[inline]
fn bump_int(x: f32) -> f32 {
    let h = (x / 2.0).floor() as i32;
    let frac = x / 2.0 - h as f32 - 0.5;
    h as f32 + 2.0 * if frac < 0.0 { 0.0 } else { frac }
}

impl<T: TexValue> Checkerboard2D<T> {
    pub fn eval(&self, sc: &ShadingContext) -> T {
        let (st, dstdx, dstdy) = self.mapping.map(sc);
        let point = || {
            if even(st) {
                self.tex1.eval(sc)
            } else {
                self.tex2.eval(sc)
            }
        };
        if self.aa == AaMode::None {
            return point();
        }
        let ds = max(dstdx.x.abs(), dstdy.x.abs());
        let dt = max(dstdx.y.abs(), dstdy.y.abs());
        let (s0, s1) = (st.x - ds, st.x + ds);
        let (t0, t1) = (st.y - dt, st.y + dt);
        if s0.floor() == s1.floor() && t0.floor() == t1.floor() {
            return point();
        }
        let sint = (bump_int(s1) - bump_int(s0)) / (2.0 * ds);
        let tint = (bump_int(t1) - bump_int(t0)) / (2.0 * dt);
        let mut area2 = sint + tint - 2.0 * sint * tint;
        if ds > 1.0 || dt > 1.0 {
            area2 = 0.5;
        }
        self.tex1
            .eval(sc)
            .scale(1.0 - area2)
            .add(self.tex2.eval(sc).scale(area2))
    }
}

impl<T: TexValue> Checkerboard3D<T> {
    pub fn eval(&self, sc: &ShadingContext) -> T {
        let (p, _, _) = self.mapping.map(sc);
        let sum = (p.x.floor() as i32)
            .wrapping_add(p.y.floor() as i32)
            .wrapping_add(p.z.floor() as i32);
        if sum % 2 == 0 {
            self.tex1.eval(sc)
        } else {
            self.tex2.eval(sc)
        }
    }
}

/// std::max(a, b).
#[inline]
fn max(a: f32, b: f32) -> f32 {
    if a < b {
        b
    } else {
        a
    }
}
