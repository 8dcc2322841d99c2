//! `loopsubdiv`: Loop subdivision of a triangle mesh, as pbrt-v3's
//! `shapes/loopsubdiv.cpp`.
//!
//! | parameter | type | pbrt-v3 default |
//! |---|---|---|
//! | `levels` (else `nlevels`) | integer | 3 |
//! | `indices` | integer[3·faces] | none (required) |
//! | `P` | point3[] | none (required) |
//! | `scheme` | string | `"loop"` (read and ignored, as pbrt-v3) |
//!
//! Each level splits every triangle into four. A vertex already there moves
//! to (1 − nβ)·p + β·Σ(one ring), β = 1/16 at a regular interior vertex
//! (valence 6), 3/16 at valence 3 and 3/(8n) otherwise; a boundary vertex to
//! ¾·p + ⅛ of each of its two boundary neighbours. A new vertex on an edge is
//! ⅜ of each end plus ⅛ of the two opposite vertices, or the midpoint on a
//! boundary edge. After the last level every vertex is pushed to the limit
//! surface (interior: the one-ring rule with γ = 1/(n + 3/(8β)); boundary:
//! ⅗·p + ⅕ of each boundary neighbour), and its normal is the cross product
//! of the two limit tangents pbrt-v3 computes (cosine/sine-weighted one ring
//! inside; its boundary stencils on the boundary), unnormalised as pbrt-v3
//! passes them to the mesh. The mesh has no uv. Vertices and faces come out
//! in pbrt-v3's order.
//!
//! Topology as pbrt-v3 builds it: faces that share an edge are neighbours,
//! paired in file order (a third face on an edge stays unpaired, so the edge
//! is a boundary for it). Bad input (errors, where pbrt-v3 crashes or loops):
//! an index count that is not a multiple of 3, an index out of range, a face
//! that repeats a vertex, two neighbours that run along their edge the same
//! way (faces must be consistently oriented), a position that is not a
//! finite 32-bit float, a refinement beyond the vertex budget. Vertices that
//! no face uses are left out (warning; pbrt-v3 crashes on them). `levels` is
//! capped at [`MAX_LEVELS`] with a warning.

use super::{array, finished, first_non_finite, one_int, within_budget, Notes, Problem};
use crate::lang::params::{ParamList, ParamType};
use crate::scene::MeshData;
use glam::{DVec3, Vec3};
use std::collections::HashMap;
use std::f64::consts::PI;
use std::hash::{BuildHasherDefault, Hasher};

/// More levels than any mesh within the vertex budget can take (each level
/// multiplies the faces by four).
pub const MAX_LEVELS: i64 = 11;

const NONE: u32 = u32::MAX;

fn next(i: usize) -> usize {
    (i + 1) % 3
}

fn prev(i: usize) -> usize {
    (i + 2) % 3
}

/// A validated control mesh.
#[derive(Clone, Debug)]
pub struct LoopSubdiv {
    pub levels: u32,
    pub positions: Vec<DVec3>,
    /// Faces as vertex triples, every index < positions.len().
    pub faces: Vec<[u32; 3]>,
}

pub fn read(p: &ParamList, notes: &mut Notes) -> Result<LoopSubdiv, Problem> {
    let nlevels = one_int(p, "nlevels");
    let levels_param = one_int(p, "levels");
    let (levels, lname) = match (levels_param, nlevels) {
        (Some(l), _) => (l, "levels"),
        (None, Some(l)) => (l, "nlevels"),
        (None, None) => (3, "levels"),
    };
    let _ = crate::loader::lookup::string(p, "scheme");
    let Some(iq) = array(p, "indices", ParamType::Integer) else {
        return Err(Problem::shape(
            "needs the vertex indices \"integer indices\"",
        ));
    };
    let Some(pq) = array(p, "P", ParamType::Point3) else {
        return Err(Problem::shape("needs the vertex positions \"point P\""));
    };
    let levels = if levels > MAX_LEVELS {
        notes.push(Problem::at(
            lname,
            format!(
                "\"{lname}\" {levels} is more than pbrs subdivides: {MAX_LEVELS} levels are used"
            ),
        ));
        MAX_LEVELS
    } else {
        // pbrt-v3 runs no level for a negative count.
        levels.max(0)
    };
    let c = pq.nums();
    if let Some((i, x)) = first_non_finite(c) {
        return Err(Problem::at(
            "P",
            format!("coordinate {i} of \"P\" ({x}) is not a finite 32-bit float"),
        ));
    }
    let positions: Vec<DVec3> = c
        .chunks_exact(3)
        .map(|c| DVec3::new(c[0] as f32 as f64, c[1] as f32 as f64, c[2] as f32 as f64))
        .collect();
    let idx = iq.nums();
    if idx.len() % 3 != 0 {
        return Err(Problem::at(
            "indices",
            format!("\"indices\" has {} values, not a multiple of 3", idx.len()),
        ));
    }
    if idx.is_empty() {
        return Err(Problem::at("indices", "\"indices\" is empty"));
    }
    let nv = positions.len();
    if let Some((k, &bad)) = idx
        .iter()
        .enumerate()
        .find(|(_, &x)| x < 0.0 || x >= nv as f64)
    {
        return Err(Problem::at(
            "indices",
            format!("index {bad} (entry {k}) is out of range: \"P\" has {nv} vertices"),
        ));
    }
    let faces: Vec<[u32; 3]> = idx
        .chunks_exact(3)
        .map(|c| [c[0] as u32, c[1] as u32, c[2] as u32])
        .collect();
    if let Some((k, f)) = faces
        .iter()
        .enumerate()
        .find(|(_, f)| f[0] == f[1] || f[1] == f[2] || f[2] == f[0])
    {
        return Err(Problem::at(
            "indices",
            format!(
                "face {k} ({} {} {}) repeats a vertex: Loop subdivision needs proper triangles",
                f[0], f[1], f[2]
            ),
        ));
    }
    let mut mesh = LoopSubdiv {
        levels: levels as u32,
        positions,
        faces,
    };
    let dropped = mesh.drop_unused_vertices();
    if dropped > 0 {
        notes.push(Problem::at(
            "P",
            format!("{dropped} of the {nv} vertices are in no face: left out"),
        ));
    }
    Ok(mesh)
}

/// A cheap hasher for edge keys (two vertex indices in one u64).
#[derive(Default)]
struct EdgeHasher(u64);

impl Hasher for EdgeHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0.rotate_left(8) ^ b as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15);
        }
    }
    fn write_u64(&mut self, x: u64) {
        self.0 = (x ^ (x >> 29)).wrapping_mul(0x9e37_79b9_7f4a_7c15);
        self.0 ^= self.0 >> 32;
    }
}

type EdgeMap<V> = HashMap<u64, V, BuildHasherDefault<EdgeHasher>>;

fn edge_key(a: u32, b: u32) -> u64 {
    let (lo, hi) = if a < b { (a, b) } else { (b, a) };
    (lo as u64) << 32 | hi as u64
}

/// One level of the subdivision: vertices, faces and their adjacency.
struct Level {
    p: Vec<DVec3>,
    /// A face of each vertex (pbrt-v3's `startFace`).
    start: Vec<u32>,
    boundary: Vec<bool>,
    regular: Vec<bool>,
    fv: Vec<[u32; 3]>,
    /// The neighbour across edge (v[i], v[i+1]) of each face, or NONE.
    ff: Vec<[u32; 3]>,
}

impl Level {
    fn vnum(&self, f: u32, v: u32) -> usize {
        let fv = &self.fv[f as usize];
        let i = fv.iter().position(|&x| x == v);
        debug_assert!(i.is_some(), "vertex {v} is not in face {f}");
        i.unwrap_or(0)
    }
    fn next_face(&self, f: u32, v: u32) -> u32 {
        self.ff[f as usize][self.vnum(f, v)]
    }
    fn prev_face(&self, f: u32, v: u32) -> u32 {
        self.ff[f as usize][prev(self.vnum(f, v))]
    }
    fn next_vert(&self, f: u32, v: u32) -> u32 {
        self.fv[f as usize][next(self.vnum(f, v))]
    }
    fn prev_vert(&self, f: u32, v: u32) -> u32 {
        self.fv[f as usize][prev(self.vnum(f, v))]
    }
    fn other_vert(&self, f: u32, a: u32, b: u32) -> u32 {
        let fv = &self.fv[f as usize];
        *fv.iter().find(|&&x| x != a && x != b).unwrap_or(&fv[0])
    }

    /// Faces around `v` from its start face, walking to the next face while
    /// `step` finds one (at most every face once: the adjacency is a
    /// consistent pairing, so the walk returns to the start or ends).
    fn walk(&self, v: u32, step: impl Fn(u32, u32) -> u32) -> (usize, u32) {
        let start = self.start[v as usize];
        let mut f = start;
        let mut n = 1;
        loop {
            let g = step(f, v);
            if g == NONE || g == start || n > self.fv.len() {
                return (n, g);
            }
            f = g;
            n += 1;
        }
    }

    fn valence(&self, v: u32) -> usize {
        if !self.boundary[v as usize] {
            self.walk(v, |f, v| self.next_face(f, v)).0
        } else {
            // The faces forward and back from the start (which both walks
            // count), plus one: a boundary vertex has one more neighbour
            // than faces.
            let fwd = self.walk(v, |f, v| self.next_face(f, v)).0;
            let back = self.walk(v, |f, v| self.prev_face(f, v)).0;
            fwd + back
        }
    }

    /// The one ring of `v` into `ring` (pbrt-v3's order: around the faces
    /// for an interior vertex; for a boundary vertex from one boundary
    /// neighbour across the faces to the other).
    fn one_ring(&self, v: u32, ring: &mut Vec<DVec3>) {
        ring.clear();
        let limit = self.fv.len() + 1;
        if !self.boundary[v as usize] {
            let start = self.start[v as usize];
            let mut f = start;
            loop {
                ring.push(self.p[self.next_vert(f, v) as usize]);
                f = self.next_face(f, v);
                if f == start || f == NONE || ring.len() > limit {
                    break;
                }
            }
        } else {
            let mut f = self.start[v as usize];
            let mut steps = 0;
            loop {
                let g = self.next_face(f, v);
                if g == NONE || steps > limit {
                    break;
                }
                f = g;
                steps += 1;
            }
            ring.push(self.p[self.next_vert(f, v) as usize]);
            loop {
                ring.push(self.p[self.prev_vert(f, v) as usize]);
                f = self.prev_face(f, v);
                if f == NONE || ring.len() > limit {
                    break;
                }
            }
        }
    }

    /// (1 − nβ)·p + β·Σ ring.
    fn weight_one_ring(&self, v: u32, beta: f64, ring: &mut Vec<DVec3>) -> DVec3 {
        self.one_ring(v, ring);
        let n = ring.len() as f64;
        let sum: DVec3 = ring.iter().copied().sum();
        (1.0 - n * beta) * self.p[v as usize] + beta * sum
    }

    /// (1 − 2β)·p + β·(both boundary neighbours).
    fn weight_boundary(&self, v: u32, beta: f64, ring: &mut Vec<DVec3>) -> DVec3 {
        self.one_ring(v, ring);
        let (first, last) = (ring[0], ring[ring.len() - 1]);
        (1.0 - 2.0 * beta) * self.p[v as usize] + beta * (first + last)
    }

    fn finish_vertex_flags(&mut self) {
        for v in 0..self.p.len() as u32 {
            let (_, end) = self.walk(v, |f, v| self.next_face(f, v));
            self.boundary[v as usize] = end == NONE;
            let n = self.valence(v);
            self.regular[v as usize] = if self.boundary[v as usize] {
                n == 4
            } else {
                n == 6
            };
        }
    }
}

fn beta(valence: usize) -> f64 {
    if valence == 3 {
        3.0 / 16.0
    } else {
        3.0 / (8.0 * valence as f64)
    }
}

fn loop_gamma(valence: usize) -> f64 {
    1.0 / (valence as f64 + 3.0 / (8.0 * beta(valence)))
}

impl LoopSubdiv {
    /// Removes vertices no face uses, renumbering the faces; returns how
    /// many went.
    fn drop_unused_vertices(&mut self) -> usize {
        let mut used = vec![false; self.positions.len()];
        for f in &self.faces {
            for &v in f {
                used[v as usize] = true;
            }
        }
        let dropped = used.iter().filter(|u| !**u).count();
        if dropped == 0 {
            return 0;
        }
        let mut remap = vec![NONE; used.len()];
        let mut kept = Vec::with_capacity(used.len() - dropped);
        for (i, &u) in used.iter().enumerate() {
            if u {
                remap[i] = kept.len() as u32;
                kept.push(self.positions[i]);
            }
        }
        for f in &mut self.faces {
            for v in f.iter_mut() {
                *v = remap[*v as usize];
            }
        }
        self.positions = kept;
        dropped
    }

    /// The base level with pbrt-v3's adjacency, or an error for faces that
    /// are not consistently oriented.
    fn base_level(&self) -> Result<(Level, usize), Problem> {
        let (nv, nf) = (self.positions.len(), self.faces.len());
        let mut start = vec![NONE; nv];
        for (i, f) in self.faces.iter().enumerate() {
            for &v in f {
                start[v as usize] = i as u32;
            }
        }
        let mut ff = vec![[NONE; 3]; nf];
        // Open edges: the face and edge number waiting for a partner.
        let mut open: EdgeMap<(u32, usize)> = EdgeMap::default();
        open.reserve(3 * nf / 2 + 1);
        let mut unique_edges = 0;
        for (i, f) in self.faces.iter().enumerate() {
            for e in 0..3 {
                let (a, b) = (f[e], f[next(e)]);
                let key = edge_key(a, b);
                match open.remove(&key) {
                    None => {
                        open.insert(key, (i as u32, e));
                        unique_edges += 1;
                    }
                    Some((g, ge)) => {
                        let gf = self.faces[g as usize];
                        if gf[ge] == a {
                            return Err(Problem::at(
                                "indices",
                                format!("faces {g} and {i} both run from vertex {a} to {b}: Loop subdivision needs consistently oriented faces"),
                            ));
                        }
                        ff[g as usize][ge] = i as u32;
                        ff[i][e] = g;
                    }
                }
            }
        }
        // A third face on an edge pairs again with a fourth, so count edges
        // by their vertex pair (as the new edge vertices are made).
        let mut pairs: EdgeMap<()> = EdgeMap::default();
        pairs.reserve(unique_edges);
        for f in &self.faces {
            for e in 0..3 {
                pairs.insert(edge_key(f[e], f[next(e)]), ());
            }
        }
        let mut level = Level {
            p: self.positions.clone(),
            start,
            boundary: vec![false; nv],
            regular: vec![false; nv],
            fv: self.faces.clone(),
            ff,
        };
        level.finish_vertex_flags();
        Ok((level, pairs.len()))
    }

    /// The vertex and face counts after `levels` levels from `v` vertices,
    /// `e` edges and `f` faces: every edge gets one new vertex and splits in
    /// two, every face gets three inner edges (exact, unless two faces share
    /// all three vertices: then an upper bound).
    pub fn counts(v: u64, e: u64, f: u64, levels: u32) -> (u64, u64) {
        let (mut v, mut e, mut f) = (v, e, f);
        for _ in 0..levels {
            v = v.saturating_add(e);
            e = e.saturating_mul(2).saturating_add(f.saturating_mul(3));
            f = f.saturating_mul(4);
        }
        (v, f)
    }

    pub fn refine(&self, _notes: &mut Notes) -> Result<MeshData, Problem> {
        let (mut level, edges) = self.base_level()?;
        let (nv, nf) = Self::counts(
            level.p.len() as u64,
            edges as u64,
            level.fv.len() as u64,
            self.levels,
        );
        within_budget(nv, nf, &format!("subdividing {} levels", self.levels))?;
        let mut ring = Vec::with_capacity(16);
        for _ in 0..self.levels {
            level = subdivide(&level, &mut ring);
        }
        limit_mesh(level, &mut ring)
    }
}

/// One level of Loop subdivision (pbrt-v3's numbering: vertex i's child is
/// i, then the edge vertices in order of their first face and edge; face i's
/// children are 4i … 4i+3, the fourth the middle one).
fn subdivide(l: &Level, ring: &mut Vec<DVec3>) -> Level {
    let (nv, nf) = (l.p.len(), l.fv.len());
    let mut p = Vec::with_capacity(nv + 3 * nf / 2 + 1);
    let mut start = Vec::with_capacity(p.capacity());
    let mut boundary = l.boundary.clone();
    let mut regular = l.regular.clone();
    for v in 0..nv as u32 {
        let np = if !l.boundary[v as usize] {
            let b = if l.regular[v as usize] {
                1.0 / 16.0
            } else {
                beta(l.valence(v))
            };
            l.weight_one_ring(v, b, ring)
        } else {
            l.weight_boundary(v, 1.0 / 8.0, ring)
        };
        p.push(np);
        let sf = l.start[v as usize];
        start.push(4 * sf + l.vnum(sf, v) as u32);
    }
    // The new vertex on each face edge.
    let mut edge_vert: EdgeMap<u32> = EdgeMap::default();
    edge_vert.reserve(3 * nf / 2 + 1);
    let mut fe = vec![[NONE; 3]; nf];
    for (i, f) in l.fv.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (f[k], f[next(k)]);
            let id = *edge_vert.entry(edge_key(a, b)).or_insert_with(|| {
                let id = p.len() as u32;
                let nb = l.ff[i][k];
                let (pa, pb) = (l.p[a as usize], l.p[b as usize]);
                let np = if nb == NONE {
                    0.5 * (pa + pb)
                } else {
                    let c = l.p[l.other_vert(i as u32, a, b) as usize];
                    let d = l.p[l.other_vert(nb, a, b) as usize];
                    0.375 * (pa + pb) + 0.125 * (c + d)
                };
                p.push(np);
                start.push(4 * i as u32 + 3);
                boundary.push(nb == NONE);
                regular.push(true);
                id
            });
            fe[i][k] = id;
        }
    }
    let mut fv = vec![[NONE; 3]; 4 * nf];
    let mut ff = vec![[NONE; 3]; 4 * nf];
    for (i, f) in l.fv.iter().enumerate() {
        let child = |j: usize| 4 * i + j;
        for j in 0..3 {
            // The middle child borders the three corner children.
            ff[child(3)][j] = child(next(j)) as u32;
            ff[child(j)][next(j)] = child(3) as u32;
            // Corner children border the neighbours' corner children at
            // the same vertex.
            let across = |g: u32| {
                if g == NONE {
                    NONE
                } else {
                    4 * g + l.vnum(g, f[j]) as u32
                }
            };
            ff[child(j)][j] = across(l.ff[i][j]);
            ff[child(j)][prev(j)] = across(l.ff[i][prev(j)]);

            fv[child(j)][j] = f[j];
            let m = fe[i][j];
            fv[child(j)][next(j)] = m;
            fv[child(next(j))][j] = m;
            fv[child(3)][j] = m;
        }
    }
    Level {
        p,
        start,
        boundary,
        regular,
        fv,
        ff,
    }
}

/// Pushes the vertices to the limit surface and computes pbrt-v3's limit
/// normals; the mesh for the triangle path.
fn limit_mesh(mut lim: Level, ring: &mut Vec<DVec3>) -> Result<MeshData, Problem> {
    let l = &lim;
    let nv = l.p.len();
    let limit: Vec<DVec3> = (0..nv as u32)
        .map(|v| {
            if l.boundary[v as usize] {
                l.weight_boundary(v, 1.0 / 5.0, ring)
            } else {
                l.weight_one_ring(v, loop_gamma(l.valence(v)), ring)
            }
        })
        .collect();
    // The tangents are taken on the limit positions.
    lim.p = limit;
    let mut normals = Vec::with_capacity(nv);
    for v in 0..nv as u32 {
        lim.one_ring(v, ring);
        let n = ring.len();
        let pv = lim.p[v as usize];
        let (s, t) = if !lim.boundary[v as usize] {
            let mut s = DVec3::ZERO;
            let mut t = DVec3::ZERO;
            for (j, q) in ring.iter().enumerate() {
                let a = 2.0 * PI * j as f64 / n as f64;
                s += a.cos() * *q;
                t += a.sin() * *q;
            }
            (s, t)
        } else {
            let s = ring[n - 1] - ring[0];
            let t = match n {
                2 => ring[0] + ring[1] - 2.0 * pv,
                3 => ring[1] - pv,
                4 => -ring[0] + 2.0 * ring[1] + 2.0 * ring[2] - ring[3] - 2.0 * pv,
                _ => {
                    let theta = PI / (n - 1) as f64;
                    let mut t = theta.sin() * (ring[0] + ring[n - 1]);
                    for (k, q) in ring.iter().enumerate().take(n - 1).skip(1) {
                        t += (2.0 * theta.cos() - 2.0) * (k as f64 * theta).sin() * *q;
                    }
                    -t
                }
            };
            (s, t)
        };
        let nn = s.cross(t);
        let n32 = nn.as_vec3();
        normals.push(if n32.is_finite() {
            n32
        } else {
            // Only the direction matters to the shading; keep it in range.
            let d = nn.normalize_or_zero().as_vec3();
            if d.is_finite() {
                d
            } else {
                Vec3::ZERO
            }
        });
    }
    let indices: Vec<u32> = lim.fv.iter().flatten().copied().collect();
    finished(MeshData {
        positions: std::sync::Arc::new(lim.p.iter().map(|p| p.as_vec3()).collect()),
        indices: indices.into(),
        normals: Some(normals),
        uvs: None,
        face_indices: None,
    })
}
