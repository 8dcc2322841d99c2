//! Acceleration: BVHs built by obvhs and traced four-wide in SIMD
//! ([`bvh4`]), with closest-hit and occlusion queries, in two levels.
//!
//! - The scene level: one BVH over the world-space primitives (triangles of
//!   meshes, quadrics) and over the world bounds of object instances.
//! - The object level: one BVH per instanced object, over its primitives in
//!   the object's own space. An instance is a transform and an object index, so
//!   a thousand instances of an object cost a thousand transforms, not a
//!   thousand copies of its triangles (the scene level's leaf callback traces
//!   the object's BVH).
//!
//! Instance rays are the world ray mapped to object space by the inverse
//! transform without renormalising the direction, so `t` means the same at
//! both levels and the closest hit is found across levels by `t` alone.

mod binned;
mod bvh4;
mod packet;
mod split;
mod stream;

pub use bvh4::BuildWork;
pub use packet::PACKET_MAX;

use crate::geometry::{gamma, next_float_down, next_float_up, Bounds3, Ray};
use crate::scene::AnimatedTransform;
use crate::shapes::{
    intersect_triangle, AnalyticHit, AnalyticShape, DiffGeom, SurfacePoint, TriangleMesh,
};
use bvh4::{Bvh4, Closest};
use glam::{DMat3, DMat4, DVec3, Mat3, Vec3};
use obvhs::aabb::Aabb;
use obvhs::BvhBuildParams;
use std::sync::Arc;
use std::time::Duration;

const QUADRIC_TAG: u32 = u32::MAX;
const INSTANCE_TAG: u32 = u32::MAX - 1;
const MOVING_TAG: u32 = u32::MAX - 2;
/// `Hit::instance` for a hit on world-space geometry.
const NO_INSTANCE: u32 = u32::MAX;

/// A primitive: triangle `index` of mesh `mesh`, quadric `index` when
/// `mesh == QUADRIC_TAG`, instance `index` when `mesh == INSTANCE_TAG`, or
/// moving instance `index` when `mesh == MOVING_TAG`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PrimRef {
    mesh: u32,
    index: u32,
}

impl PrimRef {
    pub fn triangle(mesh: u32, tri: u32) -> Self {
        Self { mesh, index: tri }
    }
    pub fn quadric(i: u32) -> Self {
        Self {
            mesh: QUADRIC_TAG,
            index: i,
        }
    }
    fn instance(i: u32) -> Self {
        Self {
            mesh: INSTANCE_TAG,
            index: i,
        }
    }
    fn moving(i: u32) -> Self {
        Self {
            mesh: MOVING_TAG,
            index: i,
        }
    }
}

/// What a closest-hit query found.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    pub t: f32,
    /// The primitive hit (of the instance's object when `instance` is set).
    pub prim: PrimRef,
    /// The instance hit: an index into the instances, or into the moving
    /// instances with `MOVING_BIT` set, or `NO_INSTANCE`.
    instance: u32,
    local: HitLocal,
}

/// Set in `Hit::instance` for a moving instance.
const MOVING_BIT: u32 = 1 << 31;

#[derive(Clone, Copy, Debug)]
enum HitLocal {
    Bary([f32; 3]),
    Analytic(AnalyticHit),
}

/// Everything a surface hit needs for shading.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceHit {
    pub point: SurfacePoint,
    pub material: u32,
    /// The area light of this primitive, if it emits.
    pub light: Option<u32>,
    /// The time of the ray that found it (pbrt-v3's `Interaction::time`):
    /// the rays spawned here are traced at it.
    pub time: f32,
}

/// The BVH over shapes in one space (world space for the scene
/// level, object space for an object).
struct Level {
    /// Primitives in BVH order (so leaves index them directly).
    prims: Vec<PrimRef>,
    bvh: Option<Bvh4>,
    bounds: Bounds3,
    degenerate: u64,
    build: BuildWork,
}

/// An object definition, built once and shared by all its instances.
pub struct Object {
    meshes: Vec<TriangleMesh>,
    quadrics: Vec<AnalyticShape>,
    level: Level,
}

impl Object {
    /// Builds the object's BVH over its shapes (given in object space).
    pub fn new(meshes: Vec<TriangleMesh>, quadrics: Vec<AnalyticShape>) -> Object {
        let level = Level::build(&meshes, &quadrics, &[], &[]);
        Object {
            meshes,
            quadrics,
            level,
        }
    }

    pub fn triangle_count(&self) -> u64 {
        self.meshes.iter().map(|m| m.triangle_count() as u64).sum()
    }

    pub fn bounds(&self) -> Bounds3 {
        self.level.bounds
    }

    pub fn is_empty(&self) -> bool {
        self.level.bvh.is_none()
    }

    fn shapes(&self) -> Shapes<'_> {
        Shapes {
            level: &self.level,
            meshes: &self.meshes,
            quadrics: &self.quadrics,
        }
    }
}

/// The transforms of an object placement (f64 for the ray and point
/// mappings, f32 for normals and error bounds).
#[derive(Clone, Copy, Debug)]
struct Placement {
    world_to_object: DMat4,
    object_to_world: DMat4,
    /// Linear part of object-to-world, entry-wise absolute, for error bounds.
    abs_linear: Mat3,
    /// |translation| of object-to-world, for error bounds.
    abs_translation: Vec3,
    /// Inverse transpose of the linear part: maps normals.
    normal_matrix: Mat3,
    /// The linear part: maps tangent vectors.
    linear: Mat3,
}

/// A placement of an object: its transforms.
pub struct Instance {
    object: Arc<Object>,
    place: Placement,
}

/// An object placed by a transform that moves over the shutter (an
/// animated `ObjectInstance`, or an animated shape, which pbrs makes a
/// one-shape object as pbrt-v3 wraps it in a `TransformedPrimitive`). Rays
/// map to object space by the transform interpolated at their time.
pub struct MovingInstance {
    object: Arc<Object>,
    motion: Arc<AnimatedTransform>,
}

impl Placement {
    /// `None` if the transform cannot be inverted.
    #[inline]
    fn new(object_to_world: DMat4) -> Option<Placement> {
        let lin = DMat3::from_mat4(object_to_world);
        let det = lin.determinant();
        if !(det.is_finite() && det != 0.0 && object_to_world.is_finite()) {
            return None;
        }
        let world_to_object = object_to_world.inverse();
        if !world_to_object.is_finite() {
            return None;
        }
        let l = lin.as_mat3();
        Some(Placement {
            world_to_object,
            object_to_world,
            abs_linear: Mat3::from_cols(l.x_axis.abs(), l.y_axis.abs(), l.z_axis.abs()),
            abs_translation: object_to_world.w_axis.truncate().as_vec3().abs(),
            normal_matrix: lin.inverse().transpose().as_mat3(),
            linear: l,
        })
    }

    /// The world ray in object space (same `t` parameterisation).
    #[inline]
    fn object_ray(&self, ray: &Ray) -> Ray {
        object_ray(&self.world_to_object, ray)
    }

    /// An object-space surface point in world space: the position mapped in
    /// f64, its error bound grown conservatively (pbrt-v3's
    /// `Transform::operator()(p, pError, &absError)`), normals by the inverse
    /// transpose, as pbrt-v3's `TransformedPrimitive` does.
    ///
    /// Orientation: the object-space normal is already oriented (the shape's
    /// ReverseOrientation and handedness, inside the object). The instance's
    /// handedness adds no flip: for triangles this gives exactly the side a
    /// placed (non-instanced) copy gets, because a placed mesh's normal is the
    /// cross product of world-space edges, which a mirror flips once and its
    /// `flip_normal` flips back. For spheres under a mirroring instance it
    /// differs from a placed sphere as it does in pbrt-v3 (a placed sphere's
    /// normal is flipped by its transform's handedness; an instance's is not).
    #[inline]
    fn point_to_world(&self, s: SurfacePoint, has_vertex_normals: bool) -> SurfacePoint {
        let p = self
            .object_to_world
            .transform_point3(s.p.as_dvec3())
            .as_vec3();
        let p_error = (1.0 + gamma(3)) * (self.abs_linear * s.p_error)
            + gamma(3) * (self.abs_linear * s.p.abs() + self.abs_translation);
        let mut n = (self.normal_matrix * s.n).normalize();
        let ns = (self.normal_matrix * s.ns).normalize();
        if has_vertex_normals {
            // As for world-space meshes: per-vertex normals decide the side.
            n = crate::geometry::face_forward(n, ns);
        }
        SurfacePoint { p, p_error, n, ns }
    }

    /// Object-space differential geometry in world space: tangents by the
    /// linear part, normal derivatives by the inverse transpose.
    #[inline]
    fn geom_to_world(&self, g: DiffGeom) -> DiffGeom {
        let (l, n) = (self.linear, self.normal_matrix);
        DiffGeom {
            uv: g.uv,
            dpdu: l * g.dpdu,
            dpdv: l * g.dpdv,
            dndu: n * g.dndu,
            dndv: n * g.dndv,
            shading_dpdu: l * g.shading_dpdu,
            shading_dpdv: l * g.shading_dpdv,
            shading_dndu: n * g.shading_dndu,
            shading_dndv: n * g.shading_dndv,
            face_index: g.face_index,
            ..DiffGeom::ZERO
        }
    }
}

/// A world ray mapped by `world_to_object` (same `t` parameterisation).
#[inline]
fn object_ray(world_to_object: &DMat4, ray: &Ray) -> Ray {
    let o = world_to_object.transform_point3(ray.o.as_dvec3()).as_vec3();
    let d = world_to_object
        .transform_vector3(ray.d.as_dvec3())
        .as_vec3();
    Ray {
        o,
        d,
        t_max: ray.t_max,
    }
}

/// An f64 box rounded outwards to f32.
fn round_out(lo: DVec3, hi: DVec3) -> Bounds3 {
    let (lo, hi) = (lo.as_vec3(), hi.as_vec3());
    Bounds3::EMPTY
        .union_point(Vec3::new(
            next_float_down(lo.x),
            next_float_down(lo.y),
            next_float_down(lo.z),
        ))
        .union_point(Vec3::new(
            next_float_up(hi.x),
            next_float_up(hi.y),
            next_float_up(hi.z),
        ))
}

impl Instance {
    /// `None` if the transform cannot be inverted.
    pub fn new(object: Arc<Object>, object_to_world: DMat4) -> Option<Instance> {
        Some(Instance {
            object,
            place: Placement::new(object_to_world)?,
        })
    }

    pub fn object(&self) -> &Object {
        &self.object
    }

    /// World bounds: the object's box corners mapped to world space, rounded
    /// outwards.
    fn world_bounds(&self) -> Bounds3 {
        let b = self.object.level.bounds;
        let mut out = Bounds3::EMPTY;
        for i in 0..8 {
            let c = DVec3::new(
                if i & 1 == 0 { b.min.x } else { b.max.x } as f64,
                if i & 2 == 0 { b.min.y } else { b.max.y } as f64,
                if i & 4 == 0 { b.min.z } else { b.max.z } as f64,
            );
            let w = self.place.object_to_world.transform_point3(c);
            out = out.union(&round_out(w, w));
        }
        out
    }
}

impl MovingInstance {
    /// `None` if either keyframe transform cannot be inverted (a transform
    /// that is singular only between the keyframes makes the object vanish
    /// for the rays of those times).
    pub fn new(object: Arc<Object>, motion: Arc<AnimatedTransform>) -> Option<MovingInstance> {
        Placement::new(motion.start)?;
        Placement::new(motion.end)?;
        Some(MovingInstance { object, motion })
    }

    pub fn object(&self) -> &Object {
        &self.object
    }

    /// The placement at `time` (for shading a hit).
    #[inline]
    fn at(&self, time: f32) -> Option<Placement> {
        Placement::new(self.motion.interpolate(time as f64))
    }

    /// A world ray at `time` in object space (for intersection: only the
    /// inverse transform, from the interpolated parts), `None` if the
    /// transform is singular then.
    #[inline]
    fn object_ray_at(&self, ray: &Ray, time: f32) -> Option<Ray> {
        let m = self.motion.inverse_at(time as f64);
        m.is_finite().then(|| object_ray(&m, ray))
    }

    /// A box holding the object's bounds over the whole motion (pbrt-v3's
    /// `AnimatedTransform::MotionBounds`), rounded outwards.
    fn world_bounds(&self) -> Bounds3 {
        let b = self.object.level.bounds;
        let (lo, hi) = self
            .motion
            .motion_bounds(b.min.as_dvec3(), b.max.as_dvec3());
        round_out(lo, hi)
    }
}

impl Level {
    /// Builds the BVH over the shapes and the given extra boxes
    /// (instances): by obvhs's PLOC for small levels, by the binned builder
    /// for big ones, and by whichever gives the cheaper tree in between.
    /// Zero-area triangles are left out; an empty level builds no BVH at
    /// all.
    fn build(
        meshes: &[TriangleMesh],
        quadrics: &[AnalyticShape],
        extra: &[Bounds3],
        moving: &[Bounds3],
    ) -> Level {
        let triangles: usize = meshes.iter().map(|m| m.triangle_count() as usize).sum();
        let count = triangles + quadrics.len() + extra.len() + moving.len();
        if count > BINNED_MIN {
            return Level::build_binned(meshes, quadrics, extra, moving);
        }
        if count <= COMPARE_MIN {
            return Level::build_ploc(meshes, quadrics, extra, moving);
        }
        // Neither builder makes the better tree everywhere (the f16 of
        // pbrt-v3's caustic-glass scenes traces faster with the binned one,
        // the Stanford dragon with PLOC's): both are built, side by side
        // (PLOC's reinsertion pass is mostly on one thread), and the one the
        // surface area heuristic rates cheaper is kept.
        let (ploc, binned) = rayon::join(
            || Level::build_ploc(meshes, quadrics, extra, moving),
            || Level::build_binned(meshes, quadrics, extra, moving),
        );
        // Levels of many coincident boxes keep the bounded builder's tree
        // (see `split`), whose work `build` counts.
        if ploc.build.bounded {
            return ploc;
        }
        let cost = |l: &Level| l.bvh.as_ref().map_or(f64::INFINITY, |b| b.sah_cost());
        if cost(&binned) < cost(&ploc) {
            binned
        } else {
            ploc
        }
    }

    /// [`Level::build`] by obvhs's PLOC and the SAH collapse.
    fn build_ploc(
        meshes: &[TriangleMesh],
        quadrics: &[AnalyticShape],
        extra: &[Bounds3],
        moving: &[Bounds3],
    ) -> Level {
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
        for (si, s) in quadrics.iter().enumerate() {
            let b = s.bounds();
            if !(b.min.is_finite() && b.max.is_finite() && s.is_valid()) {
                continue;
            }
            bounds = bounds.union(&b);
            prims.push(PrimRef::quadric(si as u32));
            aabbs.push(Aabb::new(b.min.into(), b.max.into()));
        }
        let placed = extra
            .iter()
            .map(|b| (b, PrimRef::instance as fn(u32) -> PrimRef));
        let moved = moving
            .iter()
            .map(|b| (b, PrimRef::moving as fn(u32) -> PrimRef));
        for (ii, (b, tag)) in placed.enumerate().chain(moved.enumerate()) {
            if b.is_empty() || !(b.min.is_finite() && b.max.is_finite()) {
                continue;
            }
            bounds = bounds.union(b);
            prims.push(tag(ii as u32));
            aabbs.push(Aabb::new(b.min.into(), b.max.into()));
        }
        let mut build = BuildWork::default();
        let bvh = if prims.is_empty() {
            None
        } else {
            let (bvh, order, work) = Bvh4::build_counted(&aabbs, build_params(aabbs.len()), |i| {
                packed_vertices(meshes, prims[i])
            });
            prims = order.iter().map(|&i| prims[i as usize]).collect();
            build = work;
            Some(bvh)
        };
        Level {
            prims,
            bvh,
            bounds,
            degenerate,
            build,
        }
    }
}

/// The vertices of `p` if a leaf tests it in its triangle pack: a triangle
/// of a mesh without alpha masks. Those with masks are left to the leaf's
/// callbacks (like quadrics and instances), so that only they pay for the
/// test.
/// Asks for the vertex indices of triangle `p` (if it is one of `meshes`):
/// surface reconstruction reads them first, behind the primitive
/// reference, once a closest hit is known.
#[inline(always)]
fn prefetch_indices(meshes: &[TriangleMesh], p: PrimRef) {
    if let Some(m) = meshes.get(p.mesh as usize) {
        prefetch(m.indices.as_ptr().wrapping_add(3 * p.index as usize));
    }
}

/// The hit of triangle `prim` of a level's own meshes at distance `t`,
/// barycentrics `b`.
#[inline(always)]
fn triangle_hit(prim: PrimRef, t: f32, b: [f32; 3]) -> Hit {
    Hit {
        t,
        prim,
        instance: NO_INSTANCE,
        local: HitLocal::Bary(b),
    }
}

fn packed_vertices(meshes: &[TriangleMesh], p: PrimRef) -> Option<[Vec3; 3]> {
    let tagged = matches!(p.mesh, QUADRIC_TAG | INSTANCE_TAG | MOVING_TAG);
    (!tagged && meshes[p.mesh as usize].alpha.is_none())
        .then(|| meshes[p.mesh as usize].vertices(p.index))
}

/// Levels with more primitives than this are built by the parallel
/// binned-SAH builder ([`binned`]), which makes the four-wide tree directly
/// in a fraction of PLOC's memory; smaller ones by obvhs's PLOC and the SAH
/// collapse.
const BINNED_MIN: usize = 262_144;

/// Levels with more primitives than this (and at most [`BINNED_MIN`]) are
/// built by both builders, and keep the tree with the lower SAH cost.
const COMPARE_MIN: usize = 4096;

/// Bytes per primitive a big level's BVH holds at its peak: about 67
/// measured (10 M triangles: 64 in leaves of 3.8 triangles with their
/// vertices, nodes of 128 bytes, the 8-byte primitive order), with room for
/// worse-filled leaves; the build's own arrays (32-byte references) are
/// freed before the leaves are made.
pub const BVH_BYTES_PER_TRIANGLE: u64 = 80;
/// The same for small levels, built by PLOC (its binary tree, the
/// reinsertion and the collapse plan live next to the result).
const PLOC_BYTES_PER_PRIMITIVE: u64 = 320;

/// Most primitives one BVH level can hold (the binned builder packs a
/// leaf's first primitive and count into 31 bits).
pub const MAX_LEVEL_PRIMITIVES: u64 = (1 << 29) - 1;

/// The bytes a level's BVH over `primitives` will need at most (see
/// [`BVH_BYTES_PER_TRIANGLE`]), for the loader's memory check: levels that
/// build both trees side by side hold both builds at once.
pub fn bvh_memory_estimate(primitives: u64) -> u64 {
    if primitives > BINNED_MIN as u64 {
        primitives.saturating_mul(BVH_BYTES_PER_TRIANGLE)
    } else if primitives > COMPARE_MIN as u64 {
        primitives * (PLOC_BYTES_PER_PRIMITIVE + BVH_BYTES_PER_TRIANGLE)
    } else {
        primitives * PLOC_BYTES_PER_PRIMITIVE
    }
}

/// Primitives of a level numbered one after the other: each mesh's
/// triangles, the quadrics, the instances, the moving instances.
struct Numbering {
    /// First number of each mesh, and (last) the number of triangles.
    mesh_start: Vec<u32>,
    quadrics: u32,
    extra: u32,
}

impl Numbering {
    fn new(meshes: &[TriangleMesh], quadrics: usize, extra: usize) -> Numbering {
        let mut mesh_start = vec![0u32];
        for m in meshes {
            mesh_start.push(mesh_start.last().copied().unwrap_or(0) + m.triangle_count());
        }
        let triangles = *mesh_start.last().unwrap_or(&0);
        Numbering {
            mesh_start,
            quadrics: triangles + quadrics as u32,
            extra: triangles + (quadrics + extra) as u32,
        }
    }

    fn triangles(&self) -> u32 {
        *self.mesh_start.last().unwrap_or(&0)
    }

    #[inline]
    fn prim(&self, g: u32) -> PrimRef {
        let t = self.triangles();
        if g < t {
            let m = self.mesh_start.partition_point(|&s| s <= g) - 1;
            PrimRef::triangle(m as u32, g - self.mesh_start[m])
        } else if g < self.quadrics {
            PrimRef::quadric(g - t)
        } else if g < self.extra {
            PrimRef::instance(g - self.quadrics)
        } else {
            PrimRef::moving(g - self.extra)
        }
    }
}

impl Level {
    /// [`Level::build`] for big levels: references made in parallel
    /// straight from the shapes, the tree built by [`binned`] on all cores.
    fn build_binned(
        meshes: &[TriangleMesh],
        quadrics: &[AnalyticShape],
        extra: &[Bounds3],
        moving: &[Bounds3],
    ) -> Level {
        use rayon::prelude::*;
        let num = Numbering::new(meshes, quadrics.len(), extra.len());
        let total = num.extra as usize + moving.len();
        let boxed = |b: Bounds3, g: u32, triangle: bool| {
            if b.is_empty() || !(b.min.is_finite() && b.max.is_finite()) {
                binned::Ref::VOID
            } else {
                binned::Ref::new(b.min, b.max, g, triangle)
            }
        };
        let mut refs: Vec<binned::Ref> = (0..total as u32)
            .into_par_iter()
            .map(|g| match num.prim(g) {
                p if p.mesh == QUADRIC_TAG => {
                    let s = &quadrics[p.index as usize];
                    if s.is_valid() {
                        boxed(s.bounds(), g, false)
                    } else {
                        binned::Ref::VOID
                    }
                }
                p if p.mesh == INSTANCE_TAG => boxed(extra[p.index as usize], g, false),
                p if p.mesh == MOVING_TAG => boxed(moving[p.index as usize], g, false),
                p => {
                    let m = &meshes[p.mesh as usize];
                    if m.is_degenerate(p.index) {
                        binned::Ref::VOID
                    } else {
                        boxed(m.bounds(p.index), g, m.alpha.is_none())
                    }
                }
            })
            .collect();
        let degenerate = refs[..num.triangles() as usize]
            .par_iter()
            .filter(|r| r.is_void())
            .count() as u64;
        refs.retain(|r| !r.is_void());
        if refs.is_empty() {
            return Level {
                prims: Vec::new(),
                bvh: None,
                bounds: Bounds3::EMPTY,
                degenerate,
                build: BuildWork::default(),
            };
        }
        let (bvh, order, (lo, hi)) =
            Bvh4::build_binned(refs, |g| packed_vertices(meshes, num.prim(g as u32)));
        let prims: Vec<PrimRef> = order.par_iter().map(|&g| num.prim(g)).collect();
        let build = BuildWork {
            binned: true,
            work: (bvh.node_count() + bvh.leaf_count()) as u64,
            ..BuildWork::default()
        };
        Level {
            prims,
            bvh: Some(bvh),
            bounds: Bounds3::EMPTY.union_point(lo).union_point(hi),
            degenerate,
            build,
        }
    }
}

/// Asks for the cache line at `p` (a hint: nothing is read).
#[inline(always)]
pub(crate) fn prefetch<T>(p: *const T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch reads nothing and cannot fault.
    unsafe {
        std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>(p as *const i8);
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = p;
}

/// A level's BVH with the shapes its leaves refer to.
#[derive(Clone, Copy)]
struct Shapes<'a> {
    level: &'a Level,
    meshes: &'a [TriangleMesh],
    quadrics: &'a [AnalyticShape],
}

impl Shapes<'_> {
    /// Closest hit among this level's shapes with `t <= ray.t_max`;
    /// instances are resolved by `instance_hit`, moving ones by `moving_hit`.
    #[inline(always)]
    fn intersect(
        &self,
        ray: &Ray,
        mut instance_hit: impl FnMut(u32, f32) -> Option<Hit>,
        mut moving_hit: impl FnMut(u32, f32) -> Option<Hit>,
    ) -> Option<Hit> {
        let bvh = self.level.bvh.as_ref()?;
        // Quadrics and instances found so far (triangles come back as values).
        let mut other: Option<Hit> = None;
        let prims = &self.level.prims;
        let meshes = self.meshes;
        let hint = |pos: u32| prefetch_indices(meshes, prims[pos as usize]);
        let found = bvh.closest_hinted(
            ray,
            ray.t_max,
            |pos, t_max| {
                let prim = prims[pos as usize];
                let h = if prim.mesh == INSTANCE_TAG {
                    instance_hit(prim.index, t_max)
                } else if prim.mesh == QUADRIC_TAG {
                    let s = &self.quadrics[prim.index as usize];
                    s.intersect(ray.o, ray.d, t_max).map(|(t, p)| Hit {
                        t,
                        prim,
                        instance: NO_INSTANCE,
                        local: HitLocal::Analytic(p),
                    })
                } else if prim.mesh == MOVING_TAG {
                    moving_hit(prim.index, t_max)
                } else {
                    self.alpha_triangle(ray, prim, t_max, false)
                }?;
                other = Some(h);
                Some(h.t)
            },
            hint,
        );
        match found {
            Closest::Nothing => None,
            Closest::Triangle { pos, t, b } => Some(triangle_hit(prims[pos as usize], t, b)),
            Closest::Other => other,
        }
    }

    /// True if any of this level's shapes (or instances, by `instance_hit`,
    /// or moving instances, by `moving_hit`) blocks the ray before
    /// `ray.t_max`.
    #[inline(always)]
    fn occluded(
        &self,
        ray: &Ray,
        mut instance_hit: impl FnMut(u32) -> bool,
        mut moving_hit: impl FnMut(u32) -> bool,
    ) -> bool {
        let Some(bvh) = self.level.bvh.as_ref() else {
            return false;
        };
        bvh.any(ray, ray.t_max, |pos| {
            self.blocks(ray, pos, &mut instance_hit, &mut moving_hit)
        })
    }

    /// Whether the primitive at BVH position `pos`, other than a plain
    /// triangle, blocks `ray` before its `t_max` (the any-hit callback).
    #[inline(always)]
    fn blocks(
        &self,
        ray: &Ray,
        pos: u32,
        instance_hit: &mut impl FnMut(u32) -> bool,
        moving_hit: &mut impl FnMut(u32) -> bool,
    ) -> bool {
        let prim = self.level.prims[pos as usize];
        if prim.mesh == INSTANCE_TAG {
            instance_hit(prim.index)
        } else if prim.mesh == QUADRIC_TAG {
            self.quadrics[prim.index as usize]
                .intersect(ray.o, ray.d, ray.t_max)
                .is_some()
        } else if prim.mesh == MOVING_TAG {
            moving_hit(prim.index)
        } else {
            self.alpha_triangle(ray, prim, ray.t_max, true).is_some()
        }
    }

    /// A triangle of a mesh with an alpha mask: hit, and not cut away
    /// (pbrt-v3 tests `alpha` for every ray, and `shadowalpha` too for
    /// shadow rays, after the hit is found and before it is accepted).
    #[inline(never)]
    fn alpha_triangle(&self, ray: &Ray, prim: PrimRef, t_max: f32, shadow: bool) -> Option<Hit> {
        let m = &self.meshes[prim.mesh as usize];
        let [p0, p1, p2] = m.vertices(prim.index);
        let (t, b) = intersect_triangle(ray.o, ray.d, t_max, p0, p1, p2)?;
        m.alpha_passes(prim.index, b, shadow).then_some(Hit {
            t,
            prim,
            instance: NO_INSTANCE,
            local: HitLocal::Bary(b),
        })
    }

    /// The differential geometry of a hit whose shading normal is `ns`.
    #[inline]
    fn diff_geom(&self, prim: PrimRef, local: HitLocal, ns: Vec3) -> DiffGeom {
        match local {
            HitLocal::Bary(b) => self.meshes[prim.mesh as usize].diff_geom(prim.index, b, ns),
            HitLocal::Analytic(p) => self.quadrics[prim.index as usize].diff_geom(p),
        }
    }

    /// The hit's shading data with `time` in place (a hit built and then
    /// copied with its time changed stalls on store forwarding).
    #[inline(always)]
    fn surface(&self, prim: PrimRef, local: HitLocal, time: f32) -> (SurfaceHit, bool) {
        match local {
            HitLocal::Bary(b) => {
                let m = &self.meshes[prim.mesh as usize];
                (
                    SurfaceHit {
                        point: m.surface_point(prim.index, b),
                        material: m.material,
                        light: m.first_light.map(|l| l + prim.index),
                        time,
                    },
                    m.n.is_some(),
                )
            }
            HitLocal::Analytic(p) => {
                let s = &self.quadrics[prim.index as usize];
                (
                    SurfaceHit {
                        point: s.surface_point(p),
                        material: s.material(),
                        light: s.light(),
                        time,
                    },
                    false,
                )
            }
        }
    }
}

/// The aggregate: every shape of a scene placed in world space (meshes, analytic shapes, instances, moving instances) and the BVHs over them, which rays are traced against (pbrt-v3's `Aggregate`).
pub struct Aggregate {
    /// World-space meshes (lights refer to their triangles by index).
    pub meshes: Vec<TriangleMesh>,
    /// World-space quadrics (spheres, disks).
    pub quadrics: Vec<AnalyticShape>,
    top: Level,
    instances: Vec<Instance>,
    /// Instances and shapes with animated transforms (empty, and never
    /// looked at, in a scene without motion).
    moving: Vec<MovingInstance>,
    /// World bounds of everything, instances included (moving ones over
    /// their whole motion).
    pub bounds: Bounds3,
    /// Triangles left out because they have zero area (each object's counted
    /// once, however often it is instanced).
    pub degenerate_triangles: u64,
    /// The scene level's build (whether it needed the bounded builder).
    pub build_work: BuildWork,
    pub build_time: Duration,
}

impl Aggregate {
    /// Builds the scene-level BVH over world-space shapes alone.
    pub fn new(meshes: Vec<TriangleMesh>, quadrics: Vec<AnalyticShape>) -> Aggregate {
        Aggregate::with_instances(meshes, quadrics, Vec::new())
    }

    /// Builds the scene-level BVH over world-space shapes and instances (whose
    /// objects were built before). Instances of empty objects are dropped.
    pub fn with_instances(
        meshes: Vec<TriangleMesh>,
        quadrics: Vec<AnalyticShape>,
        instances: Vec<Instance>,
    ) -> Aggregate {
        Aggregate::with_motion(meshes, quadrics, instances, Vec::new())
    }

    /// `with_instances` with moving instances too: the scene-level BVH holds
    /// each one's motion bounds.
    pub fn with_motion(
        meshes: Vec<TriangleMesh>,
        quadrics: Vec<AnalyticShape>,
        instances: Vec<Instance>,
        moving: Vec<MovingInstance>,
    ) -> Aggregate {
        let start = std::time::Instant::now();
        let instances: Vec<Instance> = instances
            .into_iter()
            .filter(|i| !i.object.is_empty())
            .collect();
        let moving: Vec<MovingInstance> = moving
            .into_iter()
            .filter(|i| !i.object.is_empty())
            .collect();
        let boxes: Vec<Bounds3> = instances.iter().map(Instance::world_bounds).collect();
        let moving_boxes: Vec<Bounds3> = moving.iter().map(MovingInstance::world_bounds).collect();
        let top = Level::build(&meshes, &quadrics, &boxes, &moving_boxes);
        let build_work = top.build;
        let mut degenerate = top.degenerate;
        let mut seen: Vec<*const Object> = Vec::new();
        let objects = instances
            .iter()
            .map(|i| &i.object)
            .chain(moving.iter().map(|i| &i.object));
        for o in objects {
            let p = Arc::as_ptr(o);
            if !seen.contains(&p) {
                seen.push(p);
                degenerate += o.level.degenerate;
            }
        }
        Aggregate {
            meshes,
            quadrics,
            bounds: top.bounds,
            top,
            instances,
            moving,
            degenerate_triangles: degenerate,
            build_work,
            build_time: start.elapsed(),
        }
    }

    fn shapes(&self) -> Shapes<'_> {
        Shapes {
            level: &self.top,
            meshes: &self.meshes,
            quadrics: &self.quadrics,
        }
    }

    /// Primitives in the scene-level BVH (an instance counts as one).
    pub fn primitive_count(&self) -> usize {
        self.top.prims.len()
    }

    pub fn instance_count(&self) -> usize {
        self.instances.len()
    }

    /// Moving instances (animated object instances and animated shapes).
    pub fn moving_count(&self) -> usize {
        self.moving.len()
    }

    /// Bytes held by the scene level's BVH (nodes, leaves with their
    /// triangles' vertices, the primitive order).
    pub fn bvh_bytes(&self) -> usize {
        self.top.bvh.as_ref().map_or(0, |b| b.heap_bytes())
            + self.top.prims.capacity() * std::mem::size_of::<PrimRef>()
    }

    /// Nodes and leaves of the scene level's BVH.
    pub fn bvh_counts(&self) -> (usize, usize) {
        self.top
            .bvh
            .as_ref()
            .map_or((0, 0), |b| (b.node_count(), b.leaf_count()))
    }

    pub fn has_bvh(&self) -> bool {
        self.top.bvh.is_some()
    }

    /// Closest hit along the ray, if any. (Not inlined into callers; the
    /// traversal is inlined here, so that nothing is passed through memory
    /// on the way in: a struct written just before a call and read back
    /// with wider loads stalls store forwarding.)
    ///
    /// At time 0: for a still scene (or a test); a path takes
    /// [`Aggregate::intersect_at`] with its time.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.intersect_at(ray, 0.0)
    }

    /// Closest hit along the ray at scene time `time` (read only by moving
    /// instances: a still scene never looks at it).
    #[inline(never)]
    pub fn intersect_at(&self, ray: &Ray, time: f32) -> Option<Hit> {
        self.closest_at(ray, time)
    }

    /// [`Aggregate::intersect_at`] written to `out`: the batched loops keep
    /// their hits in an array, and a hit returned by value is stored by the
    /// callee and at once copied by the caller with wider loads than its
    /// stores (a store-forwarding stall on every ray).
    #[inline(never)]
    pub fn intersect_into(&self, ray: &Ray, time: f32, out: &mut Option<Hit>) {
        *out = self.closest_at(ray, time);
    }

    /// The closest hits of `rays` (at scene times `times`) in `out`, each
    /// [`Aggregate::intersect_into`]'s: traced as one packet
    /// ([`packet`]) when the scene is triangles only (no instances, no
    /// analytic shapes, no alpha masks) and there are at most
    /// [`PACKET_MAX`], else ray by ray. For coherent rays (a pixel's
    /// camera rays).
    #[inline(never)]
    pub fn intersect_packet(&self, rays: &[Ray], times: &[f32], out: &mut [Option<Hit>]) {
        self.closest_together(rays, times, out, Bvh4::closest_packet);
    }

    /// The closest hits of incoherent `rays` (at scene times `times`) in
    /// `out`, each [`Aggregate::intersect_into`]'s: traced side by side
    /// ([`stream`]) when the scene is triangles only (as for packets) and
    /// there are at most [`PACKET_MAX`], else ray by ray.
    #[inline(never)]
    pub fn intersect_stream(&self, rays: &[Ray], times: &[f32], out: &mut [Option<Hit>]) {
        self.closest_together(rays, times, out, Bvh4::closest_stream);
    }

    /// [`Aggregate::intersect_packet`] or [`Aggregate::intersect_stream`],
    /// whose traversal `trace` is.
    #[inline(always)]
    fn closest_together(
        &self,
        rays: &[Ray],
        times: &[f32],
        out: &mut [Option<Hit>],
        trace: impl Fn(&Bvh4, &[Ray], &mut [packet::PacketHit]),
    ) {
        let n = rays.len();
        match self.top.bvh.as_ref() {
            Some(bvh) if bvh.traces_packets() && n <= PACKET_MAX => {
                let mut found = [None; PACKET_MAX];
                trace(bvh, rays, &mut found[..n]);
                for (o, f) in out[..n].iter_mut().zip(&found[..n]) {
                    *o = f.map(|(pos, t, b)| {
                        let prim = self.top.prims[pos as usize];
                        prefetch_indices(&self.meshes, prim);
                        triangle_hit(prim, t, b)
                    });
                }
            }
            _ => {
                for ((r, &time), o) in rays.iter().zip(times).zip(out.iter_mut()) {
                    self.intersect_into(r, time, o);
                }
            }
        }
    }

    /// Whether something blocks each of incoherent `rays` (at scene times
    /// `times`) before its `t_max`, in `out`, each
    /// [`Aggregate::occluded_at`]'s answer: traced side by side
    /// ([`stream`]) when there are at most [`PACKET_MAX`] (and the tree is
    /// not deeper than a packet's stack), the primitives other than plain
    /// triangles tested as a packet tests them, else ray by ray. For the
    /// shadow rays of a batch's paths.
    #[inline(never)]
    pub fn occluded_stream(&self, rays: &[Ray], times: &[f32], out: &mut [bool]) {
        self.occluded_together::<true>(rays, times, out);
    }

    /// Whether something blocks each of `rays` (at scene times `times`)
    /// before its `t_max`, in `out`, each [`Aggregate::occluded_at`]'s
    /// answer: traced as one packet when there are at most [`PACKET_MAX`]
    /// (and the tree is not deeper than a packet's stack), the primitives
    /// other than plain triangles tested ray by ray where the packet meets
    /// them, else ray by ray. For coherent rays (from one point).
    #[inline(never)]
    pub fn occluded_packet(&self, rays: &[Ray], times: &[f32], out: &mut [bool]) {
        self.occluded_together::<false>(rays, times, out);
    }

    /// [`Aggregate::occluded_packet`] (`STREAM` false) or
    /// [`Aggregate::occluded_stream`].
    #[inline(always)]
    fn occluded_together<const STREAM: bool>(&self, rays: &[Ray], times: &[f32], out: &mut [bool]) {
        match self.top.bvh.as_ref() {
            Some(bvh) if bvh.any_packets_fit() && rays.len() <= PACKET_MAX => {
                let top = self.shapes();
                let blocks = |i: usize, pos| {
                    let ray = &rays[i];
                    top.blocks(
                        ray,
                        pos,
                        &mut |k| self.instance_occluded(ray, k),
                        &mut |k| self.moving_occluded(ray, times[i], k),
                    )
                };
                let blocked = if STREAM {
                    bvh.any_stream(rays, blocks)
                } else {
                    bvh.any_packet(rays, blocks)
                };
                for (i, o) in out[..rays.len()].iter_mut().enumerate() {
                    *o = blocked >> i & 1 == 1;
                }
            }
            _ => {
                for ((r, &time), o) in rays.iter().zip(times).zip(out.iter_mut()) {
                    *o = self.occluded_at(r, time);
                }
            }
        }
    }

    #[inline(always)]
    fn closest_at(&self, ray: &Ray, time: f32) -> Option<Hit> {
        self.shapes().intersect(
            ray,
            |i, t_max| {
                let inst = &self.instances[i as usize];
                let mut r = inst.place.object_ray(ray);
                r.t_max = t_max;
                inst.object
                    .shapes()
                    .intersect(&r, |_, _| None, |_, _| None)
                    .map(|h| Hit { instance: i, ..h })
            },
            |i, t_max| self.moving_intersect(ray, time, i, t_max),
        )
    }

    /// A moving instance's closest hit (the transform interpolated at the
    /// ray's time, as pbrt-v3's `TransformedPrimitive::Intersect`).
    #[inline(never)]
    fn moving_intersect(&self, ray: &Ray, time: f32, i: u32, t_max: f32) -> Option<Hit> {
        let inst = &self.moving[i as usize];
        let mut r = inst.object_ray_at(ray, time)?;
        r.t_max = t_max;
        inst.object
            .shapes()
            .intersect(&r, |_, _| None, |_, _| None)
            .map(|h| Hit {
                instance: i | MOVING_BIT,
                ..h
            })
    }

    #[inline(never)]
    fn moving_occluded(&self, ray: &Ray, time: f32, i: u32) -> bool {
        let inst = &self.moving[i as usize];
        let Some(r) = inst.object_ray_at(ray, time) else {
            return false;
        };
        inst.object.shapes().occluded(&r, |_| false, |_| false)
    }

    /// True if anything blocks the ray before `t_max`, at time 0 (see
    /// [`Aggregate::intersect`]).
    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.occluded_at(ray, 0.0)
    }

    /// True if anything blocks the ray before `t_max` at scene time `time`.
    #[inline(never)]
    pub fn occluded_at(&self, ray: &Ray, time: f32) -> bool {
        self.shapes().occluded(
            ray,
            |i| self.instance_occluded(ray, i),
            |i| self.moving_occluded(ray, time, i),
        )
    }

    /// Whether instance `i` (not moving) blocks `ray` before its `t_max`.
    #[inline]
    fn instance_occluded(&self, ray: &Ray, i: u32) -> bool {
        let inst = &self.instances[i as usize];
        inst.object
            .shapes()
            .occluded(&inst.place.object_ray(ray), |_| false, |_| false)
    }

    /// The object and placement of an instance hit (a moving instance's at
    /// the time of the ray that found it; `None` only if that transform has
    /// become singular, which the hit itself rules out).
    fn placed(&self, hit: &Hit, time: f32) -> Option<(&Object, Placement)> {
        if hit.instance & MOVING_BIT == 0 {
            let inst = &self.instances[hit.instance as usize];
            return Some((&inst.object, inst.place));
        }
        let inst = &self.moving[(hit.instance & !MOVING_BIT) as usize];
        Some((&inst.object, inst.at(time)?))
    }

    /// The differential geometry of a hit (uv, dp/du, …), for materials
    /// that need more than the normals: computed on demand, since most hits
    /// (isotropic constant materials, light and shadow tests) never use it.
    pub fn diff_geom(&self, hit: &Hit, s: &SurfaceHit) -> DiffGeom {
        if hit.instance == NO_INSTANCE {
            return self.shapes().diff_geom(hit.prim, hit.local, s.point.ns);
        }
        let Some((object, place)) = self.placed(hit, s.time) else {
            return DiffGeom::ZERO;
        };
        let shapes = object.shapes();
        let (local, _) = shapes.surface(hit.prim, hit.local, 0.0);
        place.geom_to_world(shapes.diff_geom(hit.prim, hit.local, local.point.ns))
    }

    /// Shading data of a hit found at time 0 (see [`Aggregate::intersect`]).
    #[inline]
    pub fn surface(&self, hit: &Hit) -> SurfaceHit {
        self.surface_at(hit, 0.0)
    }

    /// Shading data of a hit found by a ray at scene time `time`.
    #[inline]
    pub fn surface_at(&self, hit: &Hit, time: f32) -> SurfaceHit {
        if hit.instance == NO_INSTANCE {
            return self.shapes().surface(hit.prim, hit.local, time).0;
        }
        let (object, place) = self
            .placed(hit, time)
            .expect("a moving instance's hit has an invertible transform at its time");
        let (s, vertex_normals) = object.shapes().surface(hit.prim, hit.local, time);
        SurfaceHit {
            point: place.point_to_world(s.point, vertex_normals),
            material: s.material,
            // Area lights inside objects are ignored (as pbrt-v3).
            light: None,
            time,
        }
    }
}

/// Build quality by primitive count: obvhs's slower builders give BVHs that
/// trace faster, worth it while the build stays a small part of the render,
/// so small levels take the slower builders and large ones `medium_build`
/// (`cargo run --release --example bvh_bench` measures both sides). Only the
/// PLOC and reinsertion parameters apply here (see `bvh4`).
fn build_params(n: usize) -> BvhBuildParams {
    if n <= 4096 {
        BvhBuildParams::very_slow_build()
    } else if n <= 262_144 {
        BvhBuildParams::slow_build()
    } else {
        BvhBuildParams::medium_build()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::rng::Pcg32;

    /// A mesh of `n` random small triangles in clusters (`clusters` of
    /// them), so that the two builders make different trees.
    fn clustered(n: usize, clusters: usize, seed: u64) -> TriangleMesh {
        let mut r = Pcg32::with_sequence(seed);
        let mut v = || Vec3::new(r.uniform_f32(), r.uniform_f32(), r.uniform_f32());
        let centres: Vec<Vec3> = (0..clusters).map(|_| v() * 100.0).collect();
        let mut p = Vec::with_capacity(3 * n);
        for i in 0..n {
            let c = centres[i % clusters] + v() * 4.0;
            p.extend([c, c + v() * 0.5, c + v() * 0.5]);
        }
        TriangleMesh::plain(p, (0..3 * n as u32).collect())
    }

    #[test]
    fn mid_sized_levels_keep_the_cheaper_tree() {
        let cost = |l: &Level| l.bvh.as_ref().unwrap().sah_cost();
        let mut picked = [0, 0];
        for (seed, clusters) in [(1, 1), (2, 7), (3, 60), (4, 400)] {
            let meshes = [clustered(COMPARE_MIN + 1000, clusters, seed)];
            let level = Level::build(&meshes, &[], &[], &[]);
            let ploc = Level::build_ploc(&meshes, &[], &[], &[]);
            let binned = Level::build_binned(&meshes, &[], &[], &[]);
            let best = cost(&ploc).min(cost(&binned));
            assert_eq!(cost(&level), best, "seed {seed}");
            assert_eq!(level.build.binned, cost(&binned) < cost(&ploc));
            picked[level.build.binned as usize] += 1;
            assert_eq!(level.prims.len(), meshes[0].triangle_count() as usize);
        }
        // Small levels are PLOC's alone.
        let meshes = [clustered(COMPARE_MIN, 7, 5)];
        assert!(!Level::build(&meshes, &[], &[], &[]).build.binned);
        // The choice is made: each builder's tree is kept somewhere.
        assert!(
            picked[0] > 0 && picked[1] > 0,
            "kept PLOC's, binned: {picked:?}"
        );
    }
}
