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

use glam::Vec3;

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

/// A point sampled on a shape, with its density.
#[derive(Clone, Copy, Debug)]
pub struct ShapeSample {
    pub point: SurfacePoint,
    /// Density with respect to area, or to solid angle for `sample_from`.
    pub pdf: f32,
}
