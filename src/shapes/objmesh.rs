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
    doc: "a triangle mesh read from an OBJ file (alpha/shadowalpha textures) (a pbrs extension). Wavefront OBJ read with `tobj`: every object/group of the file as one mesh in the file's coordinates (the CTM applies); polygons triangulated as fans (quads as `plymesh`); `vn` normals and `vt` uvs used when every vertex has them; points and lines ignored; `.mtl` materials not read (the current material applies). Unreadable file or a bad index: error naming the file at the Shape line.",
    build: |p, r| mesh_file(KIND.name, MeshFormat::Obj, p, r),
};
