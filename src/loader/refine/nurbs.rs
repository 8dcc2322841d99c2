//! `nurbs`: a (possibly rational) NURBS patch, tessellated as pbrt-v3's
//! `shapes/nurbs.cpp` does.
//!
//! | parameter | type | pbrt-v3 default |
//! |---|---|---|
//! | `nu`, `nv` | integer | none (required): control points along u and v |
//! | `uorder`, `vorder` | integer | none (required): order = degree + 1 |
//! | `uknots` | float[`nu`+`uorder`] | none (required), non-decreasing |
//! | `vknots` | float[`nv`+`vorder`] | none (required), non-decreasing |
//! | `u0`, `u1` | float | `uknots[uorder−1]`, `uknots[nu]` (the whole u domain) |
//! | `v0`, `v1` | float | `vknots[vorder−1]`, `vknots[nv]` |
//! | `P` | point3[`nu`·`nv`] | control points, u fastest |
//! | `Pw` | float[4·`nu`·`nv`] | instead of `P`: homogeneous (x·w, y·w, z·w, w) |
//!
//! pbrt-v3 evaluates the patch on a fixed 30 × 30 grid of parameters evenly
//! spaced from (`u0`, `v0`) to (`u1`, `v1`) (the spacing computed in single
//! precision, as here), with de Boor's algorithm in homogeneous coordinates.
//! Each grid point becomes a vertex with uv = its (u, v) and normal
//! normalise(∂p/∂u × ∂p/∂v); each grid cell two triangles split along its
//! (i, j)–(i+1, j+1) diagonal. Where that cross product vanishes (a
//! collapsed edge, as at the pole of a surface of revolution) pbrt-v3 stores a
//! NaN normal and shades the triangles there with their facet normal; pbrs
//! stores a zero normal, so only its neighbours' normals are interpolated.
//!
//! Bad input (all errors, which pbrt-v3 mostly does not check and crashes
//! on): a missing parameter, an order below 2 or above [`MAX_ORDER`], fewer
//! control points than the order, a knot vector of the wrong length, not
//! non-decreasing or not finite, an empty knot domain, `u0`…`v1` outside the
//! domain or `u0` = `u1`, a control-point count other than `nu`·`nv`, a
//! weight that is not positive, a value that is not a finite 32-bit float.
//! `u0` > `u1` is accepted (the patch is diced backwards, as pbrt-v3 does).

use super::{array, finished, first_non_finite, one_float, one_int, Notes, Problem};
use crate::lang::params::{ParamList, ParamType};
use crate::scene::MeshData;
use glam::{DVec3, DVec4, Vec2, Vec3};

/// pbrt-v3's fixed dicing rate, both ways.
pub const DICE: usize = 30;
/// The highest order pbrs evaluates (the work per grid point grows with the
/// cube of the order; pbrt-v3 has no limit).
pub const MAX_ORDER: i64 = 32;

/// One direction of a patch: its order, knots and the diced parameter range.
#[derive(Clone, Debug)]
pub struct Axis {
    pub order: usize,
    pub n: usize,
    pub knots: Vec<f64>,
    pub t0: f64,
    pub t1: f64,
}

/// A validated patch.
#[derive(Clone, Debug)]
pub struct Nurbs {
    pub u: Axis,
    pub v: Axis,
    /// `nu`·`nv` homogeneous control points (x·w, y·w, z·w, w), u fastest.
    pub points: Vec<DVec4>,
}

fn read_axis(p: &ParamList, notes: &mut Notes, names: [&'static str; 6]) -> Result<Axis, Problem> {
    let [n_name, order_name, knots_name, t0_name, t1_name, dir] = names;
    let Some(n) = one_int(p, n_name) else {
        return Err(Problem::shape(format!(
            "needs the number of control points \"integer {n_name}\""
        )));
    };
    let Some(order) = one_int(p, order_name) else {
        return Err(Problem::shape(format!(
            "needs the {dir} order \"integer {order_name}\""
        )));
    };
    let Some(kq) = array(p, knots_name, ParamType::Float) else {
        return Err(Problem::shape(format!(
            "needs the {dir} knot vector \"float {knots_name}\""
        )));
    };
    if !(2..=MAX_ORDER).contains(&order) {
        return Err(Problem::at(
            order_name,
            format!("\"{order_name}\" is {order}: pbrs takes orders 2 to {MAX_ORDER}"),
        ));
    }
    if n < order {
        return Err(Problem::at(
            n_name,
            format!("\"{n_name}\" is {n}: fewer control points than the order {order}"),
        ));
    }
    let knots = kq.nums();
    if knots.len() as i64 != n + order {
        return Err(Problem::at(
            knots_name,
            format!(
                "\"{knots_name}\" has {} knots, not {n_name} + {order_name} = {}",
                knots.len(),
                n + order
            ),
        ));
    }
    if let Some((i, x)) = first_non_finite(knots) {
        return Err(Problem::at(
            knots_name,
            format!("knot {i} of \"{knots_name}\" ({x}) is not a finite 32-bit float"),
        ));
    }
    if let Some(i) = (1..knots.len()).find(|&i| knots[i] < knots[i - 1]) {
        return Err(Problem::at(
            knots_name,
            format!(
                "\"{knots_name}\" decreases at knot {i} ({} after {}): knots must not decrease",
                knots[i],
                knots[i - 1]
            ),
        ));
    }
    let (n, order) = (n as usize, order as usize);
    let (lo, hi) = (knots[order - 1], knots[n]);
    if lo >= hi {
        return Err(Problem::at(
            knots_name,
            format!(
                "the {dir} domain [{knots_name}[{}], {knots_name}[{n}]] = [{lo}, {hi}] is empty",
                order - 1
            ),
        ));
    }
    let t0 = one_float(p, t0_name).unwrap_or(lo);
    let t1 = one_float(p, t1_name).unwrap_or(hi);
    for (name, t) in [(t0_name, t0), (t1_name, t1)] {
        // pbrt-v3 reads past its knot vector outside the domain.
        if !(lo..=hi).contains(&t) {
            return Err(Problem::at(
                name,
                format!("\"{name}\" = {t} is outside the {dir} domain [{lo}, {hi}] of the knots"),
            ));
        }
    }
    if t0 == t1 {
        return Err(Problem::at(
            t1_name,
            format!("\"{t0_name}\" = \"{t1_name}\" = {t0}: the patch would be empty"),
        ));
    }
    if t0 > t1 {
        notes.push(Problem::at(
            t0_name,
            format!("\"{t0_name}\" {t0} > \"{t1_name}\" {t1}: diced from {t0} down to {t1}, as pbrt-v3 does"),
        ));
    }
    Ok(Axis {
        order,
        n,
        knots: knots.to_vec(),
        t0,
        t1,
    })
}

pub fn read(p: &ParamList, notes: &mut Notes) -> Result<Nurbs, Problem> {
    let u = read_axis(p, notes, ["nu", "uorder", "uknots", "u0", "u1", "u"])?;
    let v = read_axis(p, notes, ["nv", "vorder", "vknots", "v0", "v1", "v"])?;
    let count = u.n * v.n;
    let points: Vec<DVec4> = if let Some(q) = array(p, "P", ParamType::Point3) {
        let c = q.nums();
        if c.len() != 3 * count {
            return Err(Problem::at(
                "P",
                format!(
                    "\"P\" has {} points but nu × nv = {} × {} = {count}",
                    q.count(),
                    u.n,
                    v.n
                ),
            ));
        }
        if let Some((i, x)) = first_non_finite(c) {
            return Err(Problem::at(
                "P",
                format!("coordinate {i} of \"P\" ({x}) is not a finite 32-bit float"),
            ));
        }
        c.chunks_exact(3)
            .map(|c| DVec4::new(c[0], c[1], c[2], 1.0))
            .collect()
    } else if let Some(q) = array(p, "Pw", ParamType::Float) {
        let c = q.nums();
        if c.len() % 4 != 0 {
            return Err(Problem::at(
                "Pw",
                format!("\"Pw\" has {} values, not a multiple of 4", c.len()),
            ));
        }
        if c.len() != 4 * count {
            return Err(Problem::at(
                "Pw",
                format!(
                    "\"Pw\" has {} points but nu × nv = {} × {} = {count}",
                    c.len() / 4,
                    u.n,
                    v.n
                ),
            ));
        }
        if let Some((i, x)) = first_non_finite(c) {
            return Err(Problem::at(
                "Pw",
                format!("value {i} of \"Pw\" ({x}) is not a finite 32-bit float"),
            ));
        }
        if let Some(i) = (0..count).find(|&i| c[4 * i + 3] <= 0.0) {
            return Err(Problem::at(
                "Pw",
                format!(
                    "control point {i} of \"Pw\" has weight {}: weights must be positive",
                    c[4 * i + 3]
                ),
            ));
        }
        c.chunks_exact(4)
            .map(|c| DVec4::new(c[0], c[1], c[2], c[3]))
            .collect()
    } else {
        return Err(Problem::shape(
            "needs the control points \"point P\" or \"float Pw\"",
        ));
    };
    Ok(Nurbs { u, v, points })
}

impl Axis {
    /// The knot span [knots[s], knots[s+1]] used at `t`: pbrt-v3's (the
    /// first span from the domain's start that reaches `t`), moved on past
    /// empty spans so that it always has length (pbrt-v3 divides by zero
    /// there).
    fn span(&self, t: f64) -> usize {
        let k = &self.knots;
        let last = self.n - 1;
        let mut s = self.order - 1;
        while s < last && t > k[s + 1] {
            s += 1;
        }
        while s < last && k[s + 1] <= k[s] {
            s += 1;
        }
        s
    }

    /// De Boor's algorithm on the `order` control points `d` of span `s`
    /// (overwritten): the curve's homogeneous point at `t` and its
    /// homogeneous derivative.
    fn de_boor(&self, s: usize, t: f64, d: &mut [DVec4]) -> (DVec4, DVec4) {
        let k = &self.knots;
        let p = self.order - 1;
        // Raise the blend level up to p − 1; the last level is done below so
        // that its two inputs also give the derivative.
        for r in 1..p {
            for j in (r..=p).rev() {
                let lo = k[s + j - p];
                let a = (t - lo) / (k[s + j + 1 - r] - lo);
                d[j] = d[j - 1].lerp(d[j], a);
            }
        }
        let width = k[s + 1] - k[s];
        let a = (t - k[s]) / width;
        let point = d[p - 1].lerp(d[p], a);
        let deriv = (d[p] - d[p - 1]) * (p as f64 / width);
        (point, deriv)
    }
}

/// The Euclidean derivative of the projected curve from its homogeneous
/// point `h` and derivative `dh`.
fn projected_derivative(h: DVec4, dh: DVec4) -> DVec3 {
    (dh.truncate() * h.w - h.truncate() * dh.w) / (h.w * h.w)
}

impl Nurbs {
    fn point(&self, iu: usize, iv: usize) -> DVec4 {
        self.points[iv * self.u.n + iu]
    }

    /// The surface point at (u, v) with ∂p/∂u and ∂p/∂v.
    pub fn evaluate(&self, u: f64, v: f64) -> (DVec3, DVec3, DVec3) {
        let (su, sv) = (self.u.span(u), self.v.span(v));
        let (ou, ov) = (self.u.order, self.v.order);
        let (fu, fv) = (su + 1 - ou, sv + 1 - ov);
        let mut work = [DVec4::ZERO; MAX_ORDER as usize];
        let mut iso = [DVec4::ZERO; MAX_ORDER as usize];
        // Along v through each of the span's columns, then along u.
        for (i, c) in iso[..ou].iter_mut().enumerate() {
            for (j, w) in work[..ov].iter_mut().enumerate() {
                *w = self.point(fu + i, fv + j);
            }
            *c = self.v.de_boor(sv, v, &mut work[..ov]).0;
        }
        let (h, dhdu) = self.u.de_boor(su, u, &mut iso[..ou]);
        // Along u through each of the span's rows, then along v.
        for (j, r) in iso[..ov].iter_mut().enumerate() {
            for (i, w) in work[..ou].iter_mut().enumerate() {
                *w = self.point(fu + i, fv + j);
            }
            *r = self.u.de_boor(su, u, &mut work[..ou]).0;
        }
        let (h2, dhdv) = self.v.de_boor(sv, v, &mut iso[..ov]);
        (
            h.truncate() / h.w,
            projected_derivative(h, dhdu),
            projected_derivative(h2, dhdv),
        )
    }

    pub fn refine(&self, _notes: &mut Notes) -> Result<MeshData, Problem> {
        // pbrt-v3's parameter grid, in single precision as pbrt-v3 makes it.
        let grid = |a: &Axis| -> Vec<f32> {
            (0..DICE)
                .map(|i| {
                    let f = i as f32 / (DICE - 1) as f32;
                    (1.0 - f) * a.t0 as f32 + f * a.t1 as f32
                })
                .collect()
        };
        let (us, vs) = (grid(&self.u), grid(&self.v));
        let mut positions = Vec::with_capacity(DICE * DICE);
        let mut normals = Vec::with_capacity(DICE * DICE);
        let mut uvs = Vec::with_capacity(DICE * DICE);
        // The f32 grid may round just past the domain; evaluate inside it.
        let clamp = |a: &Axis, t: f32| (t as f64).clamp(a.knots[a.order - 1], a.knots[a.n]);
        for &v in &vs {
            for &u in &us {
                let (p, dpdu, dpdv) = self.evaluate(clamp(&self.u, u), clamp(&self.v, v));
                let n = dpdu.cross(dpdv).normalize_or_zero();
                if !p.is_finite() {
                    return Err(Problem::shape(format!(
                        "the patch is not finite at (u, v) = ({u}, {v}) (control points too large)"
                    )));
                }
                positions.push(p.as_vec3());
                normals.push(n.as_vec3());
                uvs.push(Vec2::new(u, v));
            }
        }
        let at = |i: usize, j: usize| (j * DICE + i) as u32;
        let mut indices = Vec::with_capacity(6 * (DICE - 1) * (DICE - 1));
        for j in 0..DICE - 1 {
            for i in 0..DICE - 1 {
                let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                indices.extend_from_slice(&[a, b, c, a, c, d]);
            }
        }
        let normals: Vec<Vec3> = normals
            .into_iter()
            .map(|n| if n.is_finite() { n } else { Vec3::ZERO })
            .collect();
        finished(MeshData {
            positions: positions.into(),
            indices: indices.into(),
            normals: Some(normals),
            uvs: Some(uvs),
            face_indices: None,
        })
    }
}
