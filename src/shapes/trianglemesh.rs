//! pbrt-v3's `trianglemesh`: triangles given by vertex positions and
//! indices, with optional per-vertex normals and uv.
//!
//! | parameter | type        | pbrt-v3 default                        |
//! |-----------|-------------|----------------------------------------|
//! | `P`       | point3[]    | required                               |
//! | `indices` | integer[]   | required (but for a single triangle)   |
//! | `N`       | normal[]    | none (one per vertex, else dropped)    |
//! | `uv`/`st` | point2[]    | none (one per vertex, else dropped)    |
//! | `faceIndices` | integer[] | none (one per triangle, else dropped): the Ptex face of each triangle |
//!
//! `alpha` and `shadowalpha` (float textures) are read with the graphics
//! state by the loader, as for every triangle mesh it reads from a file.

use super::curve::to_vec3;
use super::{ShapeInput, ShapeKind, Surface};
use crate::scene::{Elem, MeshData, ParamSpec, ParamValues, Support};
use glam::{Vec2, Vec3};
use std::sync::Arc;

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::list("P", Elem::Point3, "vertex positions (required)"),
    ParamSpec::list(
        "indices",
        Elem::Int,
        "three vertex indices per triangle (required unless P has 3 vertices)",
    ),
    ParamSpec::list("N", Elem::Normal, "per-vertex shading normals"),
    ParamSpec::list("uv", Elem::Point2, "per-vertex surface parameters"),
    ParamSpec::list(
        "st",
        Elem::Point2,
        "the same as `uv` (pbrt-v3's older name)",
    ),
    ParamSpec::list(
        "faceIndices",
        Elem::Int,
        "the Ptex face of each triangle (`ptex` textures)",
    ),
];

pub const KIND: ShapeKind = ShapeKind {
    name: "trianglemesh",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "a triangle mesh given in the scene file (alpha/shadowalpha textures). Index count not a multiple of 3, an index negative or ≥ vertex count, no P: error. N, uv or faceIndices count mismatch: warning, dropped. S: unused warning",
    build: |p, r| mesh(p, r).map(|m| Surface::TriangleMesh(Arc::new(m))),
};

/// pbrt-v3's checks: positions given, finite; indices a multiple of 3 and
/// in range (errors); normals and uv of the wrong count are dropped
/// (warnings).
fn mesh(p: &ParamValues, r: &mut dyn ShapeInput) -> Option<MeshData> {
    if !p.has("P") {
        r.error(
            None,
            "trianglemesh needs vertex positions \"point P\"".into(),
            "no \"point P\"",
        );
        return None;
    }
    let positions = to_vec3(&p.floats("P"));
    let nv = positions.len();
    if nv == 0 {
        r.error(
            Some("P"),
            "trianglemesh has no vertices".into(),
            "empty \"point P\"",
        );
        return None;
    }
    if positions.iter().any(|v| !v.is_finite()) {
        r.error(
            Some("P"),
            "a vertex of \"P\" does not fit a 32-bit float".into(),
            "too large",
        );
        return None;
    }
    let indices = indices(p, r, nv)?;
    let normals = if p.has("N") {
        let n = to_vec3(&p.floats("N"));
        if n.len() != nv {
            r.warn(Some("N"), format!("\"N\" has {} normals but \"P\" has {nv} vertices: normals dropped (as pbrt-v3)", n.len()), "count mismatch");
            None
        } else if n.iter().any(|v| !v.is_finite() || *v == Vec3::ZERO) {
            r.warn(
                Some("N"),
                "\"N\" has a zero or non-finite normal: normals dropped".into(),
                "bad normal",
            );
            None
        } else {
            Some(n)
        }
    } else {
        None
    };
    let uvs = match ["uv", "st"].into_iter().find(|n| p.has(n)) {
        Some(name) => {
            let v = p.floats(name);
            if v.len() != 2 * nv {
                r.warn(Some(name), format!("\"{name}\" has {} numbers but \"P\" has {nv} vertices (expected {}): uvs dropped (as pbrt-v3)", v.len(), 2 * nv), "count mismatch");
                None
            } else {
                Some(
                    v.chunks_exact(2)
                        .map(|c| Vec2::new(c[0] as f32, c[1] as f32))
                        .collect(),
                )
            }
        }
        None => None,
    };
    let face_indices = if p.has("faceIndices") {
        let f = p.floats("faceIndices");
        let nt = indices.len() / 3;
        if f.len() != nt {
            r.warn(Some("faceIndices"), format!("number of face indices, {}, doesn't match number of faces, {nt}: faceIndices dropped (as pbrt-v3)", f.len()), "count mismatch");
            None
        } else {
            Some(
                f.iter()
                    .map(|&x| x.clamp(i32::MIN as f64, i32::MAX as f64) as i32)
                    .collect(),
            )
        }
    } else {
        None
    };
    Some(MeshData {
        positions: positions.into(),
        indices: indices.into(),
        normals,
        uvs,
        face_indices,
    })
}

/// The `indices`, checked against the `nv` vertices.
fn indices(p: &ParamValues, r: &mut dyn ShapeInput, nv: usize) -> Option<Vec<u32>> {
    if !p.has("indices") {
        if nv == 3 {
            return Some(vec![0, 1, 2]);
        }
        r.error(None, format!("trianglemesh needs \"integer indices\" (it has {nv} vertices; only a single triangle may omit them)"), "no \"integer indices\"");
        return None;
    }
    let v = p.floats("indices");
    if !v.len().is_multiple_of(3) {
        r.error(
            Some("indices"),
            format!(
                "trianglemesh \"indices\" has {} values, not a multiple of 3",
                v.len()
            ),
            "indices",
        );
        return None;
    }
    if let Some((k, &bad)) = v
        .iter()
        .enumerate()
        .find(|(_, &x)| x < 0.0 || x >= nv as f64)
    {
        let why = if bad < 0.0 {
            "negative"
        } else {
            "out of range"
        };
        r.error(
            Some("indices"),
            format!("trianglemesh index {bad} (entry {k}) is {why}: \"P\" has {nv} vertices"),
            &format!("{why} index"),
        );
        return None;
    }
    Some(v.iter().map(|&x| x as u32).collect())
}
