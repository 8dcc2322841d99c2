//! `wrinkled`: turbulence (a sum of |noise| octaves) at the 3D-mapped point
//! (pbrt-v3's `Turbulence`), the same value in every channel.
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `octaves` | integer | 8 | most octaves (fewer where the footprint is large) |
//! | `roughness` | float | 0.5 | amplitude factor per octave (ω) |
//!
//! The parameters and their reading are shared with the other octave sum
//! ([`super::noise::Octaves`]).

use super::noise::{turbulence, Octaves, OCTAVE_PARAMS};
use super::{Class, MappingUse, Support, TexBuild, TexBuilder, TexValue, Texture, TextureClass};
use crate::materials::ShadingContext;
use crate::scene::Tex;

pub const CLASS: TextureClass = TextureClass {
    name: "wrinkled",
    aliases: &[],
    support: Support::Supported,
    params: OCTAVE_PARAMS,
    doc: "turbulence (sum of |noise| octaves)",
    build: TexBuild {
        mapping: MappingUse::ThreeD,
        float: Some(build::<f32>),
        spectrum: Some(build::<glam::Vec3>),
    },
};

pub struct Wrinkled(pub Octaves);

fn build<T: TexValue>(b: &mut TexBuilder) -> Result<Tex<T>, String> {
    Ok(Texture::new_handle(
        b.name,
        Class::Wrinkled(Wrinkled(Octaves::read(b))),
    ))
}

impl Wrinkled {
    pub fn eval(&self, sc: &ShadingContext) -> f32 {
        self.0.eval(sc, turbulence)
    }
}
