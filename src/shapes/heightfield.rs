//! pbrt-v3's `heightfield`: a grid of heights over the unit square, two triangles per cell.
//!
//! A refined shape: the loader's `refine::heightfield` reads these parameters (as
//! pbrt-v3 looks them up), checks them and builds the triangle mesh once
//! per statement, which then takes the triangle-mesh path. pbrt-v3 gives
//! such meshes no `alpha`/`shadowalpha`, and neither does pbrs.

use super::{ShapeKind, Surface};
use crate::scene::{Elem, ParamSpec, Support};
use std::sync::Arc;

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::list("nu", Elem::Int, "samples along x (≥ 2, required)"),
    ParamSpec::list("nv", Elem::Int, "samples along y (≥ 2, required)"),
    ParamSpec::list("Pz", Elem::Number, "nu·nv heights, row by row (required)"),
];

pub const KIND: ShapeKind = ShapeKind {
    name: "heightfield",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "a height field over the unit square, refined to a triangle mesh. Refined at load as pbrt-v3 (`src/loader/refine/heightfield.rs`): vertex (i, j) at (i/(nu−1), j/(nv−1), Pz), the same uv, two triangles per cell, no normals. nu or nv < 2, wrong Pz count, non-finite height: error",
    build: |_, r| {
        r.refine(KIND.name)
            .map(|m| Surface::TriangleMesh(Arc::new(m)))
    },
};
