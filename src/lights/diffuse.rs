//! `diffuse` (alias `area`), the one `AreaLightSource` type: every later
//! shape in the attribute scope emits `L`·`scale` from its surface (pbrt-v3's
//! `DiffuseAreaLight`), one light per triangle of a mesh, as pbrt-v3, or
//! one per analytic shape. The statement builds a [`DiffuseEmission`];
//! `RenderScene::new` makes each shape's [`DiffuseLight`] from it once the
//! shape is in world space.
//!
//! | parameter | type | pbrt-v3 default | |
//! |---|---|---|---|
//! | `L` | spectrum | 1 | emitted radiance |
//! | `scale` | spectrum or float | 1 | multiplies `L` (pbrt-v3 reads a spectrum; pbrs also takes a float) |
//! | `twosided` | bool | false | emits on both sides (else along the surface normal only) |
//! | `nsamples` | integer | 1 | shadow samples for `directlighting` "all" |
//! | `samples` | integer | `nsamples` | the same; wins over `nsamples` |
//!
//! Sampling: by area on the shape (pbrt-v3's `Shape::Sample`, with the
//! sphere's cone sampling from outside), converted to solid angle; a
//! triangle of constant normal samples from a cache of its world-space
//! vertices ([`TriangleCache`]), with no visit to its mesh.

use super::bvh::LightBounds;
use super::{contribution_by_sampling, AreaLightKind, EmittedRay, LightModel, LightSample};
use crate::accel::Aggregate;
use crate::geometry::{luminance, spawn_ray, spawn_ray_to, Bounds3, Frame, Ray};
use crate::sampling::{cosine_hemisphere_pdf, cosine_sample_hemisphere, ONE_MINUS_EPSILON};
use crate::scene::{ParamSpec, ParamValues, Support};
use crate::shapes::{sample_triangle_point, SurfacePoint};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::spectrum_any("L", [1.0; 3], "emitted radiance"),
    ParamSpec::spectrum_or_float(
        "scale",
        [1.0; 3],
        "multiplies L (a spectrum in pbrt-v3; pbrs also takes a float)",
    ),
    ParamSpec::boolean(
        "twosided",
        false,
        "emit on both sides of the surface (else along its normal only)",
    ),
    ParamSpec::int(
        "nsamples",
        1,
        "shadow samples for directlighting's \"all\" strategy (at least 1)",
    ),
    ParamSpec::int_opt("samples", "the same as nsamples, which it overrides"),
];

pub const KIND: AreaLightKind = AreaLightKind {
    name: "diffuse",
    aliases: &["area"],
    support: Support::Supported,
    params: PARAMS,
    doc: "uniform emission L·scale from every later shape of the attribute scope (pbrt-v3's DiffuseAreaLight)",
    build: |p, _| DiffuseEmission::new(p),
};

/// The most shadow samples a light takes (the loader's sample limit).
const MAX_SAMPLES: i32 = 1 << 24;

/// What `AreaLightSource "diffuse"` says about the shapes after it: each
/// one's [`DiffuseLight`] is made from this in `RenderScene::new`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiffuseEmission {
    /// Emitted radiance, `L` times `scale`.
    pub l: Vec3,
    pub two_sided: bool,
    pub n_samples: u32,
}

impl DiffuseEmission {
    pub fn new(p: &ParamValues) -> DiffuseEmission {
        let n = p.int_opt("samples").unwrap_or(p.int("nsamples"));
        DiffuseEmission {
            l: p.spectrum("L") * p.spectrum("scale"),
            two_sided: p.boolean("twosided"),
            n_samples: n.clamp(1, MAX_SAMPLES) as u32,
        }
    }
}

/// The area light of one triangle or analytic shape.
#[derive(Clone, Copy, Debug)]
pub struct DiffuseLight {
    pub shape: AreaShape,
    pub l: Vec3,
    pub two_sided: bool,
    pub n_samples: u32,
    pub area: f32,
    /// The triangle's cache (all zero for an analytic shape).
    pub tri: TriangleCache,
}

impl DiffuseLight {
    /// `sample_li` with the sampled point of the light and its normal
    /// (what a bidirectional method's light vertex needs).
    #[inline(always)]
    pub fn sample_li_at(
        &self,
        r: &SurfacePoint,
        u: Vec2,
        geom: &Aggregate,
    ) -> Option<(LightSample, Vec3, Vec3)> {
        let (l, two_sided, area, cache) = (self.l, self.two_sided, self.area, self.tri);
        let s = match self.shape {
            AreaShape::Triangle { .. } if cache.n != Vec3::ZERO => {
                return cache.sample_li(r, u, l, two_sided, area);
            }
            AreaShape::Triangle { mesh, tri } => {
                let s = geom.meshes[mesh as usize].sample_area(tri, u);
                crate::shapes::to_solid_angle(r.p, s)?
            }
            AreaShape::Analytic(i) => {
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
        let shadow = spawn_ray_to(r.p, r.p_error, r.n, s.point.p, s.point.p_error, s.point.n);
        Some((
            LightSample {
                li,
                wi,
                pdf: s.pdf,
                shadow,
            },
            s.point.p,
            s.point.n,
        ))
    }

    /// The light of `shape` (already in `geom`) emitting as `e` says.
    pub fn new(e: DiffuseEmission, shape: AreaShape, geom: &Aggregate) -> DiffuseLight {
        let (area, tri) = match shape {
            AreaShape::Triangle { mesh, tri } => (
                geom.meshes[mesh as usize].area(tri),
                TriangleCache::new(geom, mesh, tri),
            ),
            AreaShape::Analytic(i) => (geom.quadrics[i as usize].area(), TriangleCache::default()),
        };
        DiffuseLight {
            shape,
            l: e.l,
            two_sided: e.two_sided,
            n_samples: e.n_samples.max(1),
            area,
            tri,
        }
    }
}

impl LightModel for DiffuseLight {
    #[inline]
    fn is_delta(&self) -> bool {
        false
    }

    fn n_samples(&self) -> u32 {
        self.n_samples.max(1)
    }

    fn n_samples_mut(&mut self) -> Option<&mut u32> {
        Some(&mut self.n_samples)
    }

    fn power(&self) -> Vec3 {
        self.l * self.area * PI * if self.two_sided { 2.0 } else { 1.0 }
    }

    #[inline]
    fn emitted(&self, n: Vec3, w: Vec3) -> Vec3 {
        if self.two_sided || n.dot(w) > 0.0 {
            self.l
        } else {
            Vec3::ZERO
        }
    }

    #[inline]
    fn contribution(&self, p: Vec3, u: Vec2, geom: &Aggregate) -> f32 {
        let AreaShape::Triangle { mesh, tri: t } = self.shape else {
            return contribution_by_sampling(self, p, u, geom);
        };
        let tri = &self.tri;
        let (b, q, _) = sample_triangle_point(tri.p, u);
        let d = q - p;
        let dist2 = d.length_squared();
        let n = if tri.n != Vec3::ZERO {
            tri.n
        } else {
            geom.meshes[mesh as usize].oriented_normal(t, b)
        };
        let cos = -n.dot(d) / dist2.sqrt();
        if dist2 == 0.0 || (!self.two_sided && cos <= 0.0) {
            return 0.0;
        }
        luminance(self.l) * cos.abs() * self.area / dist2
    }

    #[inline]
    fn sample_li(&self, r: &SurfacePoint, u: Vec2, geom: &Aggregate) -> Option<LightSample> {
        self.sample_li_at(r, u, geom).map(|(ls, _, _)| ls)
    }

    /// pbrt-v3's `Pdf_Li`: the ray is tested against the light's own shape
    /// only.
    #[inline]
    fn pdf_li(&self, r: &SurfacePoint, wi: Vec3, geom: &Aggregate) -> f32 {
        self.pdf_li_ray(r, &spawn_ray(r.p, r.p_error, r.n, wi), geom)
    }

    #[inline]
    fn pdf_li_ray(&self, r: &SurfacePoint, ray: &Ray, geom: &Aggregate) -> f32 {
        match self.shape {
            AreaShape::Triangle { .. } => self.tri.hit_pdf(ray),
            AreaShape::Analytic(i) => {
                geom.quadrics[i as usize].pdf_from(r.p, r.p_error, r.n, ray.d)
            }
        }
    }

    /// pbrt-v3's: uniform by area on the shape, cosine-weighted about the
    /// normal (on both sides for a two-sided light).
    fn pdf_le(&self, d: Vec3, n: Vec3) -> (f32, f32) {
        let cos = n.dot(d);
        let pdf_dir = if self.two_sided {
            0.5 * cosine_hemisphere_pdf(cos.abs())
        } else {
            cosine_hemisphere_pdf(cos).max(0.0)
        };
        (1.0 / self.area, pdf_dir)
    }

    /// pbrt-v3's: a point uniform by area on the shape (`u1`), a direction
    /// by cosine around its normal (`u2`; for a two-sided light `u2.x`
    /// first chooses the side).
    fn sample_le(&self, u1: Vec2, u2: Vec2, geom: &Aggregate) -> Option<EmittedRay> {
        let s = match self.shape {
            AreaShape::Triangle { mesh, tri } => geom.meshes[mesh as usize].sample_area(tri, u1),
            AreaShape::Analytic(i) => geom.quadrics[i as usize].sample_area(u1)?,
        };
        let (w, pdf_dir) = if self.two_sided {
            let (x, flip) = if u2.x < 0.5 {
                ((u2.x * 2.0).min(ONE_MINUS_EPSILON), false)
            } else {
                (((u2.x - 0.5) * 2.0).min(ONE_MINUS_EPSILON), true)
            };
            let mut w = cosine_sample_hemisphere(Vec2::new(x, u2.y));
            if flip {
                w.z = -w.z;
            }
            (w, 0.5 * cosine_hemisphere_pdf(w.z.abs()))
        } else {
            let w = cosine_sample_hemisphere(u2);
            (w, cosine_hemisphere_pdf(w.z))
        };
        let n = s.point.n;
        let w = Frame::from_normal(n).from_local(w);
        if !(s.pdf > 0.0 && pdf_dir > 0.0) {
            return None;
        }
        Some(EmittedRay {
            le: self.emitted(n, w),
            ray: spawn_ray(s.point.p, s.point.p_error, n, w),
            n,
            pdf_pos: s.pdf,
            pdf_dir,
        })
    }

    /// pbrt-v4's: the shape's bounds, its normal's cone (the whole sphere
    /// unless the normal is constant), φ = L·area (twice for two-sided).
    fn bounds(&self, geom: &Aggregate) -> Option<LightBounds> {
        let phi = luminance(self.l) * self.area * if self.two_sided { 2.0 } else { 1.0 };
        let tri = self.tri;
        let (bounds, w, cos_theta_o) = match self.shape {
            AreaShape::Triangle { .. } => {
                let bounds = Bounds3::from_point(tri.p[0])
                    .union_point(tri.p[1])
                    .union_point(tri.p[2]);
                if tri.n != Vec3::ZERO {
                    (bounds, tri.n, 1.0)
                } else {
                    (bounds, Vec3::Z, -1.0)
                }
            }
            AreaShape::Analytic(i) => (geom.quadrics[i as usize].bounds(), Vec3::Z, -1.0),
        };
        Some(LightBounds {
            bounds,
            w,
            phi,
            cos_theta_o,
            cos_theta_e: 0.0,
            two_sided: self.two_sided,
        })
    }
}

/// The shape an area light sits on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AreaShape {
    Triangle {
        mesh: u32,
        tri: u32,
    },
    /// A sphere, disk or other analytic shape of `Aggregate::quadrics`.
    Analytic(u32),
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
    pub(super) plane: Vec3,
    pub(super) bary: [Vec3; 2],
}

/// Slack of `TriangleCache::hit_pdf`'s inside test, in barycentric units:
/// rays this close outside an edge count as hits (the caller's trace then
/// decides), so that no ray the watertight test would accept is refused.
pub(super) const HIT_SLACK: f32 = 1e-4;

impl TriangleCache {
    pub fn new(geom: &Aggregate, mesh: u32, tri: u32) -> TriangleCache {
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
    ) -> Option<(LightSample, Vec3, Vec3)> {
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
        Some((
            LightSample {
                li,
                wi,
                pdf,
                shadow: spawn_ray_to(r.p, r.p_error, r.n, p, p_error, self.n),
            },
            p,
            self.n,
        ))
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::rng::Pcg32;
    use crate::shapes::intersect_triangle;

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
