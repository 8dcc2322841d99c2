//! Lights: diffuse area lights (one per triangle, as pbrt-v3, or per sphere),
//! point, spot, distant and constant infinite lights; and the distributions
//! that choose which light to sample.

mod distribution;

pub use distribution::{LightSampler, LightSamplerKind};

use crate::render::accel::Geometry;
use crate::render::geometry::{luminance, spawn_ray, spawn_ray_to, spawn_ray_to_point, Frame, Ray};
use crate::render::sampling::{uniform_sample_sphere, uniform_sphere_pdf};
use crate::render::shapes::{intersect_triangle, sample_triangle_point, ShapeSample, SurfacePoint};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// The shape an area light sits on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AreaShape {
    Triangle { mesh: u32, tri: u32 },
    Sphere(u32),
}

/// World-space vertices of a triangle light, cached so that sampling it does
/// not go through the mesh; `n` is its oriented unit normal when that is the
/// same over the whole triangle (always, unless per-vertex normals disagree
/// in orientation), else zero.
#[derive(Clone, Copy, Debug, Default)]
pub struct TriangleCache {
    pub p: [Vec3; 3],
    pub n: Vec3,
}

impl TriangleCache {
    pub fn new(geom: &Geometry, mesh: u32, tri: u32) -> TriangleCache {
        let m = &geom.meshes[mesh as usize];
        let p = m.vertices(tri);
        let corners =
            [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]].map(|b| m.oriented_normal(tri, b));
        let constant =
            corners[0] == corners[1] && corners[1] == corners[2] && corners[0].is_finite();
        TriangleCache {
            p,
            n: if constant { corners[0] } else { Vec3::ZERO },
        }
    }
}

#[derive(Clone, Copy, Debug)]
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
        l: Vec3,
        n_samples: u32,
        scene_radius: f32,
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
            }
            | Light::Infinite {
                l, scene_radius, ..
            } => l * PI * scene_radius * scene_radius,
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

    /// Radiance arriving along a ray that escapes the scene.
    #[inline]
    pub fn le_escaped(&self) -> Vec3 {
        match *self {
            Light::Infinite { l, .. } => l,
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
                    AreaShape::Triangle { mesh, tri } => {
                        let s = if cache.n != Vec3::ZERO {
                            // pbrt-v3 Triangle::Sample from the cached vertices.
                            let (_, p, p_error) = sample_triangle_point(cache.p, u);
                            ShapeSample {
                                point: SurfacePoint {
                                    p,
                                    p_error,
                                    n: cache.n,
                                    ns: cache.n,
                                },
                                pdf: 1.0 / area,
                            }
                        } else {
                            geom.meshes[mesh as usize].sample_area(tri, u)
                        };
                        crate::render::shapes::to_solid_angle(r.p, s)?
                    }
                    AreaShape::Sphere(i) => {
                        geom.spheres[i as usize].sample_from(r.p, r.p_error, r.n, u)?
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
            Light::Infinite { l, .. } => {
                let wi = uniform_sample_sphere(u);
                // Anything in the way occludes an infinitely distant light.
                let shadow = spawn_ray(r.p, r.p_error, r.n, wi);
                Some(LightSample {
                    li: l,
                    wi,
                    pdf: uniform_sphere_pdf(),
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
            Light::Infinite { .. } => uniform_sphere_pdf(),
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
                    AreaShape::Triangle { .. } => {
                        let [p0, p1, p2] = tri.p;
                        match intersect_triangle(ray.o, ray.d, ray.t_max, p0, p1, p2) {
                            // dist²/(|cos θ'|·area) = 2t²/|(e1×e2)·d| for unit d.
                            Some((t, _)) => {
                                let pdf = 2.0 * t * t / (p1 - p0).cross(p2 - p0).dot(ray.d).abs();
                                if pdf.is_finite() {
                                    pdf
                                } else {
                                    0.0
                                }
                            }
                            None => 0.0,
                        }
                    }
                    AreaShape::Sphere(i) => {
                        let s = &geom.spheres[i as usize];
                        s.pdf_from(r.p, r.p_error, r.n, wi, |o, d| {
                            s.intersect(o, d, f32::INFINITY)
                        })
                    }
                }
            }
            Light::Infinite { .. } => uniform_sphere_pdf(),
            _ => 0.0,
        }
    }
}
