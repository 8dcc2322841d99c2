//! `objmesh` (a pbrs extension): a triangle mesh read from a Wavefront OBJ file.
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
    "the OBJ file (relative to the scene file)",
)];

pub const KIND: ShapeKind = ShapeKind {
    name: "objmesh",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "a triangle mesh read from a OBJ file (alpha/shadowalpha textures)",
    build: |p, r| mesh_file(KIND.name, MeshFormat::Obj, p, r),
};
