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
