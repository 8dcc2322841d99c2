//! `windy`: waves whose height is modulated by a slower "wind strength"
//! (pbrt-v3's `WindyTexture`: |FBm(0.1·p, ω 0.5, 3 octaves)| · FBm(p, ω 0.5,
//! 6 octaves)), the same value in every channel. No parameters besides the
//! statement's transform (the 3D mapping).

use super::noise::fbm;
use super::{
    Class, Mapping3D, MappingUse, Support, TexBuild, TexBuilder, TexValue, Texture, TextureClass,
};
use crate::materials::ShadingContext;
use crate::scene::{ParamSpec, Tex};

pub const PARAMS: &[ParamSpec] = &[];

pub const CLASS: TextureClass = TextureClass {
    name: "windy",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "wind-modulated waves (two FBm sums)",
    build: TexBuild {
        mapping: MappingUse::ThreeD,
        float: Some(build::<f32>),
        spectrum: Some(build::<glam::Vec3>),
    },
};

pub struct Windy {
    pub mapping: Mapping3D,
}

fn build<T: TexValue>(b: &mut TexBuilder) -> Result<Tex<T>, String> {
    Ok(Texture::new_handle(
        b.name,
        Class::Windy(Windy {
            mapping: b.mapping3d,
        }),
    ))
}

impl Windy {
    pub fn eval(&self, sc: &ShadingContext) -> f32 {
        let (p, dpdx, dpdy) = self.mapping.map(sc);
        let wind = fbm(0.1 * p, 0.1 * dpdx, 0.1 * dpdy, 0.5, 3);
        let wave = fbm(p, dpdx, dpdy, 0.5, 6);
        wind.abs() * wave
    }
}
