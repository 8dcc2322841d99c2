//! `gltfmesh` (a pbrs extension): the triangle meshes of a glTF 2.0 file (`.gltf` or `.glb`).
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
    "the glTF file (relative to the scene file)",
)];

pub const KIND: ShapeKind = ShapeKind {
    name: "gltfmesh",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "a triangle mesh read from a glTF file (alpha/shadowalpha textures) (a pbrs extension). glTF 2.0 read with `gltf`: every `TRIANGLES` primitive of every mesh reachable from the default scene (else the first scene), each under its node's transform, then the CTM; `POSITION`, `NORMAL`, `TEXCOORD_0`, any index type or none. Buffers from the GLB chunk, files next to the `.gltf` (percent-decoded URIs) or base64 `data:` URIs. The file's coordinates are used as they are (glTF's +y up is not converted). Its materials are not read (the current material applies). Invalid file, a buffer shorter than declared, accessors outside their buffers, or a bad index: error naming the file at the Shape line.",
    build: |p, r| mesh_file(KIND.name, MeshFormat::Gltf, p, r),
};
