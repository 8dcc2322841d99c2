//! `scale`: the product of two textures.
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `tex1` | texture of the texture's type | 1 | |
//! | `tex2` | texture of the texture's type | 1 | |
//!
//! A spectrum `scale` reads both as spectra (pbrt-v3's
//! `ScaleTexture<Spectrum, Spectrum>`): a `"float tex2"` is not used. The
//! product of two constants is a constant.

use super::{Class, MappingUse, Support, TexBuild, TexBuilder, TexValue, Texture, TextureClass};
use crate::materials::ShadingContext;
use crate::scene::{ParamSpec, Tex};

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::same_tex("tex1", 1.0, "first factor"),
    ParamSpec::same_tex("tex2", 1.0, "second factor"),
];

pub const CLASS: TextureClass = TextureClass {
    name: "scale",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "tex1 · tex2",
    build: TexBuild {
        mapping: MappingUse::None,
        float: Some(build::<f32>),
        spectrum: Some(build::<glam::Vec3>),
    },
};

pub struct Scale<T> {
    pub tex1: Tex<T>,
    pub tex2: Tex<T>,
}

fn build<T: TexValue>(b: &mut TexBuilder) -> Result<Tex<T>, String> {
    let (tex1, tex2) = (b.tex::<T>("tex1"), b.tex::<T>("tex2"));
    if let (Some(a), Some(c)) = (tex1.as_constant(), tex2.as_constant()) {
        return Ok(Tex::Constant(a.mul(c)));
    }
    Ok(Texture::new_handle(
        b.name,
        Class::Scale(Scale { tex1, tex2 }),
    ))
}

impl<T: TexValue> Scale<T> {
    #[inline]
    pub fn eval(&self, sc: &ShadingContext) -> T {
        self.tex1.eval(sc).mul(self.tex2.eval(sc))
    }
}
