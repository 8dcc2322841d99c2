//! `ptex`: per-face textures read with the Ptex library. pbrs has no Ptex
//! reader (there is none in Rust), so it warns and uses a constant 0.5 in
//! its place (the grey pbrt-v3 substitutes for an image it cannot read).
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `filename` | string | | the `.ptx` file (not read) |
//! | `gamma` | float | 2.2 | (not used) |

use super::{MappingUse, Support, TexBuild, TexBuilder, TexValue, TextureClass};
use crate::scene::{ParamSpec, Tex};

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::string("filename", "", "the .ptx file"),
    ParamSpec::float("gamma", 2.2, "decoding exponent"),
];

/// Why pbrs does not read Ptex files.
pub const WHY: &str = "there is no Ptex reader for Rust; a constant 0.5 is used instead";

pub const CLASS: TextureClass = TextureClass {
    name: "ptex",
    aliases: &[],
    support: Support::Unsupported(WHY),
    params: PARAMS,
    doc: "Ptex per-face textures (not read: constant 0.5)",
    build: TexBuild {
        mapping: MappingUse::None,
        float: Some(build::<f32>),
        spectrum: Some(build::<glam::Vec3>),
    },
};

fn build<T: TexValue>(_: &mut TexBuilder) -> Result<Tex<T>, String> {
    Ok(Tex::Constant(T::splat(0.5)))
}
