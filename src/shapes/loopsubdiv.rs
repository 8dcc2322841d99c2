//! pbrt-v3's `loopsubdiv`: a triangle control mesh refined by Loop subdivision `levels` times (boundary rules as pbrt-v3).
//!
//! A refined shape: the loader's `refine::loopsubdiv` reads these parameters (as
//! pbrt-v3 looks them up), checks them and builds the triangle mesh once
//! per statement, which then takes the triangle-mesh path. pbrt-v3 gives
//! such meshes no `alpha`/`shadowalpha`, and neither does pbrs.

use super::{ShapeKind, Surface};
use crate::scene::{Elem, ParamSpec, Support};
use std::sync::Arc;

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::int("levels", 3, "subdivision levels"),
    ParamSpec::list(
        "nlevels",
        Elem::Int,
        "the same (an older name; `levels` wins)",
    ),
    ParamSpec::string("scheme", "loop", "the only scheme"),
    ParamSpec::list(
        "indices",
        Elem::Int,
        "three vertex indices per triangle (required)",
    ),
    ParamSpec::list("P", Elem::Point3, "control vertices (required)"),
];

pub const KIND: ShapeKind = ShapeKind {
    name: "loopsubdiv",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "a Loop subdivision surface, refined to a triangle mesh. Refined at load into a triangle mesh as pbrt-v3 (`src/loader/refine/loopsubdiv.rs`): Loop's even/odd and boundary rules, limit positions and pbrt-v3's limit normals, no uv. Index count not a multiple of 3, an index out of range, a face repeating a vertex, neighbouring faces not consistently oriented, a non-finite position, more than 2²² vertices after refinement: error. `levels` above 11: warning, capped. Vertices in no face: warning, left out",
    build: |_, r| {
        r.refine(KIND.name)
            .map(|m| Surface::TriangleMesh(Arc::new(m)))
    },
};
