//! `wrinkled`: turbulence (a sum of |noise| octaves) at the 3D-mapped point
//! (pbrt-v3's `Turbulence`), the same value in every channel.
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `octaves` | integer | 8 | most octaves |
//! | `roughness` | float | 0.5 | amplitude factor per octave (ω) |

use super::noise::turbulence;
use super::{
    Class, Mapping3D, MappingUse, Support, TexBuild, TexBuilder, TexValue, Texture, TextureClass,
};
use crate::render::materials::ShadingContext;
use crate::scene::{ParamSpec, Tex};

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::int("octaves", 8, "most octaves"),
    ParamSpec::float("roughness", 0.5, "amplitude factor per octave"),
];

pub const CLASS: TextureClass = TextureClass {
    name: "wrinkled",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "turbulence (sum of |noise| octaves)",
    build: TexBuild {
        mapping: MappingUse::ThreeD,
        float: Some(build::<f32>),
        spectrum: Some(build::<glam::Vec3>),
    },
};

pub struct Wrinkled {
    pub mapping: Mapping3D,
    pub octaves: i32,
    pub omega: f32,
}

fn build<T: TexValue>(b: &mut TexBuilder) -> Result<Tex<T>, String> {
    Ok(Texture::new_handle(
        b.name,
        Class::Wrinkled(Wrinkled {
            mapping: b.mapping3d,
            octaves: b.params.int("octaves"),
            omega: b.params.float("roughness"),
        }),
    ))
}

impl Wrinkled {
    pub fn eval(&self, sc: &ShadingContext) -> f32 {
        let (p, dpdx, dpdy) = self.mapping.map(sc);
        turbulence(p, dpdx, dpdy, self.omega, self.octaves)
    }
}
