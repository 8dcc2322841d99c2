use super::{ShapeSample, SurfacePoint};
use crate::render::geometry::{face_forward, gamma, Bounds3};
use crate::render::sampling::uniform_sample_triangle;
use glam::{Vec2, Vec3};

/// A triangle mesh with vertices in world space. Vertex arrays are shared by
/// all triangles (32-bit indices).
#[derive(Clone, Debug)]
pub struct TriangleMesh {
    pub p: Vec<Vec3>,
    /// Per-vertex normals in world space (unnormalised allowed).
    pub n: Option<Vec<Vec3>>,
    pub uv: Option<Vec<Vec2>>,
    pub indices: Vec<u32>,
    /// ReverseOrientation XOR the transform swaps handedness.
    pub flip_normal: bool,
    pub material: u32,
    /// Index of the area light of this mesh's first triangle; triangle `i`
    /// has light `first_light + i` (one light per triangle, as pbrt-v3).
    pub first_light: Option<u32>,
}

impl TriangleMesh {
    #[inline]
    pub fn vertices(&self, tri: u32) -> [Vec3; 3] {
        let i = 3 * tri as usize;
        [
            self.p[self.indices[i] as usize],
            self.p[self.indices[i + 1] as usize],
            self.p[self.indices[i + 2] as usize],
        ]
    }

    pub fn triangle_count(&self) -> u32 {
        (self.indices.len() / 3) as u32
    }

    pub fn area(&self, tri: u32) -> f32 {
        let [p0, p1, p2] = self.vertices(tri);
        0.5 * (p1 - p0).cross(p2 - p0).length()
    }

    pub fn bounds(&self, tri: u32) -> Bounds3 {
        let [p0, p1, p2] = self.vertices(tri);
        Bounds3::from_point(p0).union_point(p1).union_point(p2)
    }

    /// True if the triangle has zero area or non-finite vertices: such
    /// triangles are left out of the scene (they can never be seen).
    pub fn is_degenerate(&self, tri: u32) -> bool {
        let [p0, p1, p2] = self.vertices(tri);
        let l2 = (p0 - p2).cross(p1 - p2).length_squared();
        let finite = p0.is_finite() && p1.is_finite() && p2.is_finite() && l2.is_finite();
        !finite || l2 <= 0.0
    }

    /// Oriented normals at barycentrics (b0, b1, b2), as pbrt-v3's triangle.cpp.
    #[inline]
    fn normals_at(&self, tri: u32, b: [f32; 3], geometric: Vec3) -> (Vec3, Vec3) {
        let mut n = geometric;
        if self.flip_normal {
            n = -n;
        }
        if let Some(normals) = &self.n {
            let i = 3 * tri as usize;
            let ns = b[0] * normals[self.indices[i] as usize]
                + b[1] * normals[self.indices[i + 1] as usize]
                + b[2] * normals[self.indices[i + 2] as usize];
            let l2 = ns.length_squared();
            if l2 > 0.0 && l2.is_finite() {
                let ns = ns / l2.sqrt();
                // Per-vertex normals are authoritative for orientation.
                return (face_forward(geometric, ns), ns);
            }
        }
        (n, n)
    }

    /// The oriented geometric normal at barycentrics `b` (no position, no
    /// error bound: for estimates).
    #[inline]
    pub fn oriented_normal(&self, tri: u32, b: [f32; 3]) -> Vec3 {
        let [p0, p1, p2] = self.vertices(tri);
        let geometric = (p0 - p2).cross(p1 - p2).normalize();
        self.normals_at(tri, b, geometric).0
    }

    /// The surface point at barycentrics `b` (b0 + b1 + b2 = 1).
    #[inline]
    pub fn surface_point(&self, tri: u32, b: [f32; 3]) -> SurfacePoint {
        let [p0, p1, p2] = self.vertices(tri);
        let p = b[0] * p0 + b[1] * p1 + b[2] * p2;
        let p_error = gamma(7) * ((b[0] * p0).abs() + (b[1] * p1).abs() + (b[2] * p2).abs());
        let geometric = (p0 - p2).cross(p1 - p2).normalize();
        let (n, ns) = self.normals_at(tri, b, geometric);
        SurfacePoint { p, p_error, n, ns }
    }

    /// Uniform sample by area (pbrt-v3 Triangle::Sample).
    pub fn sample_area(&self, tri: u32, u: Vec2) -> ShapeSample {
        let (b, p, p_error) = sample_triangle_point(self.vertices(tri), u);
        let mut point = self.surface_point(tri, b);
        point.p = p;
        point.p_error = p_error;
        ShapeSample {
            point,
            pdf: 1.0 / self.area(tri),
        }
    }
}

/// A uniformly sampled point of a triangle (pbrt-v3 Triangle::Sample):
/// barycentrics, position, and the position's error bound.
#[inline]
pub fn sample_triangle_point(p: [Vec3; 3], u: Vec2) -> ([f32; 3], Vec3, Vec3) {
    let b = uniform_sample_triangle(u);
    let b = [b.x, b.y, 1.0 - b.x - b.y];
    let q = b[0] * p[0] + b[1] * p[1] + b[2] * p[2];
    let err = gamma(6) * ((b[0] * p[0]).abs() + (b[1] * p[1]).abs() + (b[2] * p[2]).abs());
    (b, q, err)
}

/// pbrt-v3's watertight ray–triangle test with its conservative check that
/// t is positive. Returns (t, [b0, b1, b2]).
#[inline]
pub fn intersect_triangle(
    o: Vec3,
    d: Vec3,
    t_max: f32,
    p0: Vec3,
    p1: Vec3,
    p2: Vec3,
) -> Option<(f32, [f32; 3])> {
    TriangleRay::new(o, d).intersect(t_max, p0, p1, p2)
}

/// The per-ray part of pbrt-v3's watertight triangle test (the axis
/// permutation and the shear), computed once per ray instead of once per
/// triangle. The permutation is applied with static swizzles: `kz` is the
/// same for every triangle a ray meets, so the branch on it is predicted.
#[derive(Clone, Copy, Debug)]
pub struct TriangleRay {
    o: Vec3,
    kz: u8,
    /// (Sx, Sy, Sz) of pbrt-v3.
    shear: Vec3,
}

impl TriangleRay {
    #[inline]
    pub fn new(o: Vec3, d: Vec3) -> TriangleRay {
        let ad = d.abs();
        let kz = if ad.x > ad.y {
            if ad.x > ad.z {
                0
            } else {
                2
            }
        } else if ad.y > ad.z {
            1
        } else {
            2
        };
        let dp = permute(kz, d);
        let sz = 1.0 / dp.z;
        TriangleRay {
            o,
            kz,
            shear: Vec3::new(-dp.x * sz, -dp.y * sz, sz),
        }
    }

    /// Hit distance and barycentrics for `0 < t < t_max`.
    #[inline(always)]
    pub fn intersect(&self, t_max: f32, p0: Vec3, p1: Vec3, p2: Vec3) -> Option<(f32, [f32; 3])> {
        match self.kz {
            0 => self.intersect_k::<0>(t_max, p0, p1, p2),
            1 => self.intersect_k::<1>(t_max, p0, p1, p2),
            _ => self.intersect_k::<2>(t_max, p0, p1, p2),
        }
    }

    #[inline(always)]
    fn intersect_k<const KZ: u8>(
        &self,
        t_max: f32,
        p0: Vec3,
        p1: Vec3,
        p2: Vec3,
    ) -> Option<(f32, [f32; 3])> {
        // Translate to the ray origin, permute so z is the largest direction axis.
        let mut p0t = permute(KZ, p0 - self.o);
        let mut p1t = permute(KZ, p1 - self.o);
        let mut p2t = permute(KZ, p2 - self.o);
        // Shear so the ray runs along +z.
        let (sx, sy, sz) = (self.shear.x, self.shear.y, self.shear.z);
        p0t.x += sx * p0t.z;
        p0t.y += sy * p0t.z;
        p1t.x += sx * p1t.z;
        p1t.y += sy * p1t.z;
        p2t.x += sx * p2t.z;
        p2t.y += sy * p2t.z;
        let mut e0 = p1t.x * p2t.y - p1t.y * p2t.x;
        let mut e1 = p2t.x * p0t.y - p2t.y * p0t.x;
        let mut e2 = p0t.x * p1t.y - p0t.y * p1t.x;
        if e0 == 0.0 || e1 == 0.0 || e2 == 0.0 {
            // Exactly on an edge in f32: decide in f64 (watertightness).
            e0 = (p1t.x as f64 * p2t.y as f64 - p1t.y as f64 * p2t.x as f64) as f32;
            e1 = (p2t.x as f64 * p0t.y as f64 - p2t.y as f64 * p0t.x as f64) as f32;
            e2 = (p0t.x as f64 * p1t.y as f64 - p0t.y as f64 * p1t.x as f64) as f32;
        }
        if (e0 < 0.0 || e1 < 0.0 || e2 < 0.0) && (e0 > 0.0 || e1 > 0.0 || e2 > 0.0) {
            return None;
        }
        let det = e0 + e1 + e2;
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        p0t.z *= sz;
        p1t.z *= sz;
        p2t.z *= sz;
        let t_scaled = e0 * p0t.z + e1 * p1t.z + e2 * p2t.z;
        if det < 0.0 && (t_scaled >= 0.0 || t_scaled < t_max * det) {
            return None;
        }
        if det > 0.0 && (t_scaled <= 0.0 || t_scaled > t_max * det) {
            return None;
        }
        let inv_det = 1.0 / det;
        let t = t_scaled * inv_det;
        // Conservatively reject hits whose t cannot be told apart from zero.
        let max_zt = p0t.z.abs().max(p1t.z.abs()).max(p2t.z.abs());
        let delta_z = gamma(3) * max_zt;
        let max_xt = p0t.x.abs().max(p1t.x.abs()).max(p2t.x.abs());
        let max_yt = p0t.y.abs().max(p1t.y.abs()).max(p2t.y.abs());
        let delta_x = gamma(5) * (max_xt + max_zt);
        let delta_y = gamma(5) * (max_yt + max_zt);
        let delta_e = 2.0 * (gamma(2) * max_xt * max_yt + delta_y * max_xt + delta_x * max_yt);
        let max_e = e0.abs().max(e1.abs()).max(e2.abs());
        let delta_t =
            3.0 * (gamma(3) * max_e * max_zt + delta_e * max_zt + delta_z * max_e) * inv_det.abs();
        if t <= delta_t {
            return None;
        }
        Some((t, [e0 * inv_det, e1 * inv_det, e2 * inv_det]))
    }
}

/// pbrt-v3's permutation (kx, ky, kz) = (kz+1, kz+2, kz) mod 3, as a swizzle.
#[inline(always)]
fn permute(kz: u8, v: Vec3) -> Vec3 {
    match kz {
        0 => Vec3::new(v.y, v.z, v.x),
        1 => Vec3::new(v.z, v.x, v.y),
        _ => v,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hits_inside_misses_outside() {
        let (p0, p1, p2) = (
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        );
        let h = intersect_triangle(
            Vec3::new(0.2, 0.2, 1.0),
            -Vec3::Z,
            f32::INFINITY,
            p0,
            p1,
            p2,
        )
        .unwrap();
        assert!((h.0 - 1.0).abs() < 1e-6);
        let p = h.1[0] * p0 + h.1[1] * p1 + h.1[2] * p2;
        assert!((p - Vec3::new(0.2, 0.2, 0.0)).length() < 1e-6);
        assert!(intersect_triangle(
            Vec3::new(0.8, 0.8, 1.0),
            -Vec3::Z,
            f32::INFINITY,
            p0,
            p1,
            p2
        )
        .is_none());
        assert!(
            intersect_triangle(Vec3::new(0.2, 0.2, 1.0), Vec3::Z, f32::INFINITY, p0, p1, p2)
                .is_none()
        );
        assert!(intersect_triangle(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z, 0.5, p0, p1, p2).is_none());
    }

    #[test]
    fn degenerate_triangle_never_hits() {
        let (p0, p1, p2) = (Vec3::ZERO, Vec3::X, Vec3::X * 2.0);
        for d in [-Vec3::Z, Vec3::new(0.1, 0.0, -1.0), Vec3::Y] {
            assert!(
                intersect_triangle(Vec3::new(0.5, 0.0, 1.0), d, f32::INFINITY, p0, p1, p2)
                    .is_none()
            );
        }
    }
}
