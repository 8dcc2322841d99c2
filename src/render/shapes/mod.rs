//! Shapes in world space: triangle meshes and spheres, with intersection,
//! surface interactions carrying error bounds, and sampling for area lights.

mod sphere;
mod triangle;

pub use sphere::Sphere;
pub use sphere::{area_to_solid_angle, to_solid_angle};
pub use triangle::{
    intersect_triangle, pack_triangles, sample_triangle_point, TriangleMesh, TrianglePack,
    TriangleRay, TriangleRay4,
};

use crate::render::geometry::RayDiff;
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
