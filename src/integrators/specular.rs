//! The recursive specular tree of `directlighting` and `whitted`
//! (pbrt-v3's `SamplerIntegrator::Li` with `SpecularReflect` and
//! `SpecularTransmit`), run with an explicit stack; each kind adds its own
//! direct lighting at every vertex ([`SpecularTree::add_direct`]). The
//! kinds' batches trace the camera rays first and run the tree lane by
//! lane from their hits ([`tree_lanes`]).

use super::batch::Batch;
use super::common::{emitted, escaped, shade_geom, with_diff};
use super::{Scratch, MAX_PASS_THROUGH};
use crate::accel::{Hit, SurfaceHit};
use crate::geometry::{spawn_ray, Ray, RayDiff};
use crate::integrators::RenderScene;
use crate::materials::{Bsdf, BxdfFlags};
use crate::samplers::Sampler;
use crate::scene::bounds::{note_cut, Cut, MAX_TREE_VERTICES};
use crate::shapes::DiffGeom;
use glam::Vec3;

/// A pending vertex of directlighting's and whitted's specular tree.
#[derive(Clone, Copy, Debug)]
pub(super) struct Work {
    ray: Ray,
    /// The ray's differentials, if it carries them (camera rays and their
    /// specular bounces, as pbrt-v3's SpecularReflect/SpecularTransmit).
    diff: Option<RayDiff>,
    beta: Vec3,
    depth: u32,
    pass: u32,
}

/// A kind that renders by the specular tree: its depth and the direct
/// light it adds at every vertex.
pub(super) trait SpecularTree {
    /// `maxdepth`: the tree's vertices are at depths below it.
    fn max_depth(&self) -> u32;

    /// Adds to `local` the direct light at `s` (BSDF `bsdf`, towards `wo`).
    #[allow(clippy::too_many_arguments)]
    fn add_direct(
        &self,
        local: &mut Vec3,
        scene: &RenderScene,
        s: &SurfaceHit,
        bsdf: &Bsdf,
        wo: Vec3,
        sampler: &mut Sampler,
        scratch: &mut Scratch,
    );
}

/// directlighting and whitted: pbrt-v3's recursive Li, run with an
/// explicit stack (kept in the per-tile scratch) instead of recursion, so
/// that a hall of mirrors with a huge `maxdepth` cannot overflow a
/// thread's stack. Vertices are expanded depth first, reflection before
/// transmission, as pbrt-v3 recurses; both specular samples of a vertex
/// are drawn when it is expanded (the same distribution as pbrt-v3, which
/// draws the transmission sample after the reflection subtree).
/// `first` says how far the camera ray's vertex has got already;
/// `bsdf` is the BSDF to shade into (holding the first vertex's when
/// `first` is [`First::Shaded`]).
#[allow(clippy::too_many_arguments)]
pub(super) fn specular_tree_li<'a>(
    kind: &impl SpecularTree,
    ray: Ray,
    first: First,
    time: f32,
    diff: Option<RayDiff>,
    scene: &'a RenderScene,
    sampler: &mut Sampler,
    scratch: &mut Scratch,
    bsdf: &mut Bsdf<'a>,
) -> Vec3 {
    let mut stack = std::mem::take(&mut scratch.work);
    stack.clear();
    // The camera ray's vertex is taken without going through the stack
    // (most samples have no other), and each vertex is expanded in place
    // in `w` (an `Option` taken each time was copied by wide loads that
    // stalled on the narrower stores that had just made it).
    let mut w = Work {
        ray,
        diff,
        beta: Vec3::ONE,
        depth: 0,
        pass: 0,
    };
    let mut l = Vec3::ZERO;
    let mut first = first;
    let mut at_root = true;
    let mut vertices = 0u32;
    let mut hit: Option<Hit> = None;
    loop {
        vertices += 1;
        if vertices > MAX_TREE_VERTICES {
            note_cut(Cut::Tree);
            break;
        }
        'vertex: {
            scratch.counts.closest += 1;
            // The surface and differential geometry are read where they
            // were made (in `first`, or fresh locals that the calls write
            // into): moved into shared variables, they were copied by wide
            // loads that stalled on the narrower stores that had just made
            // them.
            if at_root {
                at_root = false;
                match &mut first {
                    First::Shaded { hit: h, s, geom } => {
                        if geom.is_none() && bsdf.has_specular() {
                            *geom = w.diff.as_ref().map(|d| with_diff(scene, h, s, d));
                        }
                        l += expand(
                            kind,
                            scene,
                            &w,
                            s,
                            geom.as_ref(),
                            bsdf,
                            sampler,
                            scratch,
                            &mut stack,
                        );
                        break 'vertex;
                    }
                    First::Hit(h) => hit = *h,
                    First::Trace => scene.aggregate.intersect_into(&w.ray, time, &mut hit),
                }
            } else {
                scene.aggregate.intersect_into(&w.ray, time, &mut hit);
            }
            let Some(h) = hit.as_ref() else {
                l += w.beta * escaped(scene, w.ray.d);
                break 'vertex;
            };
            let mut s = scene.aggregate.surface_at(h, time);
            let material = &scene.materials[s.material as usize];
            if material.is_none() {
                if w.pass < MAX_PASS_THROUGH {
                    let ray = spawn_ray(s.point.p, s.point.p_error, s.point.n, w.ray.d);
                    // A spawned ray has no differentials (pbrt-v3's SpawnRay).
                    stack.push(Work {
                        ray,
                        diff: None,
                        pass: w.pass + 1,
                        ..w
                    });
                }
                break 'vertex;
            }
            // A material that reads the geometry gets it with the ray's
            // differentials; otherwise it is computed only if specular
            // children will carry differentials.
            let shading_geom;
            let mut geom = None;
            if let Some(d) = w.diff.as_ref() {
                if scene.material_needs_geom[s.material as usize] {
                    shading_geom = with_diff(scene, h, &s, d);
                    geom = Some(&shading_geom);
                }
            }
            shade_geom(scene, h, &mut s, material, false, geom, bsdf);
            let child_geom;
            if geom.is_none() && bsdf.has_specular() {
                if let Some(d) = w.diff.as_ref() {
                    child_geom = with_diff(scene, h, &s, d);
                    geom = Some(&child_geom);
                }
            }
            l += expand(
                kind, scene, &w, &s, geom, bsdf, sampler, scratch, &mut stack,
            );
        }
        match stack.pop() {
            Some(next) => w = next,
            None => break,
        }
    }
    scratch.work = stack;
    l
}

/// A shaded vertex of the tree (surface `s`, BSDF `bsdf`, differential
/// geometry `geom` if computed): its emission and direct light, weighted
/// by the vertex's throughput, and its specular children pushed onto
/// `stack` (reflection to be expanded first).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn expand(
    kind: &impl SpecularTree,
    scene: &RenderScene,
    w: &Work,
    s: &SurfaceHit,
    geom: Option<&DiffGeom>,
    bsdf: &Bsdf,
    sampler: &mut Sampler,
    scratch: &mut Scratch,
    stack: &mut Vec<Work>,
) -> Vec3 {
    let wo = -w.ray.d;
    let mut local = emitted(scene, s, wo);
    kind.add_direct(&mut local, scene, s, bsdf, wo, sampler, scratch);
    if w.depth + 1 < kind.max_depth() {
        let mut children = [None, None];
        for (i, filter) in [
            BxdfFlags::SPECULAR_REFLECTION,
            BxdfFlags::SPECULAR_TRANSMISSION,
        ]
        .into_iter()
        .enumerate()
        {
            if !bsdf.has_specular() {
                // pbrt-v3 draws the sample and the BSDF ignores it.
                sampler.skip_2d();
                continue;
            }
            let u = sampler.get_2d();
            if let Some(bs) = bsdf.sample(wo, u, filter) {
                let cos = bs.wi.dot(s.point.ns).abs();
                if bs.pdf > 0.0 && bs.f != Vec3::ZERO && cos != 0.0 {
                    let ray = spawn_ray(s.point.p, s.point.p_error, s.point.n, bs.wi);
                    let beta = w.beta * bs.f * cos / bs.pdf;
                    let diff = match (&w.diff, geom) {
                        (Some(d), Some(g)) if i == 0 => {
                            Some(g.reflected(s.point.p, s.point.ns, wo, bs.wi, d))
                        }
                        (Some(d), Some(g)) => {
                            Some(g.transmitted(s.point.p, s.point.ns, wo, bs.wi, bsdf.eta, d))
                        }
                        _ => None,
                    };
                    children[i] = Some(Work {
                        ray,
                        diff,
                        beta,
                        depth: w.depth + 1,
                        pass: 0,
                    });
                }
            }
        }
        // Pushed transmission first so that reflection is expanded first.
        let [reflected, transmitted] = children;
        if let Some(t) = transmitted {
            stack.push(t);
        }
        if let Some(r) = reflected {
            stack.push(r);
        }
    }
    w.beta * local
}

/// Where [`specular_tree_li`] starts its camera vertex.
#[allow(clippy::large_enum_variant)] // one per camera ray, on the stack, never stored
pub(super) enum First {
    /// The camera ray is still to be traced.
    Trace,
    /// The camera ray's intersection, already traced.
    Hit(Option<Hit>),
    /// The camera ray's hit already shaded: its surface (with the BSDF's
    /// shading normal) and its differential geometry, if computed; the
    /// BSDF is the one handed to `specular_tree_li`.
    Shaded {
        hit: Hit,
        s: SurfaceHit,
        geom: Option<DiffGeom>,
    },
}

/// A kind's radiance along a camera ray by the specular tree.
#[inline]
pub(super) fn tree_li(
    kind: &impl SpecularTree,
    ray: Ray,
    time: f32,
    diff: Option<RayDiff>,
    scene: &RenderScene,
    sampler: &mut Sampler,
    scratch: &mut Scratch,
) -> Vec3 {
    let mut bsdf = Bsdf::empty();
    specular_tree_li(
        kind,
        ray,
        First::Trace,
        time,
        diff,
        scene,
        sampler,
        scratch,
        &mut bsdf,
    )
}

/// The specular tree lane by lane from the batch's camera hits (traced by
/// [`super::batch::trace_camera_rays`]); lanes of weight 0 get no radiance.
pub(super) fn tree_lanes(
    kind: &impl SpecularTree,
    b: &mut Batch,
    scene: &RenderScene,
    scratch: &mut Scratch,
) {
    let mut bsdf = Bsdf::empty();
    for j in 0..b.len {
        let (ray, time, diff) = (b.rays[j], b.times[j], b.diffs[j]);
        let sampler = &mut b.samplers[j];
        // The scalar loop's test: a NaN weight gets no radiance.
        b.l[j] = if b.weights[j] > 0.0 {
            let first = First::Hit(b.hits[j]);
            specular_tree_li(
                kind, ray, first, time, diff, scene, sampler, scratch, &mut bsdf,
            )
        } else {
            Vec3::ZERO
        };
    }
}
