//! `constant`: the same value everywhere.
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `value` | float or spectrum (the texture's type) | 1 | the value |
//!
//! It is a [`Tex::Constant`]: no texture object, read in place.

use super::{MappingUse, Support, TexBuild, TexBuilder, TexValue, TextureClass};
use crate::scene::{ParamSpec, Tex};

pub const PARAMS: &[ParamSpec] = &[ParamSpec::same_value("value", 1.0, "the value")];

pub const CLASS: TextureClass = TextureClass {
    name: "constant",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "a constant value",
    build: TexBuild {
        mapping: MappingUse::None,
        float: Some(build::<f32>),
        spectrum: Some(build::<glam::Vec3>),
    },
};

fn build<T: TexValue>(b: &mut TexBuilder) -> Result<Tex<T>, String> {
    Ok(Tex::Constant(b.value::<T>("value")))
}
