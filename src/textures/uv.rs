//! `uv` (spectrum only): the 2D mapping's (s, t), wrapped to [0, 1), as
//! red and green.
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | mapping | see `mapping.rs` | uv | |
//!
//! pbrt-v3 makes no float `uv` texture (the name stays undefined).

use super::{Class, Mapping2D, MappingUse, Support, TexBuild, TexBuilder, Texture, TextureClass};
use crate::materials::ShadingContext;
use crate::scene::{ParamSpec, Tex};
use glam::Vec3;

pub const PARAMS: &[ParamSpec] = &[];

pub const CLASS: TextureClass = TextureClass {
    name: "uv",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "(s − ⌊s⌋, t − ⌊t⌋, 0) as RGB",
    build: TexBuild {
        mapping: MappingUse::TwoD,
        float: None,
        spectrum: Some(build),
    },
};

pub struct UvTexture {
    pub mapping: Mapping2D,
}

fn build(b: &mut TexBuilder) -> Result<Tex<Vec3>, String> {
    Ok(Texture::new_handle(
        b.name,
        Class::Uv(UvTexture {
            mapping: b.mapping2d,
        }),
    ))
}

impl UvTexture {
    #[inline]
    pub fn eval(&self, sc: &ShadingContext) -> Vec3 {
        let (st, _, _) = self.mapping.map(sc);
        Vec3::new(st.x - st.x.floor(), st.y - st.y.floor(), 0.0)
    }
}
