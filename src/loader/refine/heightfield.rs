//! `heightfield`: a grid of heights over the unit square, as pbrt-v3's
//! `shapes/heightfield.cpp`.
//!
//! | parameter | type | pbrt-v3 default |
//! |---|---|---|
//! | `nu` | integer | none (required; pbrt-v3 stops on a failed check) |
//! | `nv` | integer | none (required) |
//! | `Pz` | float[`nu`·`nv`] | none (required), row by row, `u` fastest |
//!
//! Vertex (i, j) (column i < `nu`, row j < `nv`) is at
//! (i/(`nu`−1), j/(`nv`−1), `Pz`[j·`nu`+i]) with that same (x, y) as its uv;
//! each grid cell is two triangles split along its (i, j)–(i+1, j+1)
//! diagonal. No normals: the mesh is shaded with its facets, as in pbrt-v3.
//! `nu` or `nv` below 2 (pbrt-v3 divides by zero there), a `Pz` count other
//! than `nu`·`nv` or a height that is not a finite 32-bit float: error.

use super::{array, finished, first_non_finite, one_int, within_budget, Notes, Problem};
use crate::lang::params::{ParamList, ParamType};
use crate::scene::MeshData;
use glam::{Vec2, Vec3};

/// A validated heightfield.
#[derive(Clone, Debug)]
pub struct Heightfield {
    pub nu: usize,
    pub nv: usize,
    /// `nu`·`nv` heights, finite as f32.
    pub z: Vec<f32>,
}

pub fn read(p: &ParamList, _notes: &mut Notes) -> Result<Heightfield, Problem> {
    let nu = one_int(p, "nu");
    let nv = one_int(p, "nv");
    let pz = array(p, "Pz", ParamType::Float);
    let (Some(nu), Some(nv)) = (nu, nv) else {
        return Err(Problem::shape(
            "needs the grid size \"integer nu\" and \"integer nv\"",
        ));
    };
    let Some(pz) = pz else {
        return Err(Problem::shape("needs the heights \"float Pz\""));
    };
    for (n, v) in [("nu", nu), ("nv", nv)] {
        if v < 2 {
            return Err(Problem::at(
                n,
                format!("\"{n}\" is {v}: a heightfield needs at least 2 samples each way"),
            ));
        }
    }
    let z = pz.nums();
    if nu.checked_mul(nv) != Some(z.len() as i64) {
        return Err(Problem::at(
            "Pz",
            format!(
                "\"Pz\" has {} heights but nu × nv = {nu} × {nv} = {}",
                z.len(),
                nu as i128 * nv as i128
            ),
        ));
    }
    if let Some((i, x)) = first_non_finite(z) {
        return Err(Problem::at(
            "Pz",
            format!("height {i} of \"Pz\" ({x}) is not a finite 32-bit float"),
        ));
    }
    Ok(Heightfield {
        nu: nu as usize,
        nv: nv as usize,
        z: z.iter().map(|&x| x as f32).collect(),
    })
}

impl Heightfield {
    pub fn refine(&self, _notes: &mut Notes) -> Result<MeshData, Problem> {
        let (nu, nv) = (self.nu, self.nv);
        let cells = (nu as u64 - 1) * (nv as u64 - 1);
        within_budget((nu * nv) as u64, 2 * cells, "this heightfield")?;
        // pbrt-v3 computes the grid coordinates in single precision.
        let (su, sv) = ((nu - 1) as f32, (nv - 1) as f32);
        let mut positions = Vec::with_capacity(nu * nv);
        let mut uvs = Vec::with_capacity(nu * nv);
        for j in 0..nv {
            for i in 0..nu {
                let xy = Vec2::new(i as f32 / su, j as f32 / sv);
                positions.push(Vec3::new(xy.x, xy.y, self.z[j * nu + i]));
                uvs.push(xy);
            }
        }
        let mut indices = Vec::with_capacity(6 * cells as usize);
        let at = |i: usize, j: usize| (j * nu + i) as u32;
        for j in 0..nv - 1 {
            for i in 0..nu - 1 {
                let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                indices.extend_from_slice(&[a, b, c, a, c, d]);
            }
        }
        finished(MeshData {
            positions: positions.into(),
            indices: indices.into(),
            normals: None,
            uvs: Some(uvs),
            face_indices: None,
        })
    }
}
