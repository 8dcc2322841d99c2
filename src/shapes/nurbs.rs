//! pbrt-v3's `nurbs`: a (possibly rational) NURBS patch, diced on pbrt-v3's 30 × 30 grid.
//!
//! A refined shape: the loader's `refine::nurbs` reads these parameters (as
//! pbrt-v3 looks them up), checks them and builds the triangle mesh once
//! per statement, which then takes the triangle-mesh path. pbrt-v3 gives
//! such meshes no `alpha`/`shadowalpha`, and neither does pbrs.

use super::{ShapeKind, Surface};
use crate::scene::{Elem, ParamSpec, Support};
use std::sync::Arc;

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::list("nu", Elem::Int, "control points along u (required)"),
    ParamSpec::list("nv", Elem::Int, "control points along v (required)"),
    ParamSpec::list("uorder", Elem::Int, "order along u = degree + 1 (required)"),
    ParamSpec::list("vorder", Elem::Int, "order along v (required)"),
    ParamSpec::list(
        "uknots",
        Elem::Number,
        "nu + uorder non-decreasing knots (required)",
    ),
    ParamSpec::list(
        "vknots",
        Elem::Number,
        "nv + vorder non-decreasing knots (required)",
    ),
    ParamSpec::float_opt("u0", "start of the u range (default the knot domain's)"),
    ParamSpec::float_opt("u1", "end of the u range"),
    ParamSpec::float_opt("v0", "start of the v range"),
    ParamSpec::float_opt("v1", "end of the v range"),
    ParamSpec::list("P", Elem::Point3, "nu·nv control points, u fastest"),
    ParamSpec::list(
        "Pw",
        Elem::Number,
        "instead of P: homogeneous (x·w, y·w, z·w, w)",
    ),
];

pub const KIND: ShapeKind = ShapeKind {
    name: "nurbs",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "a NURBS patch, refined to a triangle mesh. Refined at load as pbrt-v3 (`src/loader/refine/nurbs.rs`): a fixed 30×30 grid from (u0, v0) to (u1, v1), normals normalise(∂p/∂u × ∂p/∂v) (zero where that vanishes), uv = (u, v). Missing parameter, order outside 2…32, nu < order, wrong knot count, decreasing or non-finite knots, empty domain, u0…v1 outside it or u0 = u1, wrong point count, a weight ≤ 0: error. u0 > u1: warning, diced backwards as pbrt-v3",
    build: |_, r| {
        r.refine(KIND.name)
            .map(|m| Surface::TriangleMesh(Arc::new(m)))
    },
};
