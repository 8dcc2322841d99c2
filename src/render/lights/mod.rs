//! Lights: diffuse area lights (one per triangle, as pbrt-v3, or per sphere),
//! point, spot, distant and infinite lights (constant or an environment
//! map, [`infinite`]); and the distributions that choose which light to
//! sample.

pub mod bvh;
mod distribution;
pub mod infinite;
mod pack;

pub use distribution::{LightSampler, LightSamplerKind, SPATIAL_MAX_LIGHTS};
pub use infinite::{EnvMap, EnvSampling};
pub use pack::{dot3, lane3, pack_triangle_lights, splat3, TriangleLightPack, Vec3x4};

use crate::render::accel::Geometry;
use crate::render::geometry::{luminance, spawn_ray, spawn_ray_to, spawn_ray_to_point, Frame, Ray};
use crate::render::shapes::{sample_triangle_point, SurfacePoint};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;
use std::sync::Arc;

/// The shape an area light sits on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AreaShape {
    Triangle {
        mesh: u32,
        tri: u32,
    },
    /// A sphere, disk or other analytic shape of `Geometry::quadrics`.
    Quadric(u32),
}

/// World-space vertices of a triangle light, cached so that sampling it does
/// not go through the mesh; `n` is its oriented unit normal when that is the
/// same over the whole triangle (always, unless per-vertex normals disagree
/// in orientation), else zero. `plane` and `bary` are what `hit_pdf` needs
/// to test a ray against the triangle without the watertight test's per-ray
/// setup: e1×e2, and the two vectors whose dot products with a point's
/// offset from `p[0]` are its barycentrics b1 and b2.
#[derive(Clone, Copy, Debug, Default)]
pub struct TriangleCache {
    pub p: [Vec3; 3],
    pub n: Vec3,
    plane: Vec3,
    bary: [Vec3; 2],
}

/// Slack of `TriangleCache::hit_pdf`'s inside test, in barycentric units:
/// rays this close outside an edge count as hits (the caller's trace then
/// decides), so that no ray the watertight test would accept is refused.
const HIT_SLACK: f32 = 1e-4;

impl TriangleCache {
    pub fn new(geom: &Geometry, mesh: u32, tri: u32) -> TriangleCache {
        let m = &geom.meshes[mesh as usize];
        let p = m.vertices(tri);
        let corners =
            [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]].map(|b| m.oriented_normal(tri, b));
        let constant =
            corners[0] == corners[1] && corners[1] == corners[2] && corners[0].is_finite();
        Self::from_vertices(p, if constant { corners[0] } else { Vec3::ZERO })
    }

    /// The cache of a triangle with vertices `p` and constant normal `n`
    /// (zero if it is not constant).
    pub fn from_vertices(p: [Vec3; 3], n: Vec3) -> TriangleCache {
        let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
        let plane = e1.cross(e2);
        let inv = 1.0 / plane.length_squared();
        TriangleCache {
            p,
            n,
            plane,
            // b1 = (q × e2)·(e1 × e2)/|e1 × e2|² = q·(e2 × (e1 × e2))/|…|², and
            // b2 = q·((e1 × e2) × e1)/|…|² for q in the plane.
            bary: [e2.cross(plane) * inv, plane.cross(e1) * inv],
        }
    }

    /// `Light::sample_li` for a triangle of constant normal: pbrt-v3's
    /// Triangle::Sample from the cached vertices, converted to solid angle,
    /// with one square root and two divisions (the distance serves the
    /// direction and the density).
    #[inline]
    fn sample_li(
        &self,
        r: &SurfacePoint,
        u: Vec2,
        l: Vec3,
        two_sided: bool,
        area: f32,
    ) -> Option<LightSample> {
        let (_, p, p_error) = sample_triangle_point(self.p, u);
        let d = p - r.p;
        let dist2 = d.length_squared();
        let dist = dist2.sqrt();
        let wi = d * (1.0 / dist);
        // dist²/(|cos θ'|·area) with |cos θ'| = |n·d|/dist.
        let n_dot_d = self.n.dot(d);
        let pdf = dist2 * dist / (n_dot_d.abs() * area);
        // Also refuses dist = 0 (NaN) and grazing samples (infinite).
        if !(pdf > 0.0 && pdf < f32::INFINITY) {
            return None;
        }
        let li = if two_sided || n_dot_d < 0.0 {
            l
        } else {
            Vec3::ZERO
        };
        Some(LightSample {
            li,
            wi,
            pdf,
            shadow: spawn_ray_to(r.p, r.p_error, r.n, p, p_error, self.n),
        })
    }

    /// Solid-angle density 2t²/|(e1×e2)·d| of area-sampling this triangle
    /// towards the point where `ray` (unit direction) crosses it, or 0 if it
    /// does not: pbrt-v3's Pdf_Li for a triangle. The plane is intersected
    /// directly and the barycentrics come from the precomputed vectors, with
    /// no branches until the end (the directions tested are random, so a
    /// branchy test is mispredicted often). Edges are accepted with a slack
    /// of `HIT_SLACK`; callers trace the ray to find what it really hits, so
    /// a few extra accepted rays cost a trace, never bias. A degenerate
    /// triangle gives NaN arithmetic and so 0.
    #[inline]
    pub fn hit_pdf(&self, ray: &Ray) -> f32 {
        // One division: t and the density both use 1/((e1×e2)·d).
        let inv = 1.0 / self.plane.dot(ray.d);
        let t = self.plane.dot(self.p[0] - ray.o) * inv;
        let q = (ray.o - self.p[0]) + t * ray.d;
        let b1 = q.dot(self.bary[0]);
        let b2 = q.dot(self.bary[1]);
        let pdf = 2.0 * t * t * inv.abs();
        let hit = (t > 0.0)
            & (t < ray.t_max)
            & (b1 >= -HIT_SLACK)
            & (b2 >= -HIT_SLACK)
            & (b1 + b2 <= 1.0 + HIT_SLACK)
            & (pdf < f32::INFINITY);
        if hit {
            pdf
        } else {
            0.0
        }
    }
}

#[derive(Clone, Debug)]
pub enum Light {
    Area {
        shape: AreaShape,
        l: Vec3,
        two_sided: bool,
        n_samples: u32,
        area: f32,
        tri: TriangleCache,
    },
    Point {
        p: Vec3,
        intensity: Vec3,
    },
    Spot {
        p: Vec3,
        frame: Frame,
        intensity: Vec3,
        cos_total: f32,
        cos_falloff_start: f32,
    },
    /// `w` points towards the light.
    Distant {
        w: Vec3,
        l: Vec3,
        scene_radius: f32,
    },
    Infinite {
        n_samples: u32,
        scene_radius: f32,
        map: Arc<EnvMap>,
    },
}

/// A light sample as seen from a reference point.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    pub li: Vec3,
    pub wi: Vec3,
    /// Solid-angle density (1 for delta lights).
    pub pdf: f32,
    /// The shadow ray to test; unoccluded means the light is seen.
    pub shadow: Ray,
}

impl Light {
    /// Delta lights cannot be hit by rays (no BSDF sample for them in MIS).
    #[inline]
    pub fn is_delta(&self) -> bool {
        matches!(
            self,
            Light::Point { .. } | Light::Spot { .. } | Light::Distant { .. }
        )
    }

    pub fn is_infinite(&self) -> bool {
        matches!(self, Light::Infinite { .. })
    }

    pub fn n_samples(&self) -> u32 {
        match *self {
            Light::Area { n_samples, .. } | Light::Infinite { n_samples, .. } => n_samples.max(1),
            _ => 1,
        }
    }

    /// Luminance of the emitted power (pbrt-v3's `Power().y()`).
    pub fn power(&self) -> f32 {
        let p = match *self {
            Light::Area {
                l, two_sided, area, ..
            } => l * area * PI * if two_sided { 2.0 } else { 1.0 },
            Light::Point { intensity, .. } => 4.0 * PI * intensity,
            Light::Spot {
                intensity,
                cos_total,
                cos_falloff_start,
                ..
            } => intensity * 2.0 * PI * (1.0 - 0.5 * (cos_falloff_start + cos_total)),
            Light::Distant {
                l, scene_radius, ..
            } => l * PI * scene_radius * scene_radius,
            Light::Infinite {
                scene_radius,
                ref map,
                ..
            } => map.power_radiance() * PI * scene_radius * scene_radius,
        };
        luminance(p).max(0.0)
    }

    /// Emitted radiance of an area light at a point with normal `n`, towards `w`.
    #[inline]
    pub fn emitted(&self, n: Vec3, w: Vec3) -> Vec3 {
        match *self {
            Light::Area { l, two_sided, .. } if two_sided || n.dot(w) > 0.0 => l,
            _ => Vec3::ZERO,
        }
    }

    /// Radiance arriving along a ray with direction `d` that escapes the
    /// scene (pbrt-v3's `Le`).
    #[inline]
    pub fn le(&self, d: Vec3) -> Vec3 {
        match self {
            Light::Infinite { map, .. } => map.le(d),
            _ => Vec3::ZERO,
        }
    }

    /// A cheap estimate of luminance(Li)/pdf at a point in space, for the
    /// spatial light distribution: the same sampling as `sample_li`, with no
    /// shadow ray and no error bounds (pbrt-v3 also ignores visibility here).
    pub fn contribution_estimate(&self, p: Vec3, u: Vec2, geom: &Geometry) -> f32 {
        let c = match *self {
            Light::Area {
                shape: AreaShape::Triangle { mesh, tri: t },
                l,
                two_sided,
                area,
                tri,
                ..
            } => {
                let (b, q, _) = sample_triangle_point(tri.p, u);
                let d = q - p;
                let dist2 = d.length_squared();
                let n = if tri.n != Vec3::ZERO {
                    tri.n
                } else {
                    geom.meshes[mesh as usize].oriented_normal(t, b)
                };
                let cos = -n.dot(d) / dist2.sqrt();
                if dist2 == 0.0 || (!two_sided && cos <= 0.0) {
                    return 0.0;
                }
                luminance(l) * cos.abs() * area / dist2
            }
            _ => {
                let r = SurfacePoint {
                    p,
                    p_error: Vec3::ZERO,
                    n: Vec3::ZERO,
                    ns: Vec3::ZERO,
                };
                match self.sample_li(&r, u, geom) {
                    Some(s) if s.pdf > 0.0 => luminance(s.li) / s.pdf,
                    _ => 0.0,
                }
            }
        };
        if c.is_finite() {
            c.max(0.0)
        } else {
            0.0
        }
    }

    /// Sample incident light at `r` (pbrt-v3's Sample_Li). Visibility is not
    /// tested here: the caller traces `shadow`.
    #[inline]
    pub fn sample_li(&self, r: &SurfacePoint, u: Vec2, geom: &Geometry) -> Option<LightSample> {
        match *self {
            Light::Area {
                shape,
                l,
                two_sided,
                area,
                tri: cache,
                ..
            } => {
                let s = match shape {
                    AreaShape::Triangle { .. } if cache.n != Vec3::ZERO => {
                        return cache.sample_li(r, u, l, two_sided, area);
                    }
                    AreaShape::Triangle { mesh, tri } => {
                        let s = geom.meshes[mesh as usize].sample_area(tri, u);
                        crate::render::shapes::to_solid_angle(r.p, s)?
                    }
                    AreaShape::Quadric(i) => {
                        geom.quadrics[i as usize].sample_from(r.p, r.p_error, r.n, u)?
                    }
                };
                let d = s.point.p - r.p;
                if d.length_squared() == 0.0 || s.pdf.is_nan() || s.pdf <= 0.0 {
                    return None;
                }
                let wi = d.normalize();
                let li = if two_sided || s.point.n.dot(-wi) > 0.0 {
                    l
                } else {
                    Vec3::ZERO
                };
                let shadow =
                    spawn_ray_to(r.p, r.p_error, r.n, s.point.p, s.point.p_error, s.point.n);
                Some(LightSample {
                    li,
                    wi,
                    pdf: s.pdf,
                    shadow,
                })
            }
            Light::Point { p, intensity } => {
                let d = p - r.p;
                let d2 = d.length_squared();
                if d2 == 0.0 {
                    return None;
                }
                Some(LightSample {
                    li: intensity / d2,
                    wi: d / d2.sqrt(),
                    pdf: 1.0,
                    shadow: spawn_ray_to_point(r.p, r.p_error, r.n, p),
                })
            }
            Light::Spot {
                p,
                frame,
                intensity,
                cos_total,
                cos_falloff_start,
            } => {
                let d = p - r.p;
                let d2 = d.length_squared();
                if d2 == 0.0 {
                    return None;
                }
                let wi = d / d2.sqrt();
                let cos = frame.to_local(-wi).z;
                let falloff = if cos < cos_total {
                    0.0
                } else if cos > cos_falloff_start {
                    1.0
                } else {
                    let delta = (cos - cos_total) / (cos_falloff_start - cos_total);
                    (delta * delta) * (delta * delta)
                };
                Some(LightSample {
                    li: intensity * falloff / d2,
                    wi,
                    pdf: 1.0,
                    shadow: spawn_ray_to_point(r.p, r.p_error, r.n, p),
                })
            }
            Light::Distant { w, l, scene_radius } => {
                let far = r.p + w * (2.0 * scene_radius);
                Some(LightSample {
                    li: l,
                    wi: w,
                    pdf: 1.0,
                    shadow: spawn_ray_to_point(r.p, r.p_error, r.n, far),
                })
            }
            Light::Infinite { ref map, .. } => {
                let (wi, li, pdf) = map.sample(u)?;
                // Anything in the way occludes an infinitely distant light.
                let shadow = spawn_ray(r.p, r.p_error, r.n, wi);
                Some(LightSample {
                    li,
                    wi,
                    pdf,
                    shadow,
                })
            }
        }
    }

    /// Solid-angle density of `sample_li` producing direction `wi` from `r`
    /// (pbrt-v3's Pdf_Li: for area lights, the ray is tested against the
    /// light's own shape only). 0 when `wi` cannot come from this light.
    #[inline]
    pub fn pdf_li(&self, r: &SurfacePoint, wi: Vec3, geom: &Geometry) -> f32 {
        match *self {
            Light::Area { .. } => self.pdf_li_ray(r, &spawn_ray(r.p, r.p_error, r.n, wi), geom),
            Light::Infinite { ref map, .. } => map.pdf(wi),
            _ => 0.0,
        }
    }

    /// `pdf_li` for the direction of `ray`, which must be the ray spawned
    /// from `r` in that direction (`spawn_ray(r.p, r.p_error, r.n, wi)`):
    /// for callers that trace that ray anyway.
    #[inline]
    pub fn pdf_li_ray(&self, r: &SurfacePoint, ray: &Ray, geom: &Geometry) -> f32 {
        match *self {
            Light::Area { shape, tri, .. } => {
                let wi = ray.d;
                match shape {
                    AreaShape::Triangle { .. } => tri.hit_pdf(ray),
                    AreaShape::Quadric(i) => {
                        geom.quadrics[i as usize].pdf_from(r.p, r.p_error, r.n, wi)
                    }
                }
            }
            Light::Infinite { ref map, .. } => map.pdf(ray.d),
            _ => 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::sampling::rng::Pcg32;
    use crate::render::shapes::intersect_triangle;

    fn cache(p: [Vec3; 3]) -> TriangleCache {
        TriangleCache::from_vertices(p, (p[1] - p[0]).cross(p[2] - p[0]).normalize())
    }

    /// `hit_pdf` against pbrt-v3's watertight test: every ray the watertight
    /// test accepts is accepted with the same density (to rounding), and
    /// every ray accepted beyond it passes within the slack of an edge.
    #[test]
    fn hit_pdf_agrees_with_the_watertight_test() {
        let mut rng = Pcg32::with_sequence(3);
        let mut u = || rng.uniform_f32();
        let (mut hits, mut extra) = (0, 0);
        for scale in [1e-4f32, 1.0, 1e4] {
            for _ in 0..20_000 {
                let mut v = || Vec3::new(u() - 0.5, u() - 0.5, u() - 0.5) * 2.0 * scale;
                let p = [v(), v(), v()];
                let c = cache(p);
                let o = v() * 3.0;
                // Aim near the triangle (sometimes just outside it).
                let (a, b) = (u() * 1.2 - 0.1, u() * 1.2 - 0.1);
                let target = p[0] + a * (p[1] - p[0]) + b * (p[2] - p[0]);
                let d = (target - o).normalize();
                if !d.is_finite() {
                    continue;
                }
                let ray = Ray::new(o, d);
                let fast = c.hit_pdf(&ray);
                match intersect_triangle(o, d, f32::INFINITY, p[0], p[1], p[2]) {
                    Some((t, _)) => {
                        let plane = (p[1] - p[0]).cross(p[2] - p[0]);
                        let want = 2.0 * t * t / plane.dot(d).abs();
                        if want.is_finite() {
                            hits += 1;
                            // Both distances round; at grazing incidence
                            // the relative error grows as 1/|cos|.
                            let cond = plane.length() / plane.dot(d).abs();
                            assert!(
                                (fast - want).abs() <= 1e-5 * cond.max(1.0) * want,
                                "pdf {fast} vs {want} (scale {scale}, 1/cos {cond})"
                            );
                        }
                    }
                    None if fast > 0.0 => {
                        extra += 1;
                        // Outside the watertight test: only near an edge.
                        let near = a.abs() < 1e-3 || b.abs() < 1e-3 || (a + b - 1.0).abs() < 1e-3;
                        assert!(near, "accepted at ({a}, {b})");
                    }
                    None => {}
                }
            }
        }
        assert!(hits > 15_000, "{hits} hits");
        assert!(
            extra < 100,
            "{extra} rays accepted beyond the watertight test"
        );
    }

    #[test]
    fn hit_pdf_of_a_degenerate_triangle_is_zero() {
        let p = Vec3::new(1.0, 2.0, 3.0);
        let c = cache([p, p, p + Vec3::X]);
        let ray = Ray::new(Vec3::ZERO, p.normalize());
        assert_eq!(c.hit_pdf(&ray), 0.0);
    }
}
