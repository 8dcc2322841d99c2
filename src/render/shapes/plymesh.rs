//! pbrt-v3's `plymesh`: a triangle mesh read from a PLY file (ASCII or binary; quads are split).
//!
//! | parameter  | type   | pbrt-v3 default |
//! |------------|--------|-----------------|
//! | `filename` | string | required        |
//!
//! The loader reads the file (once, however many shapes name it) through
//! [`ShapeInput::mesh_file`]; `alpha` and `shadowalpha` are read with the
//! graphics state, as for `trianglemesh`.

use super::{mesh_file, MeshFormat, ShapeKind};
use crate::scene::{ParamSpec, Support};

pub const PARAMS: &[ParamSpec] = &[ParamSpec::filename(
    "filename",
    "the PLY file (relative to the scene file)",
)];

pub const KIND: ShapeKind = ShapeKind {
    name: "plymesh",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "a triangle mesh read from a PLY file (alpha/shadowalpha textures)",
    build: |p, r| mesh_file(KIND.name, MeshFormat::Ply, p, r),
};
