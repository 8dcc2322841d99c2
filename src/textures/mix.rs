//! `mix`: a blend of two textures by a float texture.
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `tex1` | texture of the texture's type | 0 | |
//! | `tex2` | texture of the texture's type | 1 | |
//! | `amount` | float texture | 0.5 | weight of `tex2` |
//!
//! Value (1 − amount)·tex1 + amount·tex2; of constants, a constant.

use super::{Class, MappingUse, Support, TexBuild, TexBuilder, TexValue, Texture, TextureClass};
use crate::materials::ShadingContext;
use crate::scene::{FloatTex, ParamSpec, Tex};

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::same_tex("tex1", 0.0, "value at amount 0"),
    ParamSpec::same_tex("tex2", 1.0, "value at amount 1"),
    ParamSpec::float_tex("amount", 0.5, "weight of tex2"),
];

pub const CLASS: TextureClass = TextureClass {
    name: "mix",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "(1 − amount)·tex1 + amount·tex2",
    build: TexBuild {
        mapping: MappingUse::None,
        float: Some(build::<f32>),
        spectrum: Some(build::<glam::Vec3>),
    },
};

pub struct Mix<T> {
    pub tex1: Tex<T>,
    pub tex2: Tex<T>,
    pub amount: FloatTex,
}

fn build<T: TexValue>(b: &mut TexBuilder) -> Result<Tex<T>, String> {
    let m = Mix {
        tex1: b.tex::<T>("tex1"),
        tex2: b.tex::<T>("tex2"),
        amount: b.params.float_tex("amount").expect("default"),
    };
    if let (Some(t1), Some(t2), Some(a)) = (
        m.tex1.as_constant(),
        m.tex2.as_constant(),
        m.amount.as_constant(),
    ) {
        return Ok(Tex::Constant(mix(t1, t2, a)));
    }
    Ok(Texture::new_handle(b.name, Class::Mix(m)))
}

#[inline]
fn mix<T: TexValue>(t1: T, t2: T, amt: f32) -> T {
    t1.scale(1.0 - amt).add(t2.scale(amt))
}

impl<T: TexValue> Mix<T> {
    #[inline]
    pub fn eval(&self, sc: &ShadingContext) -> T {
        let (t1, t2) = (self.tex1.eval(sc), self.tex2.eval(sc));
        mix(t1, t2, self.amount.eval(sc))
    }
}
