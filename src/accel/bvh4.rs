//! A four-wide BVH traced with SIMD box and triangle tests.
//!
//! obvhs builds the tree (PLOC and SAH reinsertion, the same steps as its
//! CWBVH builder); this module collapses obvhs's binary tree into nodes of up
//! to four children and leaves of up to four primitives, choosing which
//! subtrees become slots and leaves by the surface area heuristic
//! ([`CollapsePlan`]). A node holds its
//! children's boxes as six four-lane vectors, so one ray meets all four boxes
//! in a handful of SIMD instructions; a leaf holds its triangles' vertices in
//! lanes, so one ray meets up to four triangles in one pass of the watertight
//! test ([`TriangleRay::intersect4`], bit-identical to the scalar test).
//! Spheres and instances in a leaf are handed to the caller one by one.
//!
//! On the Cornell box (36 triangles) a ray visits a node or two and a few
//! leaves; obvhs's CWBVH traversal, which decodes compressed boxes and calls
//! back per primitive, was about a third of the render time there.
//!
//! Box tests follow pbrt-v3's `Bounds3::IntersectP`: slab distances with the
//! far distance scaled by `1 + 2γ(3)`, so that rounding never culls a box the
//! ray touches. Zero direction components get a reciprocal of ±1e30 (finite,
//! so no `0·∞`), with the sign of the component's sign bit ignored: a slab
//! parallel to the ray is then either all of `t` or none of it.

use crate::geometry::{gamma, Ray};
use crate::shapes::{pack_triangles, TrianglePack, TriangleRay4};
use glam::{BVec4A, Vec3, Vec3A, Vec4};
use obvhs::aabb::Aabb;
use obvhs::bvh2::reinsertion::ReinsertionOptimizer;
use obvhs::bvh2::Bvh2;
use obvhs::ploc::PlocBuilder;
use obvhs::BvhBuildParams;
use std::mem::MaybeUninit;

use super::{binned, split};

/// Above this many primitives with one box, PLOC's cost grows as n times
/// that count (see [`split`]); such levels use the bounded builder. Runs of
/// a few coincident boxes (a mesh repeated twice) cost PLOC nothing much.
const COINCIDENT_LIMIT: usize = 32;

/// What a BVH build did (for `--stats` and tests).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BuildWork {
    /// The bounded builder was used (many coincident primitives).
    pub bounded: bool,
    /// Most primitives sharing one box.
    pub largest_coincident: usize,
    /// Primitive touches counted: the coincidence check and the bounded
    /// builder's passes (PLOC is not instrumented), and one per node made.
    pub work: u64,
    /// Built by the parallel binned-SAH builder (a big level).
    pub binned: bool,
}

/// A child reference with this bit set is a leaf.
pub(super) const LEAF: u32 = 1 << 31;
/// Most primitives in a leaf (one SIMD pack).
pub(super) const LEAF_SIZE: usize = 4;
/// Traversal stack sizes (entries): a tiny one for small trees, kept in the
/// caller's frame, and larger ones in frames of their own. Stacks are left
/// uninitialised (zeroing 512 bytes was a few percent of a deep query).
const TINY_STACK: usize = 16;
const SMALL_STACK: usize = 64;
const LARGE_STACK: usize = 512;

/// Four children's boxes, lane `i` for child `i`: `b[axis]` is the minimum
/// and `b[3 + axis]` the maximum along `axis`. `valid` is true in the lanes of
/// used slots (an unused one has an empty box, +∞ to −∞).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(super) struct Node {
    pub(super) b: [Vec4; 6],
    pub(super) child: [u32; 4],
    pub(super) valid: BVec4A,
}

/// Up to four primitives at BVH positions `first .. first + count`;
/// `triangles` marks the lanes that are triangles (their vertices in `v`).
#[derive(Clone, Copy, Debug)]
pub(super) struct Leaf {
    pub(super) v: TrianglePack,
    pub(super) first: u32,
    pub(super) count: u32,
    pub(super) triangles: u32,
}

/// What a closest-hit query found.
pub(super) enum Closest {
    Nothing,
    /// The triangle at BVH position `pos`, at distance `t` and barycentrics `b`.
    Triangle {
        pos: u32,
        t: f32,
        b: [f32; 3],
    },
    /// The last primitive the callback accepted.
    Other,
}

pub(super) struct Bvh4 {
    pub(super) nodes: Vec<Node>,
    pub(super) leaves: Vec<Leaf>,
    /// Traversal stack entries the deepest path can need.
    pub(super) stack_need: usize,
    /// Every primitive is a triangle (tested in the leaves' lanes).
    pub(super) only_triangles: bool,
}

/// The per-ray constants of the box test.
pub(super) struct BoxRay {
    o: [Vec4; 3],
    inv: [Vec4; 3],
}

impl BoxRay {
    #[inline(always)]
    pub(super) fn new(ray: &Ray) -> BoxRay {
        let d = Vec3A::from(ray.d);
        let tiny = d.abs().cmplt(Vec3A::splat(1e-30));
        let big = Vec3A::select(
            d.cmplt(Vec3A::ZERO),
            Vec3A::splat(-1e30),
            Vec3A::splat(1e30),
        );
        let r = Vec3A::select(tiny, big, d.recip());
        BoxRay {
            o: [
                Vec4::splat(ray.o.x),
                Vec4::splat(ray.o.y),
                Vec4::splat(ray.o.z),
            ],
            inv: [Vec4::splat(r.x), Vec4::splat(r.y), Vec4::splat(r.z)],
        }
    }

    /// Entry distances and the lanes of children whose box the ray meets
    /// within `[0, t_max]`.
    #[inline(always)]
    pub(super) fn test(&self, n: &Node, t_max: f32) -> (Vec4, BVec4A) {
        // Slab distances of both planes; the near one is the smaller (the
        // same values as picking planes by the direction's sign).
        let xa = (n.b[0] - self.o[0]) * self.inv[0];
        let ya = (n.b[1] - self.o[1]) * self.inv[1];
        let za = (n.b[2] - self.o[2]) * self.inv[2];
        let xb = (n.b[3] - self.o[0]) * self.inv[0];
        let yb = (n.b[4] - self.o[1]) * self.inv[1];
        let zb = (n.b[5] - self.o[2]) * self.inv[2];
        let t0 = xa.min(xb).max(ya.min(yb)).max(za.min(zb).max(Vec4::ZERO));
        let t1 = (xa.max(xb).min(ya.max(yb)).min(za.max(zb)) * Vec4::splat(1.0 + 2.0 * gamma(3)))
            .min(Vec4::splat(t_max));
        // Unused slots (empty boxes) would pass: only `valid` lanes count.
        (t0, t0.cmple(t1) & n.valid)
    }
}

impl Bvh4 {
    /// Builds over the boxes (primitive `i` has box `aabbs[i]`, and is a
    /// triangle with vertices `triangle(i)` or something else for `None`).
    /// Returns the BVH and the primitives in BVH order (BVH position `p`
    /// holds primitive `order[p]`). `aabbs` must not be empty.
    /// Builds over the boxes (primitive `i` has box `aabbs[i]`, and is a
    /// triangle with vertices `triangle(i)` or something else for `None`).
    /// Returns the BVH, the primitives in BVH order (BVH position `p` holds
    /// primitive `order[p]`) and how it went: whether the bounded builder of
    /// [`split`] was used, and the primitive touches it counted. `aabbs`
    /// must not be empty.
    pub(super) fn build_counted(
        aabbs: &[Aabb],
        params: BvhBuildParams,
        triangle: impl Fn(usize) -> Option<[Vec3; 3]>,
    ) -> (Bvh4, Vec<u32>, BuildWork) {
        assert!(!aabbs.is_empty());
        let mut work = 0u64;
        let run = split::largest_coincident_run(aabbs, &mut work);
        let bounded = run > COINCIDENT_LIMIT;
        let mut bvh2 = if bounded {
            split::build(aabbs, &mut work)
        } else {
            let mut bvh2 = PlocBuilder::with_capacity(aabbs.len()).build(
                params.ploc_search_distance,
                aabbs,
                (0..aabbs.len() as u32).collect(),
                params.sort_precision,
                params.search_depth_threshold,
            );
            ReinsertionOptimizer::default().run(&mut bvh2, params.reinsertion_batch_ratio, None);
            bvh2
        };
        work += bvh2.nodes.len() as u64;
        let (bvh, order) = Self::from_bvh2(&mut bvh2, triangle);
        (
            bvh,
            order,
            BuildWork {
                bounded,
                largest_coincident: run,
                work,
                binned: false,
            },
        )
    }

    /// Builds with the parallel binned-SAH builder of [`binned`] over
    /// `refs` (primitive `i` is a triangle with vertices `triangle(i)` or
    /// something else for `None`); returns the BVH, the primitives in BVH
    /// order and the bounds of everything.
    pub(super) fn build_binned(
        refs: Vec<binned::Ref>,
        triangle: impl Fn(usize) -> Option<[Vec3; 3]> + Sync,
    ) -> (Bvh4, Vec<u32>, (Vec3, Vec3)) {
        let b = binned::build(refs, triangle);
        (
            Bvh4 {
                only_triangles: only_triangles(&b.leaves),
                nodes: b.nodes,
                leaves: b.leaves,
                stack_need: 3 * b.depth + 4,
            },
            b.order,
            b.bounds,
        )
    }

    /// The tree's cost by the surface area heuristic (the weights of
    /// [`CollapsePlan`]): each child box's half area times the cost of
    /// testing what it holds, summed; proportional to the expected cost of
    /// a random ray through the root's box.
    pub(super) fn sah_cost(&self) -> f64 {
        let mut cost = 0.0f64;
        for n in &self.nodes {
            for slot in 0..4 {
                if !n.valid.test(slot) {
                    continue;
                }
                let lo = Vec3::new(n.b[0][slot], n.b[1][slot], n.b[2][slot]);
                let hi = Vec3::new(n.b[3][slot], n.b[4][slot], n.b[5][slot]);
                let area = Aabb::new(lo.into(), hi.into()).half_area().max(0.0) as f64;
                let weight = if n.child[slot] & LEAF != 0 {
                    COST_LEAF
                } else {
                    COST_NODE
                };
                cost += area * weight as f64;
            }
        }
        cost
    }

    /// Bytes held by the nodes and leaves.
    pub(super) fn heap_bytes(&self) -> usize {
        self.nodes.capacity() * std::mem::size_of::<Node>()
            + self.leaves.capacity() * std::mem::size_of::<Leaf>()
    }

    pub(super) fn node_count(&self) -> usize {
        self.nodes.len()
    }

    pub(super) fn leaf_count(&self) -> usize {
        self.leaves.len()
    }

    fn from_bvh2(
        bvh2: &mut Bvh2,
        triangle: impl Fn(usize) -> Option<[Vec3; 3]>,
    ) -> (Bvh4, Vec<u32>) {
        // Parents before children, siblings side by side, in depth-first
        // order: the passes below run backwards over the array (children
        // first) instead of jumping through it, which PLOC's merge order
        // and reinsertion's moves make a cache miss per node. Only the
        // array changes, not the tree, so neither does the BVH made of it.
        bvh2.reorder_in_stack_traversal_order();
        let bvh2 = &*bvh2;
        let nodes2 = &bvh2.nodes;
        // PLOC makes a leaf per primitive; a leaf is never opened below.
        assert!(
            nodes2.iter().all(|n| n.prim_count as usize <= LEAF_SIZE),
            "obvhs BVH2 leaves hold one primitive each"
        );
        // Leaf sizes count a primitive that is not a triangle as a full
        // leaf: such a primitive (quadric, curve piece, instance) is tested
        // by its own call and costs far more than a triangle lane, so it
        // gets a leaf and a box of its own.
        let weights: Vec<u32> = (0..bvh2.primitive_indices.len())
            .map(|p| {
                if triangle(p).is_some() {
                    1
                } else {
                    LEAF_SIZE as u32
                }
            })
            .collect();
        let counts = subtree_counts(bvh2, &weights);
        let mut order: Vec<u32> = Vec::with_capacity(bvh2.primitive_indices.len());
        let mut nodes: Vec<Node> = Vec::new();
        let mut leaves: Vec<Leaf> = Vec::new();
        let mut max_depth = 0usize;

        let mut stack = Vec::new();
        let mut leaf_of = |root: usize, order: &mut Vec<u32>| -> u32 {
            let first = order.len() as u32;
            // The subtree's primitives, left to right.
            stack.push(root);
            while let Some(i) = stack.pop() {
                let n = &nodes2[i];
                if n.prim_count == 0 {
                    stack.push(n.first_index as usize + 1);
                    stack.push(n.first_index as usize);
                } else {
                    let s = n.first_index as usize;
                    order.extend_from_slice(&bvh2.primitive_indices[s..s + n.prim_count as usize]);
                }
            }
            let count = order.len() as u32 - first;
            leaves.push(make_leaf(order, first, count, &triangle));
            (leaves.len() - 1) as u32 | LEAF
        };
        let plan = CollapsePlan::new(bvh2, &counts);
        // Work list: (BVH2 node, BVH4 node to fill, depth).
        nodes.push(empty_node());
        let mut work = vec![(0usize, 0usize, 1usize)];
        while let Some((n2, out, depth)) = work.pop() {
            max_depth = max_depth.max(depth);
            let kids = if n2 == 0 && plan.is_leaf(0) {
                vec![n2] // a root small enough to be one leaf
            } else {
                plan.children(n2, nodes2)
            };
            let mut node = empty_node();
            node.valid = BVec4A::new(true, kids.len() > 1, kids.len() > 2, kids.len() > 3);
            for (slot, &k) in kids.iter().enumerate() {
                let a = nodes2[k].aabb;
                for axis in 0..3 {
                    node.b[axis][slot] = a.min[axis];
                    node.b[3 + axis][slot] = a.max[axis];
                }
                node.child[slot] = if plan.is_leaf(k) {
                    leaf_of(k, &mut order)
                } else {
                    nodes.push(empty_node());
                    work.push((k, nodes.len() - 1, depth + 1));
                    (nodes.len() - 1) as u32
                };
            }
            nodes[out] = node;
        }
        debug_assert_eq!(order.len(), bvh2.primitive_indices.len());
        (
            Bvh4 {
                only_triangles: only_triangles(&leaves),
                nodes,
                leaves,
                // Three entries per level, and room for the branch-free
                // pushes that write all four lanes.
                stack_need: 3 * max_depth + 4,
            },
            order,
        )
    }

    /// [`Bvh4::closest_hinted`] without a hint.
    #[cfg(test)]
    pub(super) fn closest(
        &self,
        ray: &Ray,
        t_max: f32,
        other: impl FnMut(u32, f32) -> Option<f32>,
    ) -> Closest {
        self.closest_hinted(ray, t_max, other, |_| {})
    }

    /// Closest hit with `t <= t_max`: triangles are tested here, other
    /// primitives (at BVH position `pos`) by `other(pos, t_max)`, which
    /// returns the distance of what it accepted (a closer `t_max` from then
    /// on) and keeps what it needs of it. `hint` is told the BVH position of
    /// each triangle that becomes the closest so far, so that the caller
    /// can start fetching what it will read of the hit.
    #[inline]
    pub(super) fn closest_hinted(
        &self,
        ray: &Ray,
        t_max: f32,
        other: impl FnMut(u32, f32) -> Option<f32>,
        hint: impl FnMut(u32),
    ) -> Closest {
        if self.stack_need <= TINY_STACK {
            let mut stack = [MaybeUninit::uninit(); TINY_STACK];
            self.closest_with(ray, t_max, other, hint, &mut stack)
        } else {
            self.closest_deep(ray, t_max, other, hint)
        }
    }

    #[inline(never)]
    fn closest_deep(
        &self,
        ray: &Ray,
        t_max: f32,
        other: impl FnMut(u32, f32) -> Option<f32>,
        hint: impl FnMut(u32),
    ) -> Closest {
        if self.stack_need <= SMALL_STACK {
            let mut stack = [MaybeUninit::uninit(); SMALL_STACK];
            self.closest_with(ray, t_max, other, hint, &mut stack)
        } else if self.stack_need <= LARGE_STACK {
            self.closest_large(ray, t_max, other, hint)
        } else {
            // Degenerate trees only (hundreds of levels deep).
            let mut stack = vec![MaybeUninit::uninit(); self.stack_need];
            self.closest_with(ray, t_max, other, hint, &mut stack)
        }
    }

    #[inline(never)]
    fn closest_large(
        &self,
        ray: &Ray,
        t_max: f32,
        other: impl FnMut(u32, f32) -> Option<f32>,
        hint: impl FnMut(u32),
    ) -> Closest {
        let mut stack = [MaybeUninit::uninit(); LARGE_STACK];
        self.closest_with(ray, t_max, other, hint, &mut stack)
    }

    #[inline(always)]
    fn closest_with(
        &self,
        ray: &Ray,
        t_max: f32,
        other: impl FnMut(u32, f32) -> Option<f32>,
        hint: impl FnMut(u32),
        stack: &mut [MaybeUninit<(u32, f32)>],
    ) -> Closest {
        let br = BoxRay::new(ray);
        let tr = TriangleRay4::new(ray.o, ray.d);
        match tr.kz() {
            0 => self.closest_k::<0>(&br, &tr, t_max, other, hint, stack),
            1 => self.closest_k::<1>(&br, &tr, t_max, other, hint, stack),
            _ => self.closest_k::<2>(&br, &tr, t_max, other, hint, stack),
        }
    }

    /// The traversal for rays whose direction is largest along `KZ`.
    #[inline(always)]
    fn closest_k<const KZ: u8>(
        &self,
        br: &BoxRay,
        tr: &TriangleRay4,
        mut t_max: f32,
        mut other: impl FnMut(u32, f32) -> Option<f32>,
        mut hint: impl FnMut(u32),
        stack: &mut [MaybeUninit<(u32, f32)>],
    ) -> Closest {
        // The closest triangle is kept, equal distances going to the lower
        // position, and boxes and triangles are tested a little past the
        // closest so far ([`reach`]): which triangle is found does not
        // depend on the order leaves are visited in (so a packet of rays,
        // `packet`, finds each ray's).
        let t_limit = t_max;
        let mut best_pos = u32::MAX;
        let mut found = Closest::Nothing;
        let mut sp = 0usize;
        let mut cur = 0u32;
        loop {
            if cur & LEAF == 0 {
                let n = &self.nodes[cur as usize];
                let (t0, hit_box) = br.test(n, reach(t_max));
                let mask = hit_box.bitmask();
                if mask != 0 {
                    let near = stack_children(n, (t0, hit_box, mask), stack, &mut sp);
                    cur = n.child[near];
                    continue;
                }
            } else {
                let leaf = &self.leaves[(cur & !LEAF) as usize];
                if leaf.triangles != 0 {
                    if let Some((lane, t, b)) =
                        tr.intersect4::<KZ>(&leaf.v, lane_limit(t_max, t_limit), leaf.triangles)
                    {
                        let pos = leaf.first + lane;
                        if closer(t, pos, t_max, best_pos) {
                            t_max = t;
                            best_pos = pos;
                            hint(pos);
                            found = Closest::Triangle { pos, t, b };
                        }
                    }
                }
                let others = ((1u32 << leaf.count) - 1) & !leaf.triangles;
                let mut m = others;
                while m != 0 {
                    let pos = leaf.first + m.trailing_zeros();
                    if let Some(t) = other(pos, t_max) {
                        t_max = t;
                        best_pos = u32::MAX;
                        found = Closest::Other;
                    }
                    m &= m - 1;
                }
            }
            // Next: the nearest stacked entry that can still be closer.
            match pop_within(stack, &mut sp, t_max) {
                Some(c) => cur = c,
                None => return found,
            }
        }
    }

    /// True if something blocks the ray with `t <= t_max`: triangles are
    /// tested here, other primitives by `blocks(pos)`.
    #[inline]
    pub(super) fn any(&self, ray: &Ray, t_max: f32, blocks: impl FnMut(u32) -> bool) -> bool {
        if self.stack_need <= TINY_STACK {
            let mut stack = [MaybeUninit::uninit(); TINY_STACK];
            self.any_with(ray, t_max, blocks, &mut stack)
        } else {
            self.any_deep(ray, t_max, blocks)
        }
    }

    #[inline(never)]
    fn any_deep(&self, ray: &Ray, t_max: f32, blocks: impl FnMut(u32) -> bool) -> bool {
        if self.stack_need <= SMALL_STACK {
            let mut stack = [MaybeUninit::uninit(); SMALL_STACK];
            self.any_with(ray, t_max, blocks, &mut stack)
        } else if self.stack_need <= LARGE_STACK {
            let mut stack = [MaybeUninit::uninit(); LARGE_STACK];
            self.any_with(ray, t_max, blocks, &mut stack)
        } else {
            let mut stack = vec![MaybeUninit::uninit(); self.stack_need];
            self.any_with(ray, t_max, blocks, &mut stack)
        }
    }

    #[inline(always)]
    fn any_with(
        &self,
        ray: &Ray,
        t_max: f32,
        blocks: impl FnMut(u32) -> bool,
        stack: &mut [MaybeUninit<u32>],
    ) -> bool {
        let br = BoxRay::new(ray);
        let tr = TriangleRay4::new(ray.o, ray.d);
        match tr.kz() {
            0 => self.any_k::<0>(&br, &tr, t_max, blocks, stack),
            1 => self.any_k::<1>(&br, &tr, t_max, blocks, stack),
            _ => self.any_k::<2>(&br, &tr, t_max, blocks, stack),
        }
    }

    #[inline(always)]
    fn any_k<const KZ: u8>(
        &self,
        br: &BoxRay,
        tr: &TriangleRay4,
        t_max: f32,
        mut blocks: impl FnMut(u32) -> bool,
        stack: &mut [MaybeUninit<u32>],
    ) -> bool {
        let mut sp = 0usize;
        let mut cur = 0u32;
        loop {
            if cur & LEAF == 0 {
                let n = &self.nodes[cur as usize];
                let mask = br.test(n, t_max).1.bitmask();
                if mask != 0 {
                    let first = mask.trailing_zeros() as usize;
                    let rest = mask & !(1 << first);
                    for i in 0..4 {
                        stack[sp] = MaybeUninit::new(n.child[i]);
                        sp += ((rest >> i) & 1) as usize;
                    }
                    cur = n.child[first];
                    continue;
                }
            } else {
                let leaf = &self.leaves[(cur & !LEAF) as usize];
                if leaf.triangles != 0 && tr.any4::<KZ>(&leaf.v, t_max, leaf.triangles) {
                    return true;
                }
                let mut m = ((1u32 << leaf.count) - 1) & !leaf.triangles;
                while m != 0 {
                    if blocks(leaf.first + m.trailing_zeros()) {
                        return true;
                    }
                    m &= m - 1;
                }
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            // SAFETY: as in `closest_k`, entries below the pointer were
            // written.
            cur = unsafe { stack[sp].assume_init() };
        }
    }
}

/// Whether every leaf holds triangles only.
fn only_triangles(leaves: &[Leaf]) -> bool {
    leaves.iter().all(|l| l.triangles == (1 << l.count) - 1)
}

/// A node's step of a closest-hit traversal, where the ray meets the boxes
/// of `mask` (not empty) at entry distances `t0`: returns the slot of the
/// nearest, to be visited next, and stacks the others without branches
/// (every lane is written, the stack pointer `sp` moves past the hit
/// ones; two or three more are stacked far to near, so that the nearer
/// are popped first), to be culled by distance when popped.
#[inline(always)]
pub(super) fn stack_children(
    n: &Node,
    (t0, hit_box, mask): (Vec4, BVec4A, u32),
    stack: &mut [MaybeUninit<(u32, f32)>],
    sp: &mut usize,
) -> usize {
    let t0m = Vec4::select(hit_box, t0, Vec4::INFINITY);
    let near =
        (t0m.cmpeq(Vec4::splat(t0m.min_element())).bitmask() & mask).trailing_zeros() as usize;
    let rest = mask & !(1 << near);
    let ts = t0.to_array();
    if rest & rest.wrapping_sub(1) == 0 {
        for (i, (&c, t)) in n.child.iter().zip(ts).enumerate() {
            stack[*sp] = MaybeUninit::new((c, t));
            *sp += ((rest >> i) & 1) as usize;
        }
    } else {
        let mut e = [(0u32, 0f32); 3];
        let mut k = 0;
        let mut m = rest;
        while m != 0 {
            let i = m.trailing_zeros() as usize;
            e[k] = (n.child[i], ts[i]);
            k += 1;
            m &= m - 1;
        }
        if e[0].1 < e[1].1 {
            e.swap(0, 1);
        }
        if k == 3 {
            if e[1].1 < e[2].1 {
                e.swap(1, 2);
            }
            if e[0].1 < e[1].1 {
                e.swap(0, 1);
            }
        }
        for (slot, &x) in stack[*sp..*sp + 3].iter_mut().zip(&e) {
            *slot = MaybeUninit::new(x);
        }
        *sp += k;
    }
    near
}

/// The nearest stacked entry (below `sp`) whose box can still hold a hit
/// as near as `t_max`, if any; those past it are dropped.
#[inline(always)]
pub(super) fn pop_within(
    stack: &[MaybeUninit<(u32, f32)>],
    sp: &mut usize,
    t_max: f32,
) -> Option<u32> {
    loop {
        if *sp == 0 {
            return None;
        }
        *sp -= 1;
        // SAFETY: entries below the stack pointer were written (the
        // pointer only moves past written entries).
        let (c, t0) = unsafe { stack[*sp].assume_init() };
        if t0 <= reach(t_max) {
            return Some(c);
        }
    }
}

/// How far a closest-hit query still looks for boxes when the closest hit
/// so far is at `t_max`: a little farther, so that a triangle as near as
/// that hit (which may win by the tie rule) is not lost to its box's
/// entry distance rounding to more than the triangle's own distance (both
/// are within far less than this margin of the exact distances, which are
/// in that order). The boxes visited then do not depend on the order of
/// the hits found before.
#[inline(always)]
pub(super) fn reach(t_max: f32) -> f32 {
    t_max * (1.0 + 1.0 / 65536.0)
}

/// The distance a leaf's triangles are tested up to when the closest hit
/// so far is at `t_max` and the query's limit is `t_limit`: every triangle
/// as near as that hit passes, and none beyond the limit.
#[inline(always)]
pub(super) fn lane_limit(t_max: f32, t_limit: f32) -> f32 {
    reach(t_max).min(t_limit)
}

/// Whether a triangle hit at `t`, BVH position `pos`, replaces the closest
/// so far (at `t_max`, position `best_pos`): nearer, or as near and lower.
#[inline(always)]
pub(super) fn closer(t: f32, pos: u32, t_max: f32, best_pos: u32) -> bool {
    t < t_max || (t == t_max && pos < best_pos)
}

/// The leaf of BVH positions `first .. first + count` (`order` maps them to
/// primitives, `triangle` gives a primitive's vertices if it is one).
pub(super) fn make_leaf(
    order: &[u32],
    first: u32,
    count: u32,
    triangle: &impl Fn(usize) -> Option<[Vec3; 3]>,
) -> Leaf {
    let prims = &order[first as usize..(first + count) as usize];
    debug_assert!(prims.len() <= LEAF_SIZE);
    let mut tris = [[Vec3::ZERO; 3]; LEAF_SIZE];
    let mut mask = 0;
    for (lane, &p) in prims.iter().enumerate() {
        if let Some(t) = triangle(p as usize) {
            tris[lane] = t;
            mask |= 1 << lane;
        }
    }
    Leaf {
        v: pack_triangles(&tris),
        first,
        count,
        triangles: mask,
    }
}

pub(super) fn empty_node() -> Node {
    let mut b = [Vec4::splat(f32::INFINITY); 6];
    for m in &mut b[3..] {
        *m = Vec4::splat(f32::NEG_INFINITY);
    }
    Node {
        b,
        child: [u32::MAX; 4],
        valid: BVec4A::FALSE,
    }
}

/// Relative costs of the surface area heuristic: testing a node's four
/// boxes, and a leaf's triangle pack (about three times the instructions).
const COST_NODE: f32 = 1.0;
const COST_LEAF: f32 = 3.0;

/// How the binary tree collapses into four-wide nodes, chosen by the
/// surface area heuristic over all ways to do it (Ylitie, Karras and
/// Laine 2017, "Efficient incoherent ray traversal on GPUs through
/// compressed wide BVHs", section 3.1): a subtree with at most
/// `LEAF_SIZE` primitives is a leaf only when that is cheaper than a node,
/// and a node's four slots go to the subtrees whose boxes save the most.
/// On the Cornell box the greedy collapse put the two side walls in one
/// leaf whose box is the whole room, tested by every ray.
struct CollapsePlan {
    /// Per BVH2 node and slot budget `k` (1..=4, at index `k - 1`): the
    /// least cost of its subtree in at most `k` slots of a parent node.
    cost: Vec<[f32; 4]>,
    /// How that cost is reached: 0 takes the subtree whole (`k` = 1) or
    /// in one slot fewer; `j` > 0 gives `j` slots to the first child and
    /// `k - j` to the second.
    split: Vec<[u8; 4]>,
    /// Whether the subtree, taken whole into one slot, is a leaf.
    leaf: Vec<bool>,
    /// As a four-wide node: the slots of its four that go to the first
    /// child (the rest to the second).
    node_split: Vec<u8>,
}

impl CollapsePlan {
    fn new(bvh2: &Bvh2, counts: &[u32]) -> CollapsePlan {
        let nodes = &bvh2.nodes;
        let n = nodes.len();
        let mut plan = CollapsePlan {
            cost: vec![[0.0; 4]; n],
            split: vec![[0; 4]; n],
            leaf: vec![false; n],
            node_split: vec![0; n],
        };
        // Children first: they follow their parents in the array.
        for i in (0..n).rev() {
            let node = &nodes[i];
            let area = node.aabb.half_area().max(0.0);
            if node.prim_count != 0 {
                plan.leaf[i] = true;
                plan.cost[i] = [area * COST_LEAF; 4];
                continue;
            }
            let f = node.first_index as usize;
            debug_assert!(f > i, "children after their parent");
            let (a, b) = (plan.cost[f], plan.cost[f + 1]);
            // Both children in `k` slots (at least one each).
            let both = |k: usize| -> (f32, u8) {
                (1..k)
                    .map(|j| (a[j - 1] + b[k - j - 1], j as u8))
                    .min_by(|x, y| x.0.total_cmp(&y.0))
                    .unwrap_or((f32::INFINITY, 0))
            };
            let (four, j) = both(4);
            let as_node = area * COST_NODE + four;
            plan.node_split[i] = j;
            let as_leaf = if counts[i] as usize <= LEAF_SIZE {
                area * COST_LEAF
            } else {
                f32::INFINITY
            };
            plan.leaf[i] = as_leaf <= as_node;
            let mut cost = [as_leaf.min(as_node); 4];
            let mut split = [0u8; 4];
            for k in 2..=4 {
                let (c, j) = both(k);
                cost[k - 1] = cost[k - 2];
                if c < cost[k - 1] {
                    cost[k - 1] = c;
                    split[k - 1] = j;
                }
            }
            plan.cost[i] = cost;
            plan.split[i] = split;
        }
        plan
    }

    fn is_leaf(&self, i: usize) -> bool {
        self.leaf[i]
    }

    /// The slots of the four-wide node made of internal BVH2 node `i`.
    fn children(&self, i: usize, nodes: &[obvhs::bvh2::node::Bvh2Node]) -> Vec<usize> {
        let mut kids = Vec::with_capacity(4);
        self.expand(i, 4, self.node_split[i] as usize, nodes, &mut kids);
        kids
    }

    /// The subtrees filling the (at most) `k` slots of subtree `i`.
    fn fill(
        &self,
        i: usize,
        mut k: usize,
        nodes: &[obvhs::bvh2::node::Bvh2Node],
        out: &mut Vec<usize>,
    ) {
        while k > 1 && self.split[i][k - 1] == 0 {
            k -= 1;
        }
        if k <= 1 {
            out.push(i);
        } else {
            self.expand(i, k, self.split[i][k - 1] as usize, nodes, out);
        }
    }

    /// Internal node `i`'s children in `k` slots, `j` of them the first's.
    fn expand(
        &self,
        i: usize,
        k: usize,
        j: usize,
        nodes: &[obvhs::bvh2::node::Bvh2Node],
        out: &mut Vec<usize>,
    ) {
        let f = nodes[i].first_index as usize;
        self.fill(f, j, nodes, out);
        self.fill(f + 1, k - j, nodes, out);
    }
}

/// Per BVH2 node, the sum of `weights` of the primitives below it (children
/// after their parents in `bvh2`'s array).
fn subtree_counts(bvh2: &Bvh2, weights: &[u32]) -> Vec<u32> {
    let nodes = &bvh2.nodes;
    let mut counts = vec![0u32; nodes.len()];
    // Children first: they follow their parents in the array.
    for (i, n) in nodes.iter().enumerate().rev() {
        let s = n.first_index as usize;
        counts[i] = if n.prim_count != 0 {
            bvh2.primitive_indices[s..s + n.prim_count as usize]
                .iter()
                .map(|&p| weights[p as usize])
                .sum()
        } else {
            debug_assert!(s > i, "children after their parent");
            counts[s] + counts[s + 1]
        };
    }
    counts
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::sampling::rng::Pcg32;
    use crate::shapes::intersect_triangle;

    fn random_triangles(rng: &mut Pcg32, n: usize, spread: f32, size: f32) -> Vec<[Vec3; 3]> {
        let mut v = |s: f32| {
            Vec3::new(
                rng.uniform_f32() - 0.5,
                rng.uniform_f32() - 0.5,
                rng.uniform_f32() - 0.5,
            ) * s
        };
        (0..n)
            .map(|_| {
                let c = v(spread);
                [c + v(size), c + v(size), c + v(size)]
            })
            .collect()
    }

    /// A tree over triangles and other primitives' boxes (and the order).
    pub(in crate::accel) fn build(tris: &[[Vec3; 3]], others: &[Aabb]) -> (Bvh4, Vec<u32>) {
        let mut aabbs: Vec<Aabb> = tris
            .iter()
            .map(|t| {
                let mut a = Aabb::empty();
                for p in t {
                    a.extend((*p).into());
                }
                a
            })
            .collect();
        aabbs.extend_from_slice(others);
        let n = tris.len();
        let (bvh, order, _) = Bvh4::build_counted(&aabbs, BvhBuildParams::medium_build(), |i| {
            (i < n).then(|| tris[i])
        });
        (bvh, order)
    }

    fn build_binned(tris: &[[Vec3; 3]], others: &[Aabb]) -> (Bvh4, Vec<u32>) {
        let n = tris.len();
        let mut refs: Vec<binned::Ref> = tris
            .iter()
            .enumerate()
            .map(|(i, t)| {
                let (lo, hi) = (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2]));
                binned::Ref::new(lo, hi, i as u32, true)
            })
            .collect();
        for (i, a) in others.iter().enumerate() {
            refs.push(binned::Ref::new(
                a.min.into(),
                a.max.into(),
                (n + i) as u32,
                false,
            ));
        }
        let (bvh, order, _) = Bvh4::build_binned(refs, |i| (i < n).then(|| tris[i]));
        (bvh, order)
    }

    /// The binned builder: right hits (as `check` for PLOC), other
    /// primitives in leaves of their own, and the same tree for one thread
    /// and two (big enough that the partition and the subtrees run in
    /// parallel).
    #[test]
    fn binned_builder_finds_the_hits_and_is_deterministic() {
        let mut rng = Pcg32::with_sequence(21);
        for (n, size) in [(1, 0.8), (5, 0.5), (37, 0.3), (3000, 0.08)] {
            let tris = random_triangles(&mut rng, n, 1.0, size);
            let (bvh, order) = build_binned(&tris, &[]);
            let mut sorted = order.clone();
            sorted.sort_unstable();
            assert!(sorted.iter().copied().eq(0..n as u32));
            let mut hits = 0;
            for _ in 0..2000 {
                let ray = random_ray(&mut rng, 1.0);
                let expect = brute(&tris, &ray).map(|h| h.0);
                // The hint's last position is the hit's.
                let mut last = None;
                let got = match bvh.closest_hinted(&ray, ray.t_max, |_, _| None, |p| last = Some(p))
                {
                    Closest::Triangle { t, pos, .. } => {
                        assert_eq!(last, Some(pos));
                        Some(t)
                    }
                    _ => {
                        assert_eq!(last, None);
                        None
                    }
                };
                assert_eq!(expect, got, "{n} triangles, ray {ray:?}");
                assert_eq!(bvh.any(&ray, ray.t_max, |_| false), expect.is_some());
                hits += got.is_some() as usize;
            }
            assert!(hits > 30, "{n} triangles: {hits} hits");
        }
        let tris = random_triangles(&mut rng, 20, 1.0, 0.3);
        let others = [Aabb::new(Vec3::splat(-0.1).into(), Vec3::splat(0.1).into())];
        let (bvh, order) = build_binned(&tris, &others);
        assert_eq!(others_on_axis(&bvh, &order), vec![20]);
        // Determinism across thread counts.
        let tris = random_triangles(&mut rng, 150_000, 1.0, 0.01);
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let (bvh, order) = pool.install(|| build_binned(&tris, &[]));
            let boxes: Vec<u32> = bvh
                .nodes
                .iter()
                .flat_map(|n| n.b.iter().flat_map(|v| v.to_array().map(f32::to_bits)))
                .chain(bvh.nodes.iter().flat_map(|n| n.child))
                .collect();
            (boxes, order, bvh.leaves.len(), bvh.stack_need)
        };
        let one = run(1);
        assert!(one.0.len() > 10_000, "{} node words", one.0.len());
        assert!(one == run(2), "the tree differs between 1 and 2 threads");
        assert!(one == run(3), "the tree differs between 1 and 3 threads");
    }

    /// Brute-force closest hit: (t, primitive).
    fn brute(tris: &[[Vec3; 3]], ray: &Ray) -> Option<(f32, u32)> {
        let mut best: Option<(f32, u32)> = None;
        for (i, t) in tris.iter().enumerate() {
            if let Some((th, _)) = intersect_triangle(ray.o, ray.d, ray.t_max, t[0], t[1], t[2]) {
                if best.is_none_or(|(bt, _)| th < bt) {
                    best = Some((th, i as u32));
                }
            }
        }
        best
    }

    fn random_ray(rng: &mut Pcg32, spread: f32) -> Ray {
        let o = Vec3::new(
            rng.uniform_f32() - 0.5,
            rng.uniform_f32() - 0.5,
            rng.uniform_f32() - 0.5,
        ) * spread;
        let mut d = Vec3::new(
            rng.uniform_f32() - 0.5,
            rng.uniform_f32() - 0.5,
            rng.uniform_f32() - 0.5,
        );
        // Some rays along the axes, with +0.0 and -0.0 components.
        match rng.uniform_u32_below(8) {
            0 => d = Vec3::new(0.0, -0.0, if d.z < 0.0 { -1.0 } else { 1.0 }),
            1 => d = Vec3::new(-0.0, d.y, 0.0),
            2 => d.x = -0.0,
            _ => {}
        }
        let mut r = Ray::new(o, d);
        if rng.uniform_u32_below(4) == 0 {
            r.t_max = rng.uniform_f32() * spread;
        }
        r
    }

    /// Checks `rays` random rays; returns how many hit something.
    fn check(tris: &[[Vec3; 3]], spread: f32, rays: usize, seed: u64) -> usize {
        let (bvh, order) = build(tris, &[]);
        let mut sorted = order.clone();
        sorted.sort_unstable();
        assert!(sorted.iter().copied().eq(0..tris.len() as u32));
        let mut rng = Pcg32::with_sequence(seed);
        let mut hits = 0;
        for _ in 0..rays {
            let ray = random_ray(&mut rng, spread);
            let expect = brute(tris, &ray);
            let got = match bvh.closest(&ray, ray.t_max, |_, _| panic!("no other primitives")) {
                Closest::Nothing => None,
                Closest::Triangle { pos, t, b } => Some((t, order[pos as usize], b)),
                Closest::Other => panic!("no other primitives"),
            };
            match (expect, got) {
                (None, None) => {}
                (Some((te, ie)), Some((tg, ig, b))) => {
                    hits += 1;
                    // Same distance; the primitive may differ only on a tie.
                    assert_eq!(te, tg, "ray {ray:?}");
                    let t = tris[ig as usize];
                    let (ts, bs) =
                        intersect_triangle(ray.o, ray.d, ray.t_max, t[0], t[1], t[2]).unwrap();
                    assert_eq!((ts, bs), (tg, b), "four-lane test differs from scalar");
                    if ie != ig {
                        assert_eq!(brute(&[t], &ray).map(|h| h.0), Some(te));
                    }
                }
                (e, g) => panic!("ray {ray:?}: brute force {e:?}, BVH {g:?}"),
            }
            let occluded = bvh.any(&ray, ray.t_max, |_| panic!("no other primitives"));
            assert_eq!(occluded, expect.is_some(), "ray {ray:?}");
        }
        hits
    }

    #[test]
    fn closest_and_any_agree_with_brute_force() {
        let mut rng = Pcg32::with_sequence(7);
        for (n, size) in [
            (1, 0.8),
            (3, 0.5),
            (4, 0.5),
            (5, 0.5),
            (37, 0.3),
            (3000, 0.08),
        ] {
            let tris = random_triangles(&mut rng, n, 1.0, size);
            let hits = check(&tris, 1.0, 3000, n as u64);
            assert!(
                hits > 50,
                "{n} triangles: too few hits ({hits}) to test anything"
            );
        }
    }

    #[test]
    fn tiny_and_huge_scales() {
        let mut rng = Pcg32::with_sequence(9);
        for scale in [1e-6f32, 1e6] {
            let tris: Vec<[Vec3; 3]> = random_triangles(&mut rng, 500, 1.0, 0.2)
                .into_iter()
                .map(|t| t.map(|p| p * scale))
                .collect();
            assert!(check(&tris, scale, 2000, 3) > 200);
        }
    }

    #[test]
    fn deep_trees_fit_their_stack() {
        // Triangles of geometrically shrinking size nested around a point
        // make a deep tree.
        let mut tris = Vec::new();
        let mut s = 1.0f32;
        for i in 0..120 {
            let o = Vec3::splat(0.001 * (i % 2) as f32);
            tris.push([
                o + Vec3::new(s, 0.0, 0.0),
                o + Vec3::new(0.0, s, 0.0),
                o - Vec3::new(0.0, 0.0, s),
            ]);
            s *= 0.8;
        }
        let (bvh, _) = build(&tris, &[]);
        assert!(bvh.stack_need > TINY_STACK, "tree depth {}", bvh.stack_need);
        assert!(check(&tris, 1.0, 3000, 5) > 300);
        // The bound holds exactly: a stack of `stack_need` entries suffices.
        let mut rng = Pcg32::with_sequence(11);
        for _ in 0..3000 {
            let ray = random_ray(&mut rng, 1.0);
            let mut stack = vec![MaybeUninit::uninit(); bvh.stack_need];
            bvh.closest_with(&ray, ray.t_max, |_, _| None, |_| {}, &mut stack);
            let mut stack = vec![MaybeUninit::uninit(); bvh.stack_need];
            bvh.any_with(&ray, ray.t_max, |_| false, &mut stack);
        }
    }

    /// A binary tree that pairs a room's opposite side walls (as obvhs
    /// built it for the Cornell box): a leaf holding both would have the
    /// whole room as its box, entered by every ray, and the greedy collapse
    /// made that leaf (the pair has four triangles). The surface area
    /// heuristic gives each wall a box of its own.
    #[test]
    fn leaves_do_not_span_the_room() {
        use obvhs::bvh2::node::Bvh2Node;
        let quad = |a: [f32; 3], b: [f32; 3], c: [f32; 3], d: [f32; 3]| {
            let [a, b, c, d] = [a, b, c, d].map(Vec3::from);
            [[a, b, c], [a, c, d]]
        };
        // Left and right walls, then the back wall and the floor.
        let tris: Vec<[Vec3; 3]> = [
            quad([-1., 0., -1.], [-1., 0., 1.], [-1., 2., 1.], [-1., 2., -1.]),
            quad([1., 0., -1.], [1., 0., 1.], [1., 2., 1.], [1., 2., -1.]),
            quad([-1., 0., -1.], [1., 0., -1.], [1., 2., -1.], [-1., 2., -1.]),
            quad([-1., 0., -1.], [1., 0., -1.], [1., 0., 1.], [-1., 0., 1.]),
        ]
        .into_iter()
        .flatten()
        .collect();
        let tri_box = |i: usize| {
            let mut a = Aabb::empty();
            for p in tris[i] {
                a.extend(p.into());
            }
            a
        };
        // Node 0 the root; 1 and 2 the wall pairs; 3-6 one wall each;
        // 7-14 the triangles.
        let inner = |kids: [usize; 2], first: u32, nodes: &[Bvh2Node]| Bvh2Node {
            aabb: nodes[kids[0]].aabb.union(&nodes[kids[1]].aabb),
            prim_count: 0,
            first_index: first,
            ..Bvh2Node::default()
        };
        let mut nodes = vec![Bvh2Node::default(); 15];
        for t in 0..8 {
            nodes[7 + t] = Bvh2Node {
                aabb: tri_box(t),
                prim_count: 1,
                first_index: t as u32,
                ..Bvh2Node::default()
            };
        }
        for w in 0..4 {
            nodes[3 + w] = inner([7 + 2 * w, 8 + 2 * w], 7 + 2 * w as u32, &nodes);
        }
        nodes[1] = inner([3, 4], 3, &nodes);
        nodes[2] = inner([5, 6], 5, &nodes);
        nodes[0] = inner([1, 2], 1, &nodes);
        let mut bvh2 = Bvh2 {
            nodes,
            primitive_indices: (0..8).collect(),
            ..Bvh2::default()
        };
        let (bvh, order) = Bvh4::from_bvh2(&mut bvh2, |i| Some(tris[i]));
        assert_eq!(order.len(), 8);
        for leaf in &bvh.leaves {
            let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
            for &p in &order[leaf.first as usize..(leaf.first + leaf.count) as usize] {
                for v in tris[p as usize] {
                    (lo, hi) = (lo.min(v), hi.max(v));
                }
            }
            assert!(
                (hi - lo).min_element() == 0.0,
                "a leaf holds more than one wall: {lo} .. {hi}"
            );
        }
    }

    /// The primitives other than triangles that a closest-hit query along
    /// the z axis hands to its callback (rejecting each).
    fn others_on_axis(bvh: &Bvh4, order: &[u32]) -> Vec<u32> {
        let ray = Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::Z);
        let mut seen = Vec::new();
        bvh.closest(&ray, f32::INFINITY, |pos, _| {
            seen.push(order[pos as usize]);
            None
        });
        seen
    }

    #[test]
    fn other_primitives_are_handed_out() {
        let mut rng = Pcg32::with_sequence(3);
        let tris = random_triangles(&mut rng, 20, 1.0, 0.3);
        // Two boxes standing for spheres or instances.
        let others = [
            Aabb::new(Vec3::splat(-0.1).into(), Vec3::splat(0.1).into()),
            Aabb::new(Vec3::splat(0.3).into(), Vec3::splat(0.4).into()),
        ];
        let (bvh, order) = build(&tris, &others);
        assert_eq!(others_on_axis(&bvh, &order), vec![20]);
        let ray = Ray::new(Vec3::new(0.35, 0.35, -5.0), Vec3::Z);
        assert!(bvh.any(&ray, f32::INFINITY, |pos| order[pos as usize] == 21));
    }
}
