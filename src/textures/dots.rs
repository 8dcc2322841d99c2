//! `dots`: polka dots, one randomly placed dot of radius 0.35 in about half
//! of the unit cells of the 2D mapping (chosen and placed by Perlin noise).
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `inside` | texture of the texture's type | 1 | see below |
//! | `outside` | texture of the texture's type | 0 | see below |
//! | mapping | see `mapping.rs` | uv | |
//!
//! pbrt-v3's `CreateDots*Texture` passes `inside` where the constructor
//! expects the texture outside the dots and `outside` for the one inside,
//! so in pbrt-v3 the dots show `outside` and the rest shows `inside`. pbrs
//! keeps pbrt-v3's images: the same swap.

use super::noise::noise;
use super::{
    Class, Mapping2D, MappingUse, Support, TexBuild, TexBuilder, TexValue, Texture, TextureClass,
};
use crate::materials::ShadingContext;
use crate::scene::{ParamSpec, Tex};
use glam::Vec2;

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::same_tex("inside", 1.0, "shown between the dots (pbrt-v3's swap)"),
    ParamSpec::same_tex("outside", 0.0, "shown in the dots (pbrt-v3's swap)"),
];

pub const CLASS: TextureClass = TextureClass {
    name: "dots",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "polka dots placed by noise (pbrt-v3 shows \"outside\" in the dots)",
    build: TexBuild {
        mapping: MappingUse::TwoD,
        float: Some(build::<f32>),
        spectrum: Some(build::<glam::Vec3>),
    },
};

pub struct Dots<T> {
    pub mapping: Mapping2D,
    /// What the dots show (the `outside` parameter).
    pub in_dot: Tex<T>,
    /// What the rest shows (the `inside` parameter).
    pub off_dot: Tex<T>,
}

fn build<T: TexValue>(b: &mut TexBuilder) -> Result<Tex<T>, String> {
    Ok(Texture::new_handle(
        b.name,
        Class::Dots(Dots {
            mapping: b.mapping2d,
            in_dot: b.tex::<T>("outside"),
            off_dot: b.tex::<T>("inside"),
        }),
    ))
}

/// True if `st` lies in its cell's dot (pbrt-v3's test).
pub fn in_dot(st: Vec2) -> bool {
    let s_cell = (st.x + 0.5).floor() as i32;
    let t_cell = (st.y + 0.5).floor() as i32;
    let (sc, tc) = (s_cell as f32, t_cell as f32);
    if noise(sc + 0.5, tc + 0.5, 0.5) > 0.0 {
        let radius = 0.35f32;
        let max_shift = 0.5 - radius;
        let s_center = sc + max_shift * noise(sc + 1.5, tc + 2.8, 0.5);
        let t_center = tc + max_shift * noise(sc + 4.5, tc + 9.8, 0.5);
        let d = st - Vec2::new(s_center, t_center);
        return d.length_squared() < radius * radius;
    }
    false
}

impl<T: TexValue> Dots<T> {
    pub fn eval(&self, sc: &ShadingContext) -> T {
        let (st, _, _) = self.mapping.map(sc);
        if in_dot(st) {
            self.in_dot.eval(sc)
        } else {
            self.off_dot.eval(sc)
        }
    }
}
