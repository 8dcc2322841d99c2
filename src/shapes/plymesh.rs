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
    doc: "a triangle mesh read from a PLY file (alpha/shadowalpha textures). Ascii / binary LE / BE PLY; `x y z`, optional `nx ny nz`, uv from `u v`, `s t`, `texture_u texture_v` or `texture_s texture_t`; faces `vertex_indices` or `vertex_index`, any integer types; quads split (0,1,2),(0,2,3); other polygons skipped with a warning; `face_indices` and other properties read and ignored. Missing, truncated or corrupt file, a face with no indices, a bad index, or a count larger than the file can hold: error naming the PLY file at the Shape line. The same file used twice is loaded once.",
    build: |p, r| mesh_file(KIND.name, MeshFormat::Ply, p, r),
};
