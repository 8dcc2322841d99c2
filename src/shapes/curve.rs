//! pbrt-v3's `curve`: a cubic Bézier curve of varying width, seen as a flat
//! strip facing the ray (`flat`), a strip facing the ray shaded as a tube
//! (`cylinder`), or a strip oriented by normals at its ends (`ribbon`).
//!
//! | parameter    | type     | pbrt-v3 default                          |
//! |--------------|----------|------------------------------------------|
//! | `P`          | point3[] | required                                 |
//! | `basis`      | string   | `"bezier"` (or `"bspline"`)              |
//! | `degree`     | integer  | 3 (or 2)                                 |
//! | `type`       | string   | `"flat"` (`"ribbon"`, `"cylinder"`)      |
//! | `width`      | float    | 1                                        |
//! | `width0`     | float    | `width` (at the curve's start)           |
//! | `width1`     | float    | `width` (at the curve's end)             |
//! | `N`          | normal[] | ribbons only, one per segment end        |
//! | `splitdepth` | integer  | 3 (each segment is split in 2^depth)     |
//!
//! The loader turns every input segment (bspline and degree 2 included) into
//! the cubic Bézier pbrt-v3 derives from it; each segment is split into
//! 2^`splitdepth` pieces (separate BVH primitives) sharing one
//! [`CurveCommon`], as pbrt-v3's `CreateCurve`.
//!
//! The ray test is pbrt-v3's: control points projected to a frame whose z is
//! the ray, recursive Bézier subdivision to a depth from the curve's
//! flatness, and at the leaves a hit if the ray passes within half the width
//! of the curve's closest point. Conventions, all pbrt-v3's: u along the
//! curve, v across it (0.5 on the centre line), dp/dv across the strip with
//! length the width (for `cylinder` rotated about dp/du by an angle from -90°
//! to 90° across v), n = dp/du × dp/dv (so a flat strip's normal points
//! along the ray), error bound 2·width in every axis, no normal derivatives.
//!
//! Deliberate differences (no NaN, never a wrong closest hit): within one
//! piece the closest of the subdivision's hits is kept (pbrt-v3 keeps the
//! last one found); ribbon normals that are parallel at both ends are used as
//! they are (pbrt-v3 divides by sin 0); a ribbon seen exactly edge-on has no
//! hit (pbrt-v3 divides by its zero width). Curves cannot be area lights
//! (pbrt-v3's `Curve::Sample` aborts); the loader warns.

use super::analytic::{Analytic, AnalyticHit};
use super::ShapeSample;
use super::{ShapeInput, ShapeKind, Surface};
use crate::scene::{CurveData, CurveSegment, Elem, ParamSpec, ParamValues, Support};

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::list("P", Elem::Point3, "control points (required)"),
    ParamSpec::string(
        "basis",
        "bezier",
        "`\"bezier\"` or `\"bspline\"` (else error)",
    ),
    ParamSpec::int("degree", 3, "2 or 3 (else error)"),
    ParamSpec::string(
        "type",
        "flat",
        "`\"flat\"`, `\"ribbon\"` or `\"cylinder\"` (else warning, cylinder)",
    ),
    ParamSpec::float("width", 1.0, "width along the whole curve"),
    ParamSpec::float_opt("width0", "width at its start (default width)"),
    ParamSpec::float_opt("width1", "width at its end (default width)"),
    ParamSpec::list("N", Elem::Normal, "ribbons: a normal at every segment end"),
    ParamSpec::list(
        "splitdepth",
        Elem::Number,
        "each segment is split in 2^splitdepth pieces (default 3; clamped to 0..10)",
    ),
];

pub const KIND: ShapeKind = ShapeKind {
    name: "curve",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "a cubic (or quadratic) Bézier or b-spline curve of varying width: `flat` (a strip facing the ray), `cylinder` (shaded as a tube) or `ribbon` (oriented by `N`), intersected as pbrt-v3 (recursive subdivision). Degree other than 2 or 3, an unknown basis, a wrong number of control points or ribbon normals, a ribbon without `N`, a width that is not positive: error; an unknown type: warning, cylinder; `N` on a non-ribbon: warning, ignored. Never an area light (pbrt-v3 cannot sample curves): warning, not emissive",
    build,
};

/// Most Bézier segments one `curve` may have (each becomes 2^splitdepth BVH
/// primitives).
const MAX_CURVE_SEGMENTS: usize = 1 << 22;

/// pbrt-v3's `CreateCurveShape`: the curve as cubic Bézier segments, with
/// its checks (errors where pbrt-v3 reports an error and makes no shape).
fn build(p: &ParamValues, r: &mut dyn ShapeInput) -> Option<Surface> {
    let width = p.float("width");
    let width0 = p.float_opt("width0").unwrap_or(width);
    let width1 = p.float_opt("width1").unwrap_or(width);
    let degree = p.int("degree");
    if degree != 2 && degree != 3 {
        r.error(
            Some("degree"),
            format!("curve degree {degree}: only degree 2 and 3 curves are supported (as pbrt-v3)"),
            "degree must be 2 or 3",
        );
        return None;
    }
    let degree = degree as usize;
    let bspline = match p.string("basis") {
        "bezier" => false,
        "bspline" => true,
        other => {
            r.error(
                Some("basis"),
                format!("curve basis \"{other}\": only \"bezier\" and \"bspline\" are supported (as pbrt-v3)"),
                "unknown basis",
            );
            return None;
        }
    };
    let (cp, segments) = control_points(p, r, degree, bspline)?;
    let kind = match p.string("type") {
        "flat" => CurveKind::Flat,
        "ribbon" => CurveKind::Ribbon,
        "cylinder" => CurveKind::Cylinder,
        other => {
            r.warn(
                Some("type"),
                format!("unknown curve type \"{other}\": \"cylinder\" is used (as pbrt-v3)"),
                "unknown curve type",
            );
            CurveKind::Cylinder
        }
    };
    let normals = normals(p, r, kind, segments)?;
    let split_depth = match p.has("splitdepth") {
        true => p.floats("splitdepth").first().map_or(3, |&d| d as i64),
        false => 3,
    };
    // pbrt-v3 takes a negative depth as no split and overflows past 31;
    // beyond 10 a piece is already far below the subdivision's resolution.
    let split_depth = split_depth.clamp(0, 10) as u32;
    let (w0, w1) = (width0, width1);
    let wat = ["width0", "width1"]
        .into_iter()
        .find(|n| p.float_opt(n).is_some())
        .unwrap_or("width");
    if !(w0 > 0.0 && w1 > 0.0 && w0.is_finite() && w1.is_finite()) {
        r.error(
            Some(wat),
            format!("curve widths {width0} and {width1}: both must be positive 32-bit floats (pbrt-v3 gives NaN or no curve otherwise)"),
            "width must be > 0",
        );
        return None;
    }
    let mut out = Vec::with_capacity(segments);
    for seg in 0..segments {
        let bez = if bspline {
            bspline_to_bezier(&cp[seg..seg + degree + 1])
        } else {
            bezier_to_cubic(&cp[seg * degree..seg * degree + degree + 1])
        };
        let t0 = seg as f32 / segments as f32;
        let t1 = (seg + 1) as f32 / segments as f32;
        out.push(CurveSegment {
            cp: bez,
            width: [w0 + (w1 - w0) * t0, w0 + (w1 - w0) * t1],
            normals: normals.as_ref().map(|n: &Vec<Vec3>| [n[seg], n[seg + 1]]),
        });
    }
    Some(Surface::Curve(std::sync::Arc::new(CurveData {
        kind,
        segments: out,
        split_depth,
    })))
}

/// The control points `P` and the number of segments they make, checked
/// as pbrt-v3 does.
fn control_points(
    p: &ParamValues,
    r: &mut dyn ShapeInput,
    degree: usize,
    bspline: bool,
) -> Option<(Vec<Vec3>, usize)> {
    if !p.has("P") {
        r.error(
            None,
            "curve needs control points \"point P\"".into(),
            "no \"point P\"",
        );
        return None;
    }
    let cp = to_vec3(&p.floats("P"));
    let ncp = cp.len();
    let segments = if bspline {
        if ncp < degree + 1 {
            r.error(
                Some("P"),
                format!(
                    "{ncp} control points: a degree {degree} b-spline curve needs at least {}",
                    degree + 1
                ),
                "too few control points",
            );
            return None;
        }
        ncp - degree
    } else {
        if ncp < degree + 1 || !(ncp - 1 - degree).is_multiple_of(degree) {
            r.error(
                Some("P"),
                format!("{ncp} control points: a degree {degree} Bézier curve needs {} + n·{degree} (n ≥ 0)", degree + 1),
                "wrong number of control points",
            );
            return None;
        }
        (ncp - 1) / degree
    };
    if cp.iter().any(|v| !v.is_finite()) {
        r.error(
            Some("P"),
            "a control point of \"P\" does not fit a 32-bit float".into(),
            "too large",
        );
        return None;
    }
    if segments > MAX_CURVE_SEGMENTS {
        r.error(
            Some("P"),
            format!("{segments} curve segments: pbrs takes at most {MAX_CURVE_SEGMENTS} per curve"),
            "too many segments",
        );
        return None;
    }
    Some((cp, segments))
}

/// A ribbon's normals `N` (one per segment end); `Some(None)` for the
/// other types, which ignore them (with a warning, as pbrt-v3).
fn normals(
    p: &ParamValues,
    r: &mut dyn ShapeInput,
    kind: CurveKind,
    segments: usize,
) -> Option<Option<Vec<Vec3>>> {
    if !p.has("N") {
        if kind == CurveKind::Ribbon {
            r.error(
                None,
                "a ribbon curve needs normals \"N\" at its segments' ends (as pbrt-v3)".into(),
                "no \"normal N\"",
            );
            return None;
        }
        return Some(None);
    }
    if kind != CurveKind::Ribbon {
        r.warn(
            Some("N"),
            "curve normals \"N\" are only used by \"ribbon\" curves: ignored (as pbrt-v3)".into(),
            "ignored",
        );
        return Some(None);
    }
    let n = to_vec3(&p.floats("N"));
    if n.len() != segments + 1 {
        r.error(
            Some("N"),
            format!(
                "{} normals: a ribbon curve with {segments} segments needs {}",
                n.len(),
                segments + 1
            ),
            "wrong number of normals",
        );
        return None;
    }
    if n.iter()
        .any(|v| !(v.is_finite() && v.length_squared() > 0.0 && v.normalize().is_finite()))
    {
        r.error(
            Some("N"),
            "a ribbon normal is zero or not a finite 32-bit vector".into(),
            "bad normal",
        );
        return None;
    }
    Some(Some(n))
}

/// A Bézier segment of degree 2 or 3 as a cubic (degree elevation).
fn bezier_to_cubic(c: &[Vec3]) -> [Vec3; 4] {
    if c.len() == 3 {
        [
            c[0],
            c[0].lerp(c[1], 2.0 / 3.0),
            c[1].lerp(c[2], 1.0 / 3.0),
            c[2],
        ]
    } else {
        [c[0], c[1], c[2], c[3]]
    }
}

/// A uniform b-spline segment of degree 2 or 3 as the cubic Bézier of the
/// same curve (by blossoming, as pbrt-v3).
fn bspline_to_bezier(c: &[Vec3]) -> [Vec3; 4] {
    if c.len() == 3 {
        let (p11, p12, p22) = (c[0].lerp(c[1], 0.5), c[1], c[1].lerp(c[2], 0.5));
        [p11, p11.lerp(p12, 2.0 / 3.0), p12.lerp(p22, 1.0 / 3.0), p22]
    } else {
        let p122 = c[0].lerp(c[1], 2.0 / 3.0);
        let p223 = c[1].lerp(c[2], 1.0 / 3.0);
        let p233 = c[1].lerp(c[2], 2.0 / 3.0);
        let p334 = c[2].lerp(c[3], 1.0 / 3.0);
        [p122.lerp(p223, 0.5), p223, p233, p233.lerp(p334, 0.5)]
    }
}

/// Triples of numbers as f32 vectors.
pub(super) fn to_vec3(v: &[f64]) -> Vec<Vec3> {
    v.chunks_exact(3)
        .map(|c| Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32))
        .collect()
}

use super::{coordinate_system, DiffGeom, Placement, SurfacePoint};
use crate::geometry::Bounds3;
pub use crate::scene::CurveKind;
use glam::{DMat4, DVec3, Vec2, Vec3};
use std::sync::Arc;

/// What the pieces of one Bézier segment share (pbrt-v3's `CurveCommon`).
#[derive(Clone, Debug)]
pub struct CurveCommon {
    pub kind: CurveKind,
    /// Object-space control points of the whole segment.
    pub cp: [Vec3; 4],
    /// Widths at u = 0 and u = 1.
    pub width: [f32; 2],
    /// Unit ribbon normals at u = 0 and 1 (zero for other kinds).
    n: [Vec3; 2],
    normal_angle: f32,
    inv_sin_normal_angle: f32,
    pub placement: Placement,
}

impl CurveCommon {
    pub fn new(
        kind: CurveKind,
        cp: [Vec3; 4],
        width: [f32; 2],
        normals: Option<[Vec3; 2]>,
        object_to_world: DMat4,
        reverse: bool,
    ) -> CurveCommon {
        let (n, normal_angle) = match normals {
            Some([a, b]) => {
                let n = [a.normalize(), b.normalize()];
                (n, n[0].dot(n[1]).clamp(0.0, 1.0).acos())
            }
            None => ([Vec3::ZERO; 2], 0.0),
        };
        CurveCommon {
            kind,
            cp,
            width,
            n,
            normal_angle,
            inv_sin_normal_angle: 1.0 / normal_angle.sin(),
            placement: Placement::new(object_to_world, reverse),
        }
    }

    #[inline]
    fn width_at(&self, u: f32) -> f32 {
        lerp(u, self.width[0], self.width[1])
    }

    /// The ribbon's normal at u: slerp between the end normals.
    #[inline]
    fn ribbon_normal(&self, u: f32) -> Vec3 {
        if self.normal_angle < 1e-4 {
            // (Nearly) parallel ends: the slerp's weights are 0/0.
            return self.n[0].lerp(self.n[1], u).normalize_or(self.n[0]);
        }
        let s0 = ((1.0 - u) * self.normal_angle).sin() * self.inv_sin_normal_angle;
        let s1 = (u * self.normal_angle).sin() * self.inv_sin_normal_angle;
        s0 * self.n[0] + s1 * self.n[1]
    }
}

/// One piece [u_min, u_max] of a Bézier segment (pbrt-v3's `Curve`).
#[derive(Clone, Debug)]
pub struct Curve {
    pub common: Arc<CurveCommon>,
    pub u_min: f32,
    pub u_max: f32,
    pub material: u32,
    pub light: Option<u32>,
    /// How far the piece's control points are from its chord (the segment
    /// between its end points): the piece, within their convex hull, lies
    /// within this distance of the chord.
    reach: f32,
}

/// A hit on a curve piece, in its object space: the point on the ray, its
/// error bound (one value for all axes), (u, v) and dp/dv (which depends on
/// the ray's direction, so is found with the hit).
#[derive(Clone, Copy, Debug)]
pub struct CurveHit {
    pub p: Vec3,
    pub err: f32,
    pub uv: Vec2,
    pub dpdv: Vec3,
}

impl Curve {
    /// The 2^`split_depth` pieces of a segment.
    pub fn pieces(
        common: Arc<CurveCommon>,
        split_depth: u32,
        material: u32,
    ) -> impl Iterator<Item = Curve> {
        let n = 1u32 << split_depth;
        (0..n).map(move |i| {
            let mut c = Curve {
                common: common.clone(),
                u_min: i as f32 / n as f32,
                u_max: (i + 1) as f32 / n as f32,
                material,
                light: None,
                reach: 0.0,
            };
            let cp = c.control_points();
            c.reach = segment_distance2(cp[1] - cp[0], cp[3] - cp[0])
                .max(segment_distance2(cp[2] - cp[0], cp[3] - cp[0]))
                .sqrt();
            c
        })
    }

    /// Speed only: true when the ray through `o` along the unit `dir`
    /// passes so far from the piece's chord (end points `a` and `b`) that
    /// it cannot come within half the piece's width of the piece, so that
    /// [`Curve::hit`]'s search would find nothing (most rays that reach a
    /// piece's box miss the piece). The distance is the origin's from the
    /// chord projected along `dir`; the limit is the piece's reach plus
    /// half its width, with a relative margin and one for the rounding of
    /// points `|p − o|` away, far beyond either computation's errors.
    #[inline]
    fn passes_wide(&self, o: Vec3, dir: Vec3, a: Vec3, b: Vec3) -> bool {
        let (qa, qb) = (a - o, b - o);
        let (pa, pb) = (qa - qa.dot(dir) * dir, qb - qb.dot(dir) * dir);
        let dist2 = segment_distance2(-pa, pb - pa);
        let far = qa.abs().max_element() + qb.abs().max_element();
        let lim = (self.reach + 0.5 * self.max_width()) * 1.001 + 2e-5 * far;
        dist2 > lim * lim
    }

    /// The piece's own Bézier control points (blossoms of the segment's).
    fn control_points(&self) -> [Vec3; 4] {
        let c = &self.common.cp;
        let (a, b) = (self.u_min, self.u_max);
        [
            blossom(c, a, a, a),
            blossom(c, a, a, b),
            blossom(c, a, b, b),
            blossom(c, b, b, b),
        ]
    }

    fn max_width(&self) -> f32 {
        self.common
            .width_at(self.u_min)
            .max(self.common.width_at(self.u_max))
    }

    /// Closest hit with 0 < t ≤ t_max (world ray; `t` is the same in object
    /// space): pbrt-v3's recursive subdivision of the piece in the ray's
    /// frame, and the hit's parameters.
    fn hit(&self, o: Vec3, d: Vec3, t_max: f32) -> Option<(f32, CurveHit)> {
        self.hit_with::<true>(o, d, t_max)
    }

    /// [`Curve::hit`], with the test of [`Curve::passes_wide`] first if
    /// `WIDE` (the same answer: the tests compare both).
    #[inline(always)]
    fn hit_with<const WIDE: bool>(&self, o: Vec3, d: Vec3, t_max: f32) -> Option<(f32, CurveHit)> {
        let (o, d) = self.common.placement.ray_to_object(o, d);
        let (o, d) = (o.as_vec3(), d.as_vec3());
        let ray_len = d.length();
        if !(ray_len > 0.0 && ray_len.is_finite()) {
            return None;
        }
        let dir = d / ray_len;
        let c = &self.common.cp;
        let (a, b) = (self.u_min, self.u_max);
        let (cp0, cp3) = (blossom(c, a, a, a), blossom(c, b, b, b));
        if WIDE && self.passes_wide(o, dir, cp0, cp3) {
            return None;
        }
        // The piece's control points, as `control_points` makes them.
        let cp_obj = [cp0, blossom(c, a, a, b), blossom(c, a, b, b), cp3];
        // The frame's "up" is along the chord, so the projected curve lies
        // roughly along x and its boxes are thin in y.
        let mut up = dir.cross(cp_obj[3] - cp_obj[0]);
        if up.length_squared() == 0.0 {
            up = coordinate_system(dir).0;
        }
        let right = up.normalize().cross(dir);
        if right.length_squared().is_nan() || right.length_squared() <= 0.0 || !right.is_finite() {
            return None;
        }
        let right = right.normalize();
        let new_up = dir.cross(right);
        let to_ray = |p: Vec3| {
            let q = p - o;
            Vec3::new(q.dot(right), q.dot(new_up), q.dot(dir))
        };
        let cp = [
            to_ray(cp_obj[0]),
            to_ray(cp_obj[1]),
            to_ray(cp_obj[2]),
            to_ray(cp_obj[3]),
        ];
        let z_max = ray_len * t_max;
        if !overlaps(&cp, self.max_width(), z_max) {
            return None;
        }
        // Subdivision depth from the curve's second differences (pbrt-v3's
        // bound for a flatness within width / 20).
        let mut l0 = 0.0f32;
        for i in 0..2 {
            let dd = (cp[i] - 2.0 * cp[i + 1] + cp[i + 2]).abs();
            l0 = l0.max(dd.x.max(dd.y).max(dd.z));
        }
        let eps = self.common.width[0].max(self.common.width[1]) * 0.05;
        let depth =
            (log2_round(std::f32::consts::SQRT_2 * 6.0 * l0 / (8.0 * eps)) / 2).clamp(0, 10);
        let mut best: Option<(f32, Leaf)> = None;
        let mut z_best = z_max;
        self.recurse(
            &cp,
            self.u_min,
            self.u_max,
            depth,
            dir,
            &mut z_best,
            &mut best,
        );
        let (z, leaf) = best?;
        let t = z / ray_len;
        let p = o + d * t;
        let c = &self.common;
        let dpdu = bezier_derivative(&c.cp, leaf.u);
        let dpdv = match c.kind {
            CurveKind::Ribbon => leaf.n_ribbon.cross(dpdu).normalize() * leaf.width,
            CurveKind::Flat | CurveKind::Cylinder => {
                // Across the curve in the plane facing the ray.
                let flat = dir.cross(dpdu).normalize() * leaf.width;
                if c.kind == CurveKind::Flat {
                    flat
                } else {
                    let theta = lerp(leaf.v, -90.0f32, 90.0).to_radians();
                    rotate(flat, dpdu.normalize(), -theta)
                }
            }
        };
        let dpdv = if dpdv.is_finite() && dpdv.length_squared() > 0.0 {
            dpdv
        } else {
            coordinate_system(dpdu.normalize()).0 * leaf.width
        };
        if !(t.is_finite() && p.is_finite() && dpdv.is_finite()) {
            return None;
        }
        Some((
            t,
            CurveHit {
                p,
                err: 2.0 * leaf.width,
                uv: Vec2::new(leaf.u, leaf.v),
                dpdv,
            },
        ))
    }

    #[allow(clippy::too_many_arguments)]
    fn recurse(
        &self,
        cp: &[Vec3; 4],
        u0: f32,
        u1: f32,
        depth: i32,
        dir: Vec3,
        z_max: &mut f32,
        best: &mut Option<(f32, Leaf)>,
    ) {
        if depth > 0 {
            let s = subdivide(cp);
            let um = 0.5 * (u0 + u1);
            let halves = [
                ([s[0], s[1], s[2], s[3]], u0, um),
                ([s[3], s[4], s[5], s[6]], um, u1),
            ];
            for (c, a, b) in halves {
                let w = self.common.width_at(a).max(self.common.width_at(b));
                if overlaps(&c, w, *z_max) {
                    self.recurse(&c, a, b, depth - 1, dir, z_max, best);
                }
            }
            return;
        }
        if let Some((z, leaf)) = self.leaf(cp, u0, u1, dir, *z_max) {
            *z_max = z;
            *best = Some((z, leaf));
        }
    }

    /// The ray (the z axis of `cp`'s frame) against a nearly straight piece.
    fn leaf(&self, cp: &[Vec3; 4], u0: f32, u1: f32, dir: Vec3, z_max: f32) -> Option<(f32, Leaf)> {
        // Outside the perpendiculars to the tangents at the ends: the
        // neighbouring piece's to test.
        let edge0 = (cp[1].y - cp[0].y) * -cp[0].y + cp[0].x * (cp[0].x - cp[1].x);
        let edge3 = (cp[2].y - cp[3].y) * -cp[3].y + cp[3].x * (cp[3].x - cp[2].x);
        if edge0 < 0.0 || edge3 < 0.0 {
            return None;
        }
        // The chord parameter closest to the ray.
        let seg = Vec2::new(cp[3].x - cp[0].x, cp[3].y - cp[0].y);
        let denom = seg.length_squared();
        if denom == 0.0 {
            return None;
        }
        let w = -Vec2::new(cp[0].x, cp[0].y).dot(seg) / denom;
        let u = lerp(w, u0, u1).clamp(u0, u1);
        let c = &self.common;
        let mut width = c.width_at(u);
        let mut n_ribbon = Vec3::ZERO;
        if c.kind == CurveKind::Ribbon {
            n_ribbon = c.ribbon_normal(u);
            // Seen at an angle, the ribbon looks narrower.
            width *= n_ribbon.dot(dir).abs();
        }
        if width.is_nan() || width <= 0.0 {
            return None;
        }
        let (pc, dpcdw) = bezier_point(cp, w.clamp(0.0, 1.0));
        let dist2 = pc.x * pc.x + pc.y * pc.y;
        if dist2 > width * width * 0.25 || pc.z < 0.0 || pc.z > z_max {
            return None;
        }
        let dist = dist2.sqrt();
        let side = dpcdw.x * -pc.y + pc.x * dpcdw.y;
        let v = if side > 0.0 {
            0.5 + dist / width
        } else {
            0.5 - dist / width
        };
        Some((
            pc.z,
            Leaf {
                u,
                v,
                width,
                n_ribbon,
            },
        ))
    }
}

#[derive(Clone, Copy, Debug)]
struct Leaf {
    u: f32,
    v: f32,
    width: f32,
    n_ribbon: Vec3,
}

/// True if the box of `cp` grown by half of `width` meets the ray's segment
/// (the z axis from 0 to `z_max`), y first (the thinnest).
#[inline]
fn overlaps(cp: &[Vec3; 4], width: f32, z_max: f32) -> bool {
    let h = 0.5 * width;
    let lo = cp[0].min(cp[1]).min(cp[2].min(cp[3]));
    let hi = cp[0].max(cp[1]).max(cp[2].max(cp[3]));
    !(hi.y + h < 0.0
        || lo.y - h > 0.0
        || hi.x + h < 0.0
        || lo.x - h > 0.0
        || hi.z + h < 0.0
        || lo.z - h > z_max)
}

/// The squared distance of `p` from the segment from the origin to `b`.
#[inline]
fn segment_distance2(p: Vec3, b: Vec3) -> f32 {
    let bb = b.length_squared();
    let u = if bb > 0.0 {
        (p.dot(b) / bb).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - u * b).length_squared()
}

/// log2 rounded to nearest from the float's bits; 0 below 1 (pbrt-v3's).
#[inline]
fn log2_round(v: f32) -> i32 {
    if v.is_nan() || v < 1.0 {
        return 0;
    }
    let bits = v.to_bits();
    (bits >> 23) as i32 - 127 + i32::from(bits & (1 << 22) != 0)
}

#[inline]
fn lerp<T>(t: f32, a: T, b: T) -> T
where
    T: std::ops::Mul<f32, Output = T> + std::ops::Add<Output = T>,
{
    a * (1.0 - t) + b * t
}

/// The Bézier blossom p(u0, u1, u2).
fn blossom(c: &[Vec3; 4], u0: f32, u1: f32, u2: f32) -> Vec3 {
    let a = [
        c[0].lerp(c[1], u0),
        c[1].lerp(c[2], u0),
        c[2].lerp(c[3], u0),
    ];
    let b = [a[0].lerp(a[1], u1), a[1].lerp(a[2], u1)];
    b[0].lerp(b[1], u2)
}

/// De Casteljau at 1/2: the control points of both halves (sharing the 4th).
fn subdivide(c: &[Vec3; 4]) -> [Vec3; 7] {
    [
        c[0],
        (c[0] + c[1]) / 2.0,
        (c[0] + 2.0 * c[1] + c[2]) / 4.0,
        (c[0] + 3.0 * c[1] + 3.0 * c[2] + c[3]) / 8.0,
        (c[1] + 2.0 * c[2] + c[3]) / 4.0,
        (c[2] + c[3]) / 2.0,
        c[3],
    ]
}

/// The point at u and the derivative (the chord when the derivative
/// vanishes, as pbrt-v3, so that a normal exists at coincident points).
fn bezier_point(c: &[Vec3; 4], u: f32) -> (Vec3, Vec3) {
    let a = [c[0].lerp(c[1], u), c[1].lerp(c[2], u), c[2].lerp(c[3], u)];
    let b = [a[0].lerp(a[1], u), a[1].lerp(a[2], u)];
    let d = b[1] - b[0];
    let deriv = if d.length_squared() > 0.0 {
        3.0 * d
    } else {
        c[3] - c[0]
    };
    (b[0].lerp(b[1], u), deriv)
}

fn bezier_derivative(c: &[Vec3; 4], u: f32) -> Vec3 {
    bezier_point(c, u).1
}

/// `v` rotated by `angle` (radians, right-handed) about the unit `axis`.
fn rotate(v: Vec3, axis: Vec3, angle: f32) -> Vec3 {
    let (s, c) = angle.sin_cos();
    v * c + axis.cross(v) * s + axis * axis.dot(v) * (1.0 - c)
}

impl Analytic for Curve {
    /// (A curve's description is its segments, placed by
    /// `Curve::pieces`; a piece is already placed.)
    fn placed(&self, _: DMat4, _: bool, _: u32) -> Self {
        self.clone()
    }

    fn is_valid(&self) -> bool {
        let c = &self.common;
        c.placement.is_valid()
            && c.cp.iter().all(|p| p.is_finite())
            && c.width.iter().all(|w| *w > 0.0 && w.is_finite())
    }

    /// World bounds: the control points' box grown by half the width.
    fn bounds(&self) -> Bounds3 {
        let cp = self.control_points();
        let (mut lo, mut hi) = (cp[0], cp[0]);
        for p in &cp[1..] {
            lo = lo.min(*p);
            hi = hi.max(*p);
        }
        let r = Vec3::splat(self.max_width() * 0.5);
        self.common
            .placement
            .bounds((lo - r).as_dvec3(), (hi + r).as_dvec3())
    }

    /// pbrt-v3's estimate: control polygon length times mean width (object
    /// space), scaled to world area.
    fn area(&self) -> f32 {
        let cp = self.control_points();
        let len: f32 = (0..3).map(|i| cp[i].distance(cp[i + 1])).sum();
        let w = 0.5 * (self.common.width_at(self.u_min) + self.common.width_at(self.u_max));
        self.common.placement.world_area((len * w) as f64)
    }

    /// Closest hit with 0 < t ≤ t_max (world ray; `t` is the same in object
    /// space): [`Curve::hit`].
    #[inline]
    fn intersect(&self, o: Vec3, d: Vec3, t_max: f32) -> Option<(f32, AnalyticHit)> {
        self.hit(o, d, t_max)
            .map(|(t, h)| (t, AnalyticHit::Curve(h)))
    }

    /// World point, error bound and oriented normal n̂(dp/du × dp/dv).
    #[inline]
    fn surface_point(&self, h: AnalyticHit) -> SurfacePoint {
        let AnalyticHit::Curve(h) = h else {
            return not_a_curve_hit(h);
        };
        let dpdu = bezier_derivative(&self.common.cp, h.uv.x);
        let mut n = dpdu.cross(h.dpdv).as_dvec3();
        if n.length_squared().is_nan() || n.length_squared() <= 0.0 {
            n = coordinate_system(h.dpdv.normalize()).0.as_dvec3();
        }
        self.common
            .placement
            .surface_point(h.p.as_dvec3(), n, DVec3::splat(h.err as f64))
    }

    /// uv and the tangents in world space; curves have no normal derivatives.
    #[inline]
    fn diff_geom(&self, h: AnalyticHit) -> DiffGeom {
        let AnalyticHit::Curve(h) = h else {
            return DiffGeom::ZERO;
        };
        let pl = &self.common.placement;
        let dpdu = pl.vector(bezier_derivative(&self.common.cp, h.uv.x).as_dvec3());
        let dpdv = pl.vector(h.dpdv.as_dvec3());
        DiffGeom {
            uv: h.uv,
            dpdu,
            dpdv,
            shading_dpdu: dpdu,
            shading_dpdv: dpdv,
            ..DiffGeom::ZERO
        }
    }

    /// Never a light (the scene leaves curves' emission out).
    fn sample_area(&self, _: Vec2) -> Option<ShapeSample> {
        None
    }

    fn sample_from(&self, _: Vec3, _: Vec3, _: Vec3, _: Vec2) -> Option<ShapeSample> {
        None
    }

    fn pdf_from(&self, _: Vec3, _: Vec3, _: Vec3, _: Vec3) -> f32 {
        0.0
    }
}

/// The point of a hit that is not a curve's (never reached: a curve's hits
/// are curve hits).
#[cold]
fn not_a_curve_hit(h: AnalyticHit) -> SurfacePoint {
    let (p, err) = h.point_and_error();
    SurfacePoint {
        p: p.as_vec3(),
        p_error: err.as_vec3(),
        n: Vec3::Z,
        ns: Vec3::Z,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::rng::Pcg32;

    fn same(a: Option<(f32, CurveHit)>, b: Option<(f32, CurveHit)>) -> bool {
        match (a, b) {
            (None, None) => true,
            (Some((ta, a)), Some((tb, b))) => {
                let bits = |v: Vec3| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()];
                ta.to_bits() == tb.to_bits()
                    && bits(a.p) == bits(b.p)
                    && a.err.to_bits() == b.err.to_bits()
                    && [a.uv.x.to_bits(), a.uv.y.to_bits()] == [b.uv.x.to_bits(), b.uv.y.to_bits()]
                    && bits(a.dpdv) == bits(b.dpdv)
            }
            _ => false,
        }
    }

    /// The test of `passes_wide` only turns away rays the search would
    /// find nothing for: random pieces (three kinds, straight, bent and
    /// looped, thin and wide, tapering to zero width, at scales 1e-3 to
    /// 1e4, placed by translations, rotations and non-uniform scales), and
    /// rays aimed at points near them from near and far, give the same
    /// answer with and without it, bit for bit; most misses are turned
    /// away by it.
    #[test]
    fn wide_rays_are_turned_away_only_when_they_miss() {
        let mut rng = Pcg32::with_sequence(23);
        let mut r = move || rng.uniform_f32();
        let (mut hits, mut turned, mut misses) = (0u32, 0u32, 0u32);
        for k in 0..4000 {
            let scale = [1.0f32, 1e-3, 1e4, 3.0][k % 4];
            let v = |r: &mut dyn FnMut() -> f32| {
                Vec3::new(r() - 0.5, r() - 0.5, r() - 0.5) * 2.0 * scale
            };
            let mut cp = [v(&mut r), v(&mut r), v(&mut r), v(&mut r)];
            if k % 5 == 0 {
                // Straight, with evenly spaced points.
                cp[1] = cp[0].lerp(cp[3], 1.0 / 3.0);
                cp[2] = cp[0].lerp(cp[3], 2.0 / 3.0);
            }
            let w = scale * [0.01f32, 0.1, 0.5, 0.002][k % 4];
            let width = if k % 7 == 0 { [w, 0.0] } else { [w, w * r()] };
            let kind = [CurveKind::Flat, CurveKind::Cylinder, CurveKind::Ribbon][k % 3];
            let normals = (kind == CurveKind::Ribbon)
                .then(|| [Vec3::new(r(), r(), 1.0), Vec3::new(r(), 1.0, r())]);
            let place = match k % 4 {
                0 => DMat4::IDENTITY,
                1 => DMat4::from_translation(DVec3::new(3.0, -2.0, 1.0) * scale as f64),
                2 => DMat4::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.7),
                _ => DMat4::from_scale(DVec3::new(2.0, 0.5, 1.0)),
            };
            let common = Arc::new(CurveCommon::new(kind, cp, width, normals, place, false));
            for piece in Curve::pieces(common.clone(), (k % 3) as u32, 0) {
                for _ in 0..20 {
                    // A world point near the piece, a ray at it.
                    let u = piece.u_min + (piece.u_max - piece.u_min) * r();
                    let at = bezier_point(&common.cp, u).0
                        + Vec3::new(r() - 0.5, r() - 0.5, r() - 0.5)
                            * w
                            * [0.5f32, 2.0, 10.0][(k / 3) % 3];
                    let at = place.transform_point3(at.as_dvec3()).as_vec3();
                    let far = [0.1f32, 1.0, 30.0][(k / 2) % 3] * scale;
                    let o = at
                        + Vec3::new(r() - 0.5, r() - 0.5, r() - 0.5).normalize_or(Vec3::X)
                            * far
                            * 4.0;
                    let d = (at - o) * [1.0f32, 0.3, 7.0][k % 3];
                    let t_max = [f32::INFINITY, 0.999 / [1.0f32, 0.3, 7.0][k % 3]][k % 2];
                    let with = piece.hit_with::<true>(o, d, t_max);
                    let without = piece.hit_with::<false>(o, d, t_max);
                    assert!(
                        same(with, without),
                        "{piece:?} {o} {d} {t_max}: {with:?} {without:?}"
                    );
                    if without.is_some() {
                        hits += 1;
                    } else {
                        misses += 1;
                        let (oo, dd) = piece.common.placement.ray_to_object(o, d);
                        let (oo, dd) = (oo.as_vec3(), dd.as_vec3());
                        let c = &piece.common.cp;
                        let (a, b) = (piece.u_min, piece.u_max);
                        let dir = dd / dd.length();
                        if piece.passes_wide(oo, dir, blossom(c, a, a, a), blossom(c, b, b, b)) {
                            turned += 1;
                        }
                    }
                }
            }
        }
        assert!(
            hits > 20_000 && misses > 20_000,
            "hits {hits}, misses {misses}"
        );
        assert!(
            turned > misses / 5,
            "{turned} of {misses} misses turned away"
        );
    }
}
