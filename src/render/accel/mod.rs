//! Acceleration: one compressed wide BVH (obvhs's CWBVH) over every primitive
//! of the scene, with closest-hit and occlusion queries.

use crate::render::geometry::{Bounds3, Ray};
use crate::render::shapes::{intersect_triangle, Sphere, SurfacePoint, TriangleMesh};
use glam::{DVec3, Vec3, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::RayHit;
use obvhs::BvhBuildParams;
use std::time::Duration;

const SPHERE_TAG: u32 = u32::MAX;

/// A primitive: triangle `index` of mesh `mesh`, or sphere `index` when
/// `mesh == SPHERE_TAG`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PrimRef {
    mesh: u32,
    index: u32,
}

impl PrimRef {
    pub fn triangle(mesh: u32, tri: u32) -> Self {
        Self { mesh, index: tri }
    }
    pub fn sphere(i: u32) -> Self {
        Self {
            mesh: SPHERE_TAG,
            index: i,
        }
    }
}

/// What a closest-hit query found.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    pub t: f32,
    pub prim: PrimRef,
    local: HitLocal,
}

#[derive(Clone, Copy, Debug)]
enum HitLocal {
    Bary([f32; 3]),
    SpherePoint(DVec3),
}

/// Everything a surface hit needs for shading.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceHit {
    pub point: SurfacePoint,
    pub material: u32,
    /// The area light of this primitive, if it emits.
    pub light: Option<u32>,
}

/// All geometry of a scene and the BVH over it.
pub struct Geometry {
    pub meshes: Vec<TriangleMesh>,
    pub spheres: Vec<Sphere>,
    /// Primitives in BVH order (so leaves index them directly).
    prims: Vec<PrimRef>,
    bvh: Option<CwBvh>,
    pub bounds: Bounds3,
    /// Length of ray directions as obvhs sees them (see `to_obvhs_ray`).
    ray_length: f32,
    /// Triangles left out because they have zero area.
    pub degenerate_triangles: u64,
    pub build_time: Duration,
}

/// obvhs's node test clamps the entry distance to an absolute 1e-4 (its
/// `EPSILON`), which would cull real hits closer than that in small scenes.
/// So obvhs gets the ray with its direction scaled by an exact power of two
/// `k` chosen so that |d|·k is 1e-12 of the scene's size: obvhs's parameter is
/// t' = t / k, every hit farther than ~1e-16 of the scene's size has t' > 1e-4,
/// and nothing overflows for any scene scale.
#[inline]
fn to_obvhs_ray(ray: &Ray, target_len: f32) -> (obvhs::ray::Ray, f32) {
    let len = ray.d.length();
    let want = target_len / len;
    // Round to a power of two (keep only sign and exponent bits): exact scaling.
    let k = if want.is_finite() && want > 0.0 {
        f32::from_bits(want.to_bits() & 0x7f80_0000).max(f32::MIN_POSITIVE)
    } else {
        1.0
    };
    let d = ray.d * k;
    // Finite reciprocals (no inf·0 = NaN in the slab tests), with the sign
    // obvhs assumes: it picks near and far planes by `direction < 0.0`,
    // which is false for -0.0, so -0.0 must get a positive reciprocal.
    let inv = |x: f32| {
        if x.abs() < 1e-30 {
            if x < 0.0 {
                -1e30
            } else {
                1e30
            }
        } else {
            1.0 / x
        }
    };
    let r = obvhs::ray::Ray {
        origin: Vec3A::from(ray.o),
        direction: Vec3A::from(d),
        inv_direction: Vec3A::new(inv(d.x), inv(d.y), inv(d.z)),
        tmin: 0.0,
        tmax: ray.t_max / k,
    };
    (r, k)
}

impl Geometry {
    /// Builds the BVH (in parallel, with obvhs's PLOC builder). Zero-area
    /// triangles are left out; an empty scene builds no BVH at all.
    pub fn new(meshes: Vec<TriangleMesh>, spheres: Vec<Sphere>) -> Geometry {
        let start = std::time::Instant::now();
        let mut prims = Vec::new();
        let mut aabbs = Vec::new();
        let mut bounds = Bounds3::EMPTY;
        let mut degenerate = 0u64;
        for (mi, m) in meshes.iter().enumerate() {
            for t in 0..m.triangle_count() {
                if m.is_degenerate(t) {
                    degenerate += 1;
                    continue;
                }
                let b = m.bounds(t);
                bounds = bounds.union(&b);
                prims.push(PrimRef::triangle(mi as u32, t));
                aabbs.push(Aabb::new(b.min.into(), b.max.into()));
            }
        }
        for (si, s) in spheres.iter().enumerate() {
            let b = s.bounds();
            if !(b.min.is_finite() && b.max.is_finite()) || s.radius <= 0.0 {
                continue;
            }
            bounds = bounds.union(&b);
            prims.push(PrimRef::sphere(si as u32));
            aabbs.push(Aabb::new(b.min.into(), b.max.into()));
        }
        let bvh = if prims.is_empty() {
            None
        } else {
            let mut t = Duration::ZERO;
            let bvh =
                obvhs::cwbvh::builder::build_cwbvh(&aabbs, BvhBuildParams::medium_build(), &mut t);
            prims = bvh
                .primitive_indices
                .iter()
                .map(|&i| prims[i as usize])
                .collect();
            Some(bvh)
        };
        let size = if bounds.is_empty() {
            1.0
        } else {
            bounds
                .diagonal()
                .length()
                .max(bounds.max.abs().max_element())
        };
        let ray_length = if size.is_finite() && size > 0.0 {
            size * 1e-12
        } else {
            1e-12
        };
        Geometry {
            meshes,
            spheres,
            prims,
            bvh,
            bounds,
            ray_length,
            degenerate_triangles: degenerate,
            build_time: start.elapsed(),
        }
    }

    pub fn primitive_count(&self) -> usize {
        self.prims.len()
    }

    pub fn has_bvh(&self) -> bool {
        self.bvh.is_some()
    }

    #[inline]
    fn intersect_prim(
        &self,
        prim: PrimRef,
        o: Vec3,
        d: Vec3,
        t_max: f32,
    ) -> Option<(f32, HitLocal)> {
        if prim.mesh == SPHERE_TAG {
            let s = &self.spheres[prim.index as usize];
            s.intersect(o, d, t_max)
                .map(|(t, p)| (t, HitLocal::SpherePoint(p)))
        } else {
            let m = &self.meshes[prim.mesh as usize];
            let [p0, p1, p2] = m.vertices(prim.index);
            intersect_triangle(o, d, t_max, p0, p1, p2).map(|(t, b)| (t, HitLocal::Bary(b)))
        }
    }

    /// Closest hit along the ray, if any.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        let bvh = self.bvh.as_ref()?;
        let mut rh = RayHit::none();
        let mut best: Option<Hit> = None;
        let (o, d) = (ray.o, ray.d);
        let (r, k) = to_obvhs_ray(ray, self.ray_length);
        bvh.ray_traverse(r, &mut rh, |r, id| {
            let prim = self.prims[id];
            match self.intersect_prim(prim, o, d, (r.tmax * k).min(ray.t_max)) {
                Some((t, local)) => {
                    best = Some(Hit { t, prim, local });
                    t / k
                }
                None => f32::INFINITY,
            }
        });
        best
    }

    /// True if anything blocks the ray before `t_max`.
    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        let Some(bvh) = self.bvh.as_ref() else {
            return false;
        };
        let (o, d, t_max) = (ray.o, ray.d, ray.t_max);
        let (r, k) = to_obvhs_ray(ray, self.ray_length);
        !bvh.ray_traverse_miss(r, |_, id| {
            match self.intersect_prim(self.prims[id], o, d, t_max) {
                Some((t, _)) => t / k,
                None => f32::INFINITY,
            }
        })
    }

    /// Shading data of a hit.
    #[inline]
    pub fn surface(&self, hit: &Hit) -> SurfaceHit {
        match hit.local {
            HitLocal::Bary(b) => {
                let m = &self.meshes[hit.prim.mesh as usize];
                SurfaceHit {
                    point: m.surface_point(hit.prim.index, b),
                    material: m.material,
                    light: m.first_light.map(|l| l + hit.prim.index),
                }
            }
            HitLocal::SpherePoint(p) => {
                let s = &self.spheres[hit.prim.index as usize];
                SurfaceHit {
                    point: s.surface_point(p),
                    material: s.material,
                    light: s.light,
                }
            }
        }
    }
}
