//! Shapes, as pbrt-v3 has them (src/shapes/*.cpp): one file per kind,
//! each opening with its parameters and pbrt-v3's checks of them, and one
//! table, [`SHAPES`], that the loader (parsing, "did you mean"), `--check`,
//! `grammar/REFERENCE.md` and the tests read. A kind's builder makes the
//! scene description's [`Surface`] (object space); the render core places
//! it in world space: triangle meshes, and the analytic shapes
//! ([`AnalyticShape`]: quadrics and curve pieces, each kind answering
//! [`Analytic`] in its own file and placed by the shared [`Placement`]) with
//! intersection, surface interactions carrying error bounds, and sampling
//! for area lights.
//!
//! A new analytic kind is its file, its `mod` line and row in [`SHAPES`]
//! here, and its row in `analytic.rs`'s enum.
//!
//! Files are read by the loader, not here: a builder asks for a mesh file
//! (or a refined shape's mesh) through [`ShapeInput`].

mod analytic;
mod cone;
mod curve;
mod cylinder;
mod disk;
mod gltfmesh;
mod heightfield;
mod hyperboloid;
mod loopsubdiv;
mod nurbs;
mod objmesh;
mod paraboloid;
mod plymesh;
mod sphere;
mod triangle;
mod trianglemesh;

pub use analytic::{Analytic, AnalyticHit, AnalyticShape, Placed, Placement};
pub use cone::Cone;
pub use curve::{Curve, CurveCommon, CurveHit, CurveKind};
pub use cylinder::Cylinder;
pub use disk::Disk;
pub use hyperboloid::{hyperboloid_coefficients, Hyperboloid};
pub use paraboloid::Paraboloid;
pub use sphere::Sphere;
pub use sphere::{area_to_solid_angle, to_solid_angle};
pub use triangle::{
    intersect_triangle, pack_triangles, sample_triangle_point, AlphaMask, TriangleMesh,
    TrianglePack, TriangleRay, TriangleRay4,
};

use crate::scene::{Kind, ParamSpec, ParamValues, Report};
pub use crate::scene::{MeshData, Surface};
use std::sync::Arc;

/// What a shape's builder needs from the loader besides its parameters:
/// where to report (file:line:col), and the files it reads.
pub trait ShapeInput: Report {
    /// The mesh of the file `filename` (as written; the loader resolves it
    /// against the scene file), read once however many shapes name it;
    /// `None` after a located error.
    fn mesh_file(&mut self, format: MeshFormat, filename: &str) -> Option<Arc<MeshData>>;
    /// The triangle mesh of a refined shape (`loopsubdiv`, `nurbs`,
    /// `heightfield`), refined by the loader from the statement; `None`
    /// after a located error.
    fn refine(&mut self, kind: &'static str) -> Option<MeshData>;
}

/// The mesh file formats the loader reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshFormat {
    Ply,
    Obj,
    Gltf,
}

impl MeshFormat {
    /// Its name in messages.
    pub fn label(self) -> &'static str {
        match self {
            MeshFormat::Ply => "PLY",
            MeshFormat::Obj => "OBJ",
            MeshFormat::Gltf => "glTF",
        }
    }
}

/// What a shape kind builds from its parameters (`None`: skipped, after a
/// warning or an error).
pub type ShapeBuild = fn(&ParamValues, &mut dyn ShapeInput) -> Option<Surface>;

/// One shape kind: its pbrt-v3 name, its parameters, its builder.
pub type ShapeKind = Kind<ShapeBuild>;

/// Every shape pbrt-v3 knows, and the pbrs mesh-file extensions (an
/// unknown shape is a warning, and the shape is skipped, as pbrt-v3).
pub static SHAPES: &[ShapeKind] = &[
    sphere::KIND,
    disk::KIND,
    cylinder::KIND,
    cone::KIND,
    paraboloid::KIND,
    hyperboloid::KIND,
    curve::KIND,
    trianglemesh::KIND,
    plymesh::KIND,
    objmesh::KIND,
    gltfmesh::KIND,
    loopsubdiv::KIND,
    nurbs::KIND,
    heightfield::KIND,
];

/// The name of the kind that builds `s` (for `--stats`: the refined and
/// mesh-file kinds are triangle meshes once built).
pub fn kind_name(s: &Surface) -> &'static str {
    match s {
        Surface::TriangleMesh(_) => trianglemesh::KIND.name,
        Surface::Curve(_) => curve::KIND.name,
        Surface::Analytic(a) => a.kind_name(),
    }
}

/// An analytic shape built at the origin, as the scene description holds it.
fn at_origin(a: impl Into<AnalyticShape>) -> Option<Surface> {
    Some(Surface::Analytic(a.into()))
}

/// `phimax`, a line of every quadric's table.
const PHIMAX: ParamSpec =
    ParamSpec::float("phimax", 360.0, "degrees of φ swept, clamped to [0, 360]");

/// `phimax` clamped to [0, 360] as pbrt-v3; `None` (with a warning) at 0.
fn phi_max(kind: &str, p: &ParamValues, r: &mut dyn ShapeInput) -> Option<f32> {
    let phimax = p.float("phimax");
    let clamped = if phimax.is_nan() {
        0.0
    } else {
        phimax.clamp(0.0, 360.0)
    };
    if clamped <= 0.0 {
        r.warn(
            Some("phimax"),
            format!("{kind} with phimax {phimax}: an empty surface, skipped"),
            "phimax must be > 0",
        );
        return None;
    }
    Some(clamped)
}

/// An error unless every value is a finite 32-bit float and `positive` ones
/// are > 0.
fn check_floats(kind: &str, r: &mut dyn ShapeInput, values: &[(&str, f32, bool)]) -> bool {
    for &(k, v, positive) in values {
        if !(v.is_finite() && (!positive || v > 0.0)) {
            let what = if positive {
                "a positive 32-bit float"
            } else {
                "a finite 32-bit float"
            };
            r.error(
                Some(k),
                format!("{kind} {k} {v} is not {what}"),
                &format!("bad {k}"),
            );
            return false;
        }
    }
    true
}

/// The mesh-file kinds' builder: the file named by `filename`, read by the
/// loader.
fn mesh_file(
    kind: &str,
    format: MeshFormat,
    p: &ParamValues,
    r: &mut dyn ShapeInput,
) -> Option<Surface> {
    let file = p.string("filename");
    if file.is_empty() {
        r.error(
            None,
            format!("{kind} needs a \"string filename\" parameter"),
            "no filename",
        );
        return None;
    }
    r.mesh_file(format, file).map(Surface::TriangleMesh)
}

use crate::geometry::RayDiff;
use glam::{Vec2, Vec3};

/// A point on a surface: position with its error bound, oriented geometric
/// normal `n` (pbrt-v3's rules: ReverseOrientation, handedness, per-vertex
/// normals), and shading normal `ns` (same hemisphere as `n`).
#[derive(Clone, Copy, Debug)]
pub struct SurfacePoint {
    pub p: Vec3,
    pub p_error: Vec3,
    pub n: Vec3,
    pub ns: Vec3,
}

/// The differential geometry of a surface hit (pbrt-v3's
/// `SurfaceInteraction` minus the point): surface parameters, the partial
/// derivatives of position and normal, and the shading frame's. BSDFs align
/// anisotropic lobes with `shading_dpdu`; textures read `uv` and the
/// derivatives. The shading normal itself is [`SurfacePoint::ns`].
#[derive(Clone, Copy, Debug, Default)]
pub struct DiffGeom {
    pub uv: Vec2,
    pub dpdu: Vec3,
    pub dpdv: Vec3,
    pub dndu: Vec3,
    pub dndv: Vec3,
    pub shading_dpdu: Vec3,
    pub shading_dpdv: Vec3,
    pub shading_dndu: Vec3,
    pub shading_dndv: Vec3,
    /// Screen-space derivatives of the hit point and of uv from the ray's
    /// differentials (pbrt-v3's `ComputeDifferentials`); all zero when the
    /// ray carries none (then textures are point-sampled).
    pub dpdx: Vec3,
    pub dpdy: Vec3,
    pub dudx: f32,
    pub dvdx: f32,
    pub dudy: f32,
    pub dvdy: f32,
    /// The Ptex face of the hit (a mesh's `faceIndices`; 0 without them).
    pub face_index: i32,
}

impl DiffGeom {
    /// All zero: what materials that do not use the differential geometry get.
    pub const ZERO: DiffGeom = DiffGeom {
        uv: Vec2::ZERO,
        dpdu: Vec3::ZERO,
        dpdv: Vec3::ZERO,
        dndu: Vec3::ZERO,
        dndv: Vec3::ZERO,
        shading_dpdu: Vec3::ZERO,
        shading_dpdv: Vec3::ZERO,
        shading_dndu: Vec3::ZERO,
        shading_dndv: Vec3::ZERO,
        dpdx: Vec3::ZERO,
        dpdy: Vec3::ZERO,
        dudx: 0.0,
        dvdx: 0.0,
        dudy: 0.0,
        dvdy: 0.0,
        face_index: 0,
    };
}

impl DiffGeom {
    /// pbrt-v3's `SurfaceInteraction::ComputeDifferentials`: where the
    /// offset rays of `diff` cross the tangent plane at `p` (geometric
    /// normal `n`) gives dp/dx and dp/dy, and solving for them in the
    /// (dp/du, dp/dv) basis gives the uv derivatives. Left zero where the
    /// offset rays miss the plane or the basis is degenerate.
    pub fn compute_differentials(&mut self, p: Vec3, n: Vec3, diff: &RayDiff) {
        let d = n.dot(p);
        let tx = -(n.dot(diff.rx_o) - d) / n.dot(diff.rx_d);
        let ty = -(n.dot(diff.ry_o) - d) / n.dot(diff.ry_d);
        if !tx.is_finite() || !ty.is_finite() {
            self.dpdx = Vec3::ZERO;
            self.dpdy = Vec3::ZERO;
            (self.dudx, self.dvdx, self.dudy, self.dvdy) = (0.0, 0.0, 0.0, 0.0);
            return;
        }
        let px = diff.rx_o + tx * diff.rx_d;
        let py = diff.ry_o + ty * diff.ry_d;
        self.dpdx = px - p;
        self.dpdy = py - p;
        // The two axes the normal is least along.
        let an = n.abs();
        let (a, b) = if an.x > an.y && an.x > an.z {
            (1, 2)
        } else if an.y > an.z {
            (0, 2)
        } else {
            (0, 1)
        };
        let m = [[self.dpdu[a], self.dpdv[a]], [self.dpdu[b], self.dpdv[b]]];
        (self.dudx, self.dvdx) = solve_2x2(m, [self.dpdx[a], self.dpdx[b]]).unwrap_or((0.0, 0.0));
        (self.dudy, self.dvdy) = solve_2x2(m, [self.dpdy[a], self.dpdy[b]]).unwrap_or((0.0, 0.0));
    }

    /// The shading normal's screen-space derivatives (pbrt-v3's `dndx`, `dndy`).
    #[inline]
    fn dndx_dndy(&self) -> (Vec3, Vec3) {
        (
            self.shading_dndu * self.dudx + self.shading_dndv * self.dvdx,
            self.shading_dndu * self.dudy + self.shading_dndv * self.dvdy,
        )
    }

    /// Differentials of the specularly reflected ray `wi` (pbrt-v3's
    /// `SpecularReflect`), from the incoming ray's `diff` at this hit
    /// (`wo` = −ray direction, `ns` the shading normal).
    pub fn reflected(&self, p: Vec3, ns: Vec3, wo: Vec3, wi: Vec3, diff: &RayDiff) -> RayDiff {
        let (dndx, dndy) = self.dndx_dndy();
        let dwodx = -diff.rx_d - wo;
        let dwody = -diff.ry_d - wo;
        let ddndx = dwodx.dot(ns) + wo.dot(dndx);
        let ddndy = dwody.dot(ns) + wo.dot(dndy);
        let won = wo.dot(ns);
        RayDiff {
            rx_o: p + self.dpdx,
            ry_o: p + self.dpdy,
            rx_d: wi - dwodx + 2.0 * (won * dndx + ddndx * ns),
            ry_d: wi - dwody + 2.0 * (won * dndy + ddndy * ns),
        }
    }

    /// Differentials of the specularly transmitted ray `wi` (pbrt-v3's
    /// `SpecularTransmit`); `eta` is the BSDF's (the inside's index over
    /// the outside's).
    pub fn transmitted(
        &self,
        p: Vec3,
        ns: Vec3,
        wo: Vec3,
        wi: Vec3,
        eta: f32,
        diff: &RayDiff,
    ) -> RayDiff {
        let (mut dndx, mut dndy) = self.dndx_dndy();
        let (mut ns, mut eta) = (ns, 1.0 / eta);
        if wo.dot(ns) < 0.0 {
            eta = 1.0 / eta;
            ns = -ns;
            dndx = -dndx;
            dndy = -dndy;
        }
        let dwodx = -diff.rx_d - wo;
        let dwody = -diff.ry_d - wo;
        let ddndx = dwodx.dot(ns) + wo.dot(dndx);
        let ddndy = dwody.dot(ns) + wo.dot(dndy);
        let won = wo.dot(ns);
        let win = wi.dot(ns).abs();
        let mu = eta * won - win;
        let k = eta - (eta * eta * won) / win;
        RayDiff {
            rx_o: p + self.dpdx,
            ry_o: p + self.dpdy,
            rx_d: wi - eta * dwodx + (mu * dndx + k * ddndx * ns),
            ry_d: wi - eta * dwody + (mu * dndy + k * ddndy * ns),
        }
    }
}

/// The roots t0 ≤ t1 of a·t² + b·t + c for a ray against a quadric of
/// radius `radius` whose closest approach to the centre (or the axis) is
/// `len`: pbrt-v4's stable quadratic, its discriminant 4a(r + len)(r − len)
/// from that approach (`None` when the ray misses).
#[inline(always)]
fn stable_roots(a: f64, b: f64, c: f64, radius: f64, len: f64) -> Option<(f64, f64)> {
    let disc = 4.0 * a * (radius + len) * (radius - len);
    if disc < 0.0 {
        return None;
    }
    let root = disc.sqrt();
    let q = if b < 0.0 {
        -0.5 * (b - root)
    } else {
        -0.5 * (b + root)
    };
    let (t0, t1) = (q / a, if q != 0.0 { c / q } else { q / a });
    Some(if t0 > t1 { (t1, t0) } else { (t0, t1) })
}

/// pbrt-v3's `SolveLinearSystem2x2`.
#[inline]
fn solve_2x2(a: [[f32; 2]; 2], b: [f32; 2]) -> Option<(f32, f32)> {
    let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
    if det.abs() < 1e-10 {
        return None;
    }
    let x0 = (a[1][1] * b[0] - a[0][1] * b[1]) / det;
    let x1 = (a[0][0] * b[1] - a[1][0] * b[0]) / det;
    if x0.is_nan() || x1.is_nan() {
        return None;
    }
    Some((x0, x1))
}

/// pbrt-v3's `CoordinateSystem`: two unit vectors completing `v1` (a unit
/// vector) to an orthonormal basis.
#[inline]
pub fn coordinate_system(v1: Vec3) -> (Vec3, Vec3) {
    let v2 = if v1.x.abs() > v1.y.abs() {
        Vec3::new(-v1.z, 0.0, v1.x) / (v1.x * v1.x + v1.z * v1.z).sqrt()
    } else {
        Vec3::new(0.0, v1.z, -v1.y) / (v1.y * v1.y + v1.z * v1.z).sqrt()
    };
    (v2, v1.cross(v2))
}

/// A point sampled on a shape, with its density.
#[derive(Clone, Copy, Debug)]
pub struct ShapeSample {
    pub point: SurfacePoint,
    /// Density with respect to area, or to solid angle for `sample_from`.
    pub pdf: f32,
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// A sphere of radius `R` about the origin: hit point and differential
    /// geometry (any tangent basis works for the test; n = p/R, so the
    /// normal's derivatives are the position's over R).
    const R: f64 = 1.3;

    fn sphere_hit(o: DVec3, d: DVec3) -> Option<DVec3> {
        let b = o.dot(d);
        let c = o.length_squared() - R * R;
        let disc = b * b - c;
        if disc < 0.0 {
            return None;
        }
        let (t0, t1) = (-b - disc.sqrt(), -b + disc.sqrt());
        let t = if t0 > 1e-9 { t0 } else { t1 };
        (t > 1e-9).then(|| o + t * d)
    }

    fn geom_at(p: DVec3) -> DiffGeom {
        let n = p.normalize().as_vec3();
        let (t1, t2) = coordinate_system(n);
        let (dpdu, dpdv) = (2.0 * t1, 0.5 * t2 + 0.3 * t1);
        DiffGeom {
            dpdu,
            dpdv,
            shading_dpdu: dpdu,
            shading_dpdv: dpdv,
            dndu: dpdu / R as f32,
            dndv: dpdv / R as f32,
            shading_dndu: dpdu / R as f32,
            shading_dndv: dpdv / R as f32,
            ..DiffGeom::ZERO
        }
    }

    /// Snell's law for unit `wo` (pointing away from the surface) and `n` on
    /// its side; `eta` = the incident side's index over the other's.
    fn refract(wo: DVec3, n: DVec3, eta: f64) -> DVec3 {
        let c = wo.dot(n);
        let ct = (1.0 - eta * eta * (1.0 - c * c)).sqrt();
        -eta * wo + (eta * c - ct) * n
    }

    fn reflect(wo: DVec3, n: DVec3) -> DVec3 {
        -wo + 2.0 * wo.dot(n) * n
    }

    /// A main ray and offset rays `EPS` away in origin and direction.
    const EPS: f64 = 1e-3;

    fn rays(o: DVec3, d: DVec3) -> [(DVec3, DVec3); 3] {
        let d = d.normalize();
        let (a, b) = (DVec3::new(0.3, -0.2, 0.5), DVec3::new(-0.4, 0.1, 0.7));
        [
            (o, d),
            (o + EPS * a, (d + EPS * b).normalize()),
            (o - EPS * b, (d + EPS * a.cross(d)).normalize()),
        ]
    }

    fn ray_diff(r: &[(DVec3, DVec3); 3]) -> RayDiff {
        RayDiff {
            rx_o: r[1].0.as_vec3(),
            rx_d: r[1].1.as_vec3(),
            ry_o: r[2].0.as_vec3(),
            ry_d: r[2].1.as_vec3(),
        }
    }

    /// `got` − `base` equals `want` − `base` to first order in EPS.
    fn first_order(got: Vec3, want: DVec3, base: DVec3, what: &str) {
        let (g, w) = (got.as_dvec3() - base, want - base);
        assert!(
            (g - w).length() <= 0.02 * w.length() + 1e-6,
            "{what}: {g} vs {w}"
        );
    }

    /// The offset rays cross the tangent plane at p + dp/dx, and the uv
    /// derivatives rebuild dp/dx in the (dp/du, dp/dv) basis.
    #[test]
    fn differentials_are_the_offset_rays_on_the_tangent_plane() {
        let r = rays(DVec3::new(0.2, 0.4, -4.0), DVec3::new(0.05, -0.1, 1.0));
        let p = sphere_hit(r[0].0, r[0].1).unwrap();
        let n = p.normalize();
        let mut g = geom_at(p);
        g.compute_differentials(p.as_vec3(), n.as_vec3(), &ray_diff(&r));
        for (k, (dp, du, dv)) in [(g.dpdx, g.dudx, g.dvdx), (g.dpdy, g.dudy, g.dvdy)]
            .into_iter()
            .enumerate()
        {
            let (o, d) = r[k + 1];
            let on_plane = o + d * ((p - o).dot(n) / d.dot(n));
            assert!((dp.as_dvec3() - (on_plane - p)).length() < 1e-5, "{dp}");
            assert!(dp.length() > 1e-4, "{dp}");
            let rebuilt = du * g.dpdu + dv * g.dpdv;
            assert!(
                (rebuilt - dp).length() < 1e-5 * (1.0 + dp.length()),
                "{rebuilt} vs {dp}"
            );
        }
        // Offset rays parallel to the plane: no differentials.
        let mut flat = geom_at(p);
        let along = RayDiff {
            rx_d: g.dpdu.normalize(),
            ..ray_diff(&r)
        };
        flat.compute_differentials(p.as_vec3(), n.as_vec3(), &along);
        assert_eq!((flat.dpdx, flat.dudx, flat.dvdy), (Vec3::ZERO, 0.0, 0.0));
    }

    /// Through a curved mirror and a curved interface (both ways), the
    /// differentials of the bounced ray are, to first order, the offset
    /// rays bounced at their own hit points.
    #[test]
    fn reflected_and_transmitted_differentials_follow_the_offset_rays() {
        let eta = 1.5;
        for (name, o, d) in [
            (
                "outside",
                DVec3::new(0.3, 0.5, -4.0),
                DVec3::new(0.0, -0.05, 1.0),
            ),
            (
                "inside",
                DVec3::new(0.1, -0.2, 0.3),
                DVec3::new(0.2, 0.3, 1.0),
            ),
        ] {
            let r = rays(o, d);
            let diff = ray_diff(&r);
            let p = sphere_hit(r[0].0, r[0].1).unwrap();
            let n = p.normalize();
            let mut g = geom_at(p);
            g.compute_differentials(p.as_vec3(), n.as_vec3(), &diff);
            let wo = -r[0].1;
            let bounce = |k: usize, transmit: bool| {
                let (o, d) = r[k];
                let q = sphere_hit(o, d).unwrap();
                let m = q.normalize();
                let wo = -d;
                let dir = if !transmit {
                    reflect(wo, m)
                } else if wo.dot(m) > 0.0 {
                    refract(wo, m, 1.0 / eta)
                } else {
                    refract(wo, -m, eta)
                };
                (q, dir)
            };
            let (_, wi_r) = bounce(0, false);
            let rd = g.reflected(
                p.as_vec3(),
                n.as_vec3(),
                wo.as_vec3(),
                wi_r.as_vec3(),
                &diff,
            );
            let (_, wi_t) = bounce(0, true);
            let td = g.transmitted(
                p.as_vec3(),
                n.as_vec3(),
                wo.as_vec3(),
                wi_t.as_vec3(),
                eta as f32,
                &diff,
            );
            for (k, transmit) in [(1, false), (2, false), (1, true), (2, true)] {
                let (q, dir) = bounce(k, transmit);
                let (dd, base_d, od) = match (k, transmit) {
                    (1, false) => (rd.rx_d, wi_r, rd.rx_o),
                    (2, false) => (rd.ry_d, wi_r, rd.ry_o),
                    (1, true) => (td.rx_d, wi_t, td.rx_o),
                    _ => (td.ry_d, wi_t, td.ry_o),
                };
                let what = format!("{name}, ray {k}, transmit {transmit}");
                first_order(od, q, p, &format!("{what}: origin"));
                first_order(dd, dir, base_d, &format!("{what}: direction"));
            }
        }
    }

    /// A flat mirror reflects the offset rays exactly.
    #[test]
    fn flat_mirror_reflects_the_offset_rays() {
        let g = DiffGeom {
            dpdu: Vec3::X,
            dpdv: Vec3::Z,
            ..DiffGeom::ZERO
        };
        let mut g = g;
        let (p, n) = (Vec3::new(0.5, 0.0, 0.2), Vec3::Y);
        let diff = RayDiff {
            rx_o: Vec3::new(0.0, 2.0, 0.0),
            rx_d: Vec3::new(0.27, -1.0, 0.1).normalize(),
            ry_o: Vec3::new(0.0, 2.0, 0.0),
            ry_d: Vec3::new(0.25, -1.0, 0.13).normalize(),
        };
        let d = Vec3::new(0.25, -1.0, 0.1).normalize();
        g.compute_differentials(p, n, &diff);
        let wi = Vec3::new(d.x, -d.y, d.z);
        let rd = g.reflected(p, n, -d, wi, &diff);
        let mirror = |v: Vec3| Vec3::new(v.x, -v.y, v.z);
        assert!((rd.rx_d - mirror(diff.rx_d)).length() < 1e-6);
        assert!((rd.ry_d - mirror(diff.ry_d)).length() < 1e-6);
        assert!(rd.rx_o.y.abs() < 1e-6 && rd.ry_o.y.abs() < 1e-6);
    }
}
