//! Coherent rays traced together: a packet of up to [`PACKET_MAX`] rays
//! (a pixel's camera rays, or the shadow rays ambient occlusion sends from
//! one point) walks the four-wide BVH once, each node's boxes and each
//! leaf's triangles tested for every ray of the packet that reaches them:
//! for the closest hit ([`Bvh4::closest_packet`]) or for any hit
//! ([`Bvh4::any_packet`], which drops a ray from the packet once it is
//! blocked, and asks a callback about primitives other than triangles).
//!
//! One ray's traversal is a chain of dependent steps (a node's loads, its
//! box test, the choice of the next child, a branch that random rays
//! mispredict), so the processor waits on it; the rays of a packet are
//! independent of each other within a step, so their tests overlap, and
//! rays that follow the same way share its choices. Each ray of the packet
//! finds what [`Bvh4::closest_hinted`] finds for it alone: the same box and
//! triangle arithmetic, boxes and triangles tested a little past the ray's
//! closest hit so far (never past its own limit), and the closest kept by
//! the same order-independent rule (nearer, or as near and at a lower
//! position), checked ray by ray in the tests below and in
//! `tests/render_batch.rs`.

use super::bvh4::{closer, lane_limit, reach, BoxRay, Bvh4, LEAF};
use crate::geometry::Ray;
use crate::shapes::TriangleRay4;
use glam::Vec4;
use std::mem::MaybeUninit;

/// Most rays in a packet.
pub const PACKET_MAX: usize = 16;

/// Stack entries a packet traversal has room for (a deeper tree is traced
/// ray by ray).
pub(super) const STACK: usize = 64;

/// A ray's closest triangle: (BVH position, t, barycentrics).
pub(super) type PacketHit = Option<(u32, f32, [f32; 3])>;

/// The rays of `mask`, lowest first.
#[inline(always)]
fn each(mut mask: u32, mut f: impl FnMut(usize)) {
    while mask != 0 {
        f(mask.trailing_zeros() as usize);
        mask &= mask - 1;
    }
}

impl Bvh4 {
    /// Whether [`Bvh4::closest_packet`] can trace this tree (triangles
    /// only, and a stack it has room for).
    pub(super) fn traces_packets(&self) -> bool {
        self.only_triangles && self.stack_need <= STACK
    }

    /// The closest hit of each of `rays` (at most [`PACKET_MAX`]) with
    /// `t <= ray.t_max`, in `out` (as long as `rays`). Only where
    /// [`Bvh4::traces_packets`].
    pub(super) fn closest_packet(&self, rays: &[Ray], out: &mut [PacketHit]) {
        let n = rays.len();
        assert!(n <= PACKET_MAX && out.len() == n && self.traces_packets());
        if n == 0 {
            return;
        }
        let mut boxes = [const { MaybeUninit::<BoxRay>::uninit() }; PACKET_MAX];
        let mut tris = [const { MaybeUninit::<TriangleRay4>::uninit() }; PACKET_MAX];
        let mut limit = [0f32; PACKET_MAX];
        let mut t_max = [0f32; PACKET_MAX];
        let mut best_pos = [u32::MAX; PACKET_MAX];
        for (i, r) in rays.iter().enumerate() {
            boxes[i].write(BoxRay::new(r));
            tris[i].write(TriangleRay4::new(r.o, r.d));
            limit[i] = r.t_max;
            t_max[i] = r.t_max;
            out[i] = None;
        }
        // SAFETY (here and below): the first `n` entries were written, and
        // only rays of masks within `(1 << n) - 1` are read.
        let boxes = |i: usize| unsafe { boxes[i].assume_init_ref() };
        let tris = |i: usize| unsafe { tris[i].assume_init_ref() };
        // Entries: (node, slot, rays) for the child in `slot` of `node`,
        // whose box the rays are tested against again when it is popped.
        let mut stack = [(0u32, 0u32, 0u32); STACK];
        let mut sp = 0usize;
        let mut cur = 0u32;
        let mut active: u32 = (1 << n) - 1;
        loop {
            if cur & LEAF == 0 {
                let node = &self.nodes[cur as usize];
                // Which rays meet each child's box; the children in the
                // order of the packet's first ray's entry distances.
                let first = active.trailing_zeros() as usize;
                let (t0, hit) = boxes(first).test(node, reach(t_max[first]));
                let order = Vec4::select(hit, t0, Vec4::INFINITY).to_array();
                let mut masks = [0u32; 4];
                each(active, |i| {
                    let bits = boxes(i).test(node, reach(t_max[i])).1.bitmask();
                    for (c, m) in masks.iter_mut().enumerate() {
                        *m |= ((bits >> c) & 1) << i;
                    }
                });
                let mut kids = [(0usize, 0f32); 4];
                let mut k = 0;
                for (c, &m) in masks.iter().enumerate() {
                    if m != 0 {
                        kids[k] = (c, order[c]);
                        k += 1;
                    }
                }
                if k > 0 {
                    // Far to near, the nearest taken now.
                    let kids = &mut kids[..k];
                    kids.sort_unstable_by(|a, b| b.1.total_cmp(&a.1));
                    for &(c, _) in &kids[..k - 1] {
                        stack[sp] = (cur, c as u32, masks[c]);
                        sp += 1;
                    }
                    let near = kids[k - 1].0;
                    cur = node.child[near];
                    active = masks[near];
                    continue;
                }
            } else {
                let leaf = &self.leaves[(cur & !LEAF) as usize];
                each(active, |i| {
                    let tr = tris(i);
                    let lim = lane_limit(t_max[i], limit[i]);
                    let found = match tr.kz() {
                        0 => tr.intersect4::<0>(&leaf.v, lim, leaf.triangles),
                        1 => tr.intersect4::<1>(&leaf.v, lim, leaf.triangles),
                        _ => tr.intersect4::<2>(&leaf.v, lim, leaf.triangles),
                    };
                    if let Some((lane, t, b)) = found {
                        let pos = leaf.first + lane;
                        if closer(t, pos, t_max[i], best_pos[i]) {
                            t_max[i] = t;
                            best_pos[i] = pos;
                            out[i] = Some((pos, t, b));
                        }
                    }
                });
            }
            // Next: a stacked child whose box a ray still meets within
            // what it has found.
            loop {
                if sp == 0 {
                    return;
                }
                sp -= 1;
                let (parent, slot, mask) = stack[sp];
                let node = &self.nodes[parent as usize];
                let mut keep = 0u32;
                each(mask, |i| {
                    let bits = boxes(i).test(node, reach(t_max[i])).1.bitmask();
                    keep |= ((bits >> slot) & 1) << i;
                });
                if keep != 0 {
                    cur = node.child[slot as usize];
                    active = keep;
                    break;
                }
            }
        }
    }
}

impl Bvh4 {
    /// Whether [`Bvh4::any_packet`] can trace this tree (a stack it has
    /// room for; any primitives).
    pub(super) fn any_packets_fit(&self) -> bool {
        self.stack_need <= STACK
    }

    /// Whether something blocks each of `rays` (at most [`PACKET_MAX`])
    /// with `t <= ray.t_max`: bit `i` for `rays[i]`, each [`Bvh4::any`]'s
    /// answer for the ray alone, `blocks(i, position)` deciding a leaf's
    /// primitives other than plain triangles for ray `i` as `any`'s
    /// callback does. Each ray meets the leaves its own traversal meets
    /// (boxes are tested against its fixed `t_max`), and whether any of
    /// their primitives blocks it does not depend on the order they are
    /// visited in. For coherent rays (ambient occlusion's from one point).
    /// Only where [`Bvh4::any_packets_fit`].
    pub(super) fn any_packet(
        &self,
        rays: &[Ray],
        mut blocks: impl FnMut(usize, u32) -> bool,
    ) -> u32 {
        let n = rays.len();
        assert!(n <= PACKET_MAX && self.any_packets_fit());
        if n == 0 {
            return 0;
        }
        let mut boxes = [const { MaybeUninit::<BoxRay>::uninit() }; PACKET_MAX];
        let mut tris = [const { MaybeUninit::<TriangleRay4>::uninit() }; PACKET_MAX];
        let mut t_max = [0f32; PACKET_MAX];
        for (i, r) in rays.iter().enumerate() {
            boxes[i].write(BoxRay::new(r));
            tris[i].write(TriangleRay4::new(r.o, r.d));
            t_max[i] = r.t_max;
        }
        // SAFETY (here and below): the first `n` entries were written, and
        // only rays of masks within `(1 << n) - 1` are read.
        let boxes = |i: usize| unsafe { boxes[i].assume_init_ref() };
        let tris = |i: usize| unsafe { tris[i].assume_init_ref() };
        // Entries: (child, the rays that met its box).
        let mut stack = [(0u32, 0u32); STACK];
        let mut sp = 0usize;
        let mut cur = 0u32;
        let mut active: u32 = (1 << n) - 1;
        let mut blocked = 0u32;
        loop {
            if cur & LEAF == 0 {
                let node = &self.nodes[cur as usize];
                let mut masks = [0u32; 4];
                each(active, |i| {
                    let bits = boxes(i).test(node, t_max[i]).1.bitmask();
                    for (c, m) in masks.iter_mut().enumerate() {
                        *m |= ((bits >> c) & 1) << i;
                    }
                });
                // The first child met next, the others stacked.
                let mut next = None;
                for (c, &m) in masks.iter().enumerate() {
                    if m == 0 {
                        continue;
                    }
                    if next.is_none() {
                        next = Some(c);
                    } else {
                        stack[sp] = (node.child[c], m);
                        sp += 1;
                    }
                }
                if let Some(c) = next {
                    cur = node.child[c];
                    active = masks[c];
                    continue;
                }
            } else {
                let leaf = &self.leaves[(cur & !LEAF) as usize];
                let others = ((1u32 << leaf.count) - 1) & !leaf.triangles;
                each(active, |i| {
                    let tr = tris(i);
                    let mut hit = leaf.triangles != 0
                        && match tr.kz() {
                            0 => tr.any4::<0>(&leaf.v, t_max[i], leaf.triangles),
                            1 => tr.any4::<1>(&leaf.v, t_max[i], leaf.triangles),
                            _ => tr.any4::<2>(&leaf.v, t_max[i], leaf.triangles),
                        };
                    let mut m = others;
                    while !hit && m != 0 {
                        hit = blocks(i, leaf.first + m.trailing_zeros());
                        m &= m - 1;
                    }
                    blocked |= u32::from(hit) << i;
                });
            }
            // Next: a stacked child with rays not yet blocked.
            loop {
                if sp == 0 {
                    return blocked;
                }
                sp -= 1;
                let (child, mask) = stack[sp];
                let open = mask & !blocked;
                if open != 0 {
                    cur = child;
                    active = open;
                    break;
                }
            }
        }
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::accel::bvh4::tests::build;
    use crate::accel::bvh4::Closest;
    use crate::sampling::rng::Pcg32;
    use crate::shapes::intersect_triangle;
    use glam::Vec3;
    use obvhs::aabb::Aabb;

    pub(in crate::accel) fn point(rng: &mut Pcg32, s: f32) -> Vec3 {
        Vec3::new(
            rng.uniform_f32() - 0.5,
            rng.uniform_f32() - 0.5,
            rng.uniform_f32() - 0.5,
        ) * s
    }

    /// Random triangles, each also present a second time (exact ties
    /// between BVH positions), and a grid of unit squares split into
    /// triangles (shared edges and vertices).
    pub(in crate::accel) fn scene(rng: &mut Pcg32, n: usize) -> Vec<[Vec3; 3]> {
        let mut tris: Vec<[Vec3; 3]> = (0..n)
            .map(|_| {
                let c = point(rng, 4.0);
                [
                    c + point(rng, 1.0),
                    c + point(rng, 1.0),
                    c + point(rng, 1.0),
                ]
            })
            .collect();
        let twins: Vec<[Vec3; 3]> = tris.iter().step_by(3).copied().collect();
        tris.extend(twins);
        for i in -2..2 {
            for j in -2..2 {
                let p = |a: i32, b: i32| Vec3::new(a as f32, -1.5, b as f32);
                tris.push([p(i, j), p(i + 1, j), p(i + 1, j + 1)]);
                tris.push([p(i, j), p(i + 1, j + 1), p(i, j + 1)]);
            }
        }
        tris
    }

    /// Packets of `len` rays: from one point into a narrow cone (a pixel's
    /// camera rays), towards grid vertices and edges, or anywhere.
    pub(in crate::accel) fn packet(rng: &mut Pcg32, len: usize) -> Vec<Ray> {
        let kind = rng.uniform_u32_below(3);
        let o = point(rng, 6.0);
        let aim = point(rng, 2.0);
        (0..len)
            .map(|_| {
                let mut r = match kind {
                    0 => Ray::new(o, (aim - o).normalize() + point(rng, 0.01)),
                    1 => {
                        // Grid vertices and edge midpoints.
                        let a = rng.uniform_u32_below(9) as f32 * 0.5 - 2.0;
                        let b = rng.uniform_u32_below(9) as f32 * 0.5 - 2.0;
                        Ray::new(o, Vec3::new(a, -1.5, b) - o)
                    }
                    _ => Ray::new(point(rng, 6.0), point(rng, 1.0)),
                };
                if rng.uniform_u32_below(4) == 0 {
                    r.t_max = rng.uniform_f32() * 6.0;
                }
                r
            })
            .collect()
    }

    /// A ray's closest triangle found by the single-ray traversal.
    pub(in crate::accel) fn closest_alone(bvh: &Bvh4, r: &Ray) -> PacketHit {
        match bvh.closest(r, r.t_max, |_, _| None) {
            Closest::Triangle { pos, t, b } => Some((pos, t, b)),
            Closest::Nothing => None,
            Closest::Other => unreachable!("triangles only"),
        }
    }

    /// A hit as bits, for exact comparisons.
    pub(in crate::accel) fn hit_bits(h: &PacketHit) -> Option<(u32, u32, [u32; 3])> {
        h.map(|(pos, t, b)| (pos, t.to_bits(), b.map(f32::to_bits)))
    }

    /// Whether a ray meets the sphere (centre, radius) at a t in (0, t_max].
    fn meets_sphere(r: &Ray, (c, radius): (Vec3, f32)) -> bool {
        let oc = r.o - c;
        let (a, b, cc) = (
            r.d.dot(r.d),
            2.0 * oc.dot(r.d),
            oc.dot(oc) - radius * radius,
        );
        let disc = b * b - 4.0 * a * cc;
        if disc < 0.0 {
            return false;
        }
        let q = disc.sqrt();
        let (t0, t1) = ((-b - q) / (2.0 * a), (-b + q) / (2.0 * a));
        (t0 > 0.0 && t0 <= r.t_max) || (t1 > 0.0 && t1 <= r.t_max)
    }

    /// Any-hit packets against triangles alone, and against triangles
    /// mixed with spheres (other primitives, decided by the callback): each
    /// ray gets what `Bvh4::any` answers for it alone.
    #[test]
    fn each_ray_of_a_packet_gets_its_own_occlusion() {
        each_ray_gets_its_own_occlusion(11, packet, |bvh, rays, blocks| {
            bvh.any_packet(rays, blocks)
        });
    }

    /// Up to [`PACKET_MAX`] rays made by `rays(rng, len)`, some of them
    /// shadow rays of limited reach, traced by `trace` over random
    /// triangles alone and mixed with spheres (tested by the callback it is
    /// given): each ray's bit is what `Bvh4::any` answers for it alone, and
    /// no bit is set past the rays.
    pub(in crate::accel) fn each_ray_gets_its_own_occlusion(
        seed: u64,
        rays: fn(&mut Pcg32, usize) -> Vec<Ray>,
        trace: impl Fn(&Bvh4, &[Ray], &dyn Fn(usize, u32) -> bool) -> u32,
    ) {
        let mut rng = Pcg32::with_sequence(seed);
        let (mut blocked, mut open, mut by_spheres) = (0, 0, 0);
        for n in [4, 20, 300, 3000] {
            for n_spheres in [0, 1, 3, n / 4] {
                let tris = scene(&mut rng, n);
                let spheres: Vec<(Vec3, f32)> = (0..n_spheres)
                    .map(|_| (point(&mut rng, 4.0), 0.05 + 0.4 * rng.uniform_f32()))
                    .collect();
                let boxes: Vec<Aabb> = spheres
                    .iter()
                    .map(|&(c, r)| {
                        Aabb::new((c - Vec3::splat(r)).into(), (c + Vec3::splat(r)).into())
                    })
                    .collect();
                let (bvh, order) = build(&tris, &boxes);
                let sphere_at = |pos: u32| spheres[order[pos as usize] as usize - tris.len()];
                for _ in 0..200 {
                    let len = 1 + rng.uniform_u32_below(PACKET_MAX as u32) as usize;
                    let mut rays = rays(&mut rng, len);
                    // Shadow rays of limited reach too, some ending on the
                    // grid (at a vertex or edge) or just short of it.
                    for r in rays.iter_mut() {
                        if rng.uniform_u32_below(2) == 0 {
                            r.t_max = rng.uniform_f32() * 8.0;
                        }
                    }
                    let got = trace(&bvh, &rays, &|i, pos| {
                        meets_sphere(&rays[i], sphere_at(pos))
                    });
                    for (i, r) in rays.iter().enumerate() {
                        let alone = bvh.any(r, r.t_max, |pos| meets_sphere(r, sphere_at(pos)));
                        assert_eq!(got >> i & 1 == 1, alone, "ray {r:?}");
                        if alone {
                            blocked += 1;
                            by_spheres += usize::from(!bvh.any(r, r.t_max, |_| false));
                        } else {
                            open += 1;
                        }
                    }
                    assert_eq!(got >> len, 0, "bits past the rays");
                }
            }
        }
        assert!(
            blocked > 2000 && open > 2000 && by_spheres > 200,
            "{blocked} blocked ({by_spheres} by spheres alone), {open} open"
        );
    }

    #[test]
    fn each_ray_of_a_packet_finds_its_own_closest_hit() {
        let mut rng = Pcg32::with_sequence(7);
        let mut hits = 0;
        let mut ties = 0;
        for n in [4, 20, 300, 3000] {
            let tris = scene(&mut rng, n);
            let (bvh, _) = build(&tris, &[]);
            assert!(bvh.traces_packets());
            for _ in 0..400 {
                let len = 1 + rng.uniform_u32_below(PACKET_MAX as u32) as usize;
                let rays = packet(&mut rng, len);
                let mut out = [None; PACKET_MAX];
                bvh.closest_packet(&rays, &mut out[..len]);
                for (r, got) in rays.iter().zip(&out) {
                    let alone = closest_alone(&bvh, r);
                    assert_eq!(hit_bits(got), hit_bits(&alone), "ray {r:?}");
                    if let Some((_, t, _)) = alone {
                        hits += 1;
                        // Triangles hit at the very same distance: the
                        // choice between them is the tie rule's.
                        let same = tris
                            .iter()
                            .filter(|v| {
                                intersect_triangle(r.o, r.d, r.t_max, v[0], v[1], v[2])
                                    .is_some_and(|(th, _)| th == t)
                            })
                            .count();
                        ties += usize::from(same > 1);
                    }
                }
            }
        }
        assert!(hits > 5000, "{hits} hits");
        assert!(ties > 0, "no equal distances tested");
    }
}
