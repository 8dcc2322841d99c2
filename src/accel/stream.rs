//! Independent rays traced side by side: up to [`STREAM_MAX`] incoherent
//! rays (a batch's bounces, photons) each walk the four-wide BVH on their
//! own, one step of each in turn, so that one ray's chain of dependent
//! steps (a node's loads, its box test, the choice of the next child)
//! overlaps the others' instead of the processor waiting on it. Each ray
//! finds what [`Bvh4::closest_hinted`] finds for it alone: the same
//! arithmetic in the same order, ray by ray. Shadow rays from different
//! points ([`Bvh4::any_stream`]) walk side by side the same way, each
//! stopping at the first thing that blocks it.

use super::bvh4::{closer, lane_limit, pop_within, reach, stack_children, BoxRay, Bvh4, LEAF};
use super::packet::PacketHit;
use crate::geometry::Ray;
use crate::shapes::TriangleRay4;
use std::mem::MaybeUninit;

/// Most rays traced side by side.
pub const STREAM_MAX: usize = super::packet::PACKET_MAX;

/// Stack entries each ray has room for: a packet's ([`Bvh4::traces_packets`]
/// says whether the tree fits).
const STACK: usize = super::packet::STACK;

struct Lane {
    br: BoxRay,
    tr: TriangleRay4,
    t_max: f32,
    limit: f32,
    best_pos: u32,
    cur: u32,
    sp: usize,
}

impl Bvh4 {
    /// The closest hit of each of `rays` (at most [`STREAM_MAX`]) with
    /// `t <= ray.t_max`, in `out`. Only where [`Bvh4::traces_packets`] (triangles
    /// only, and a stack of [`STACK`] entries is enough).
    pub(super) fn closest_stream(&self, rays: &[Ray], out: &mut [PacketHit]) {
        let n = rays.len();
        assert!(n <= STREAM_MAX && out.len() == n && self.traces_packets());
        let mut lanes = [const { MaybeUninit::<Lane>::uninit() }; STREAM_MAX];
        for (i, r) in rays.iter().enumerate() {
            lanes[i].write(Lane {
                br: BoxRay::new(r),
                tr: TriangleRay4::new(r.o, r.d),
                t_max: r.t_max,
                limit: r.t_max,
                best_pos: u32::MAX,
                cur: 0,
                sp: 0,
            });
            out[i] = None;
        }
        // SAFETY: the first `n` lanes were written.
        let lanes = unsafe { &mut *(&mut lanes[..n] as *mut [MaybeUninit<Lane>] as *mut [Lane]) };
        self.stream(lanes, out);
    }

    #[inline(always)]
    fn stream(&self, lanes: &mut [Lane], out: &mut [PacketHit]) {
        let mut stacks = [[MaybeUninit::<(u32, f32)>::uninit(); STACK]; STREAM_MAX];
        in_turn(lanes.len(), |i| {
            let l = &mut lanes[i];
            let stack = &mut stacks[i];
            let cur = l.cur;
            if cur & LEAF == 0 {
                let n = &self.nodes[cur as usize];
                let (t0, hit_box) = l.br.test(n, reach(l.t_max));
                let mask = hit_box.bitmask();
                if mask != 0 {
                    let near = stack_children(n, (t0, hit_box, mask), stack, &mut l.sp);
                    l.cur = n.child[near];
                    return true;
                }
            } else {
                let leaf = &self.leaves[(cur & !LEAF) as usize];
                if let Some((lane, t, b)) =
                    l.tr.intersect4_any_axis(&leaf.v, lane_limit(l.t_max, l.limit), leaf.triangles)
                {
                    let pos = leaf.first + lane;
                    if closer(t, pos, l.t_max, l.best_pos) {
                        l.t_max = t;
                        l.best_pos = pos;
                        out[i] = Some((pos, t, b));
                    }
                }
            }
            match pop_within(stack, &mut l.sp, l.t_max) {
                Some(c) => {
                    l.cur = c;
                    true
                }
                None => false,
            }
        });
    }
}

/// The first `n` lanes stepped in turn, one step of each per round, until
/// `step(lane)` has answered false (the lane's walk is over) for every one.
#[inline(always)]
fn in_turn(n: usize, mut step: impl FnMut(usize) -> bool) {
    let mut active: u32 = (1u32 << n) - 1;
    while active != 0 {
        let mut m = active;
        while m != 0 {
            let i = m.trailing_zeros() as usize;
            m &= m - 1;
            if !step(i) {
                active &= !(1 << i);
            }
        }
    }
}

/// A shadow ray's walk: [`Bvh4::any`]'s state.
struct AnyLane {
    br: BoxRay,
    tr: TriangleRay4,
    t_max: f32,
    cur: u32,
    sp: usize,
}

impl Bvh4 {
    /// Whether something blocks each of incoherent `rays` (at most
    /// [`STREAM_MAX`]) with `t <= ray.t_max`: bit `i` for `rays[i]`, each
    /// [`Bvh4::any`]'s answer for the ray alone, `blocks(i, position)`
    /// deciding a leaf's primitives other than plain triangles for ray `i`
    /// as `any`'s callback does. Each ray tests the boxes against its own
    /// fixed `t_max`, so it meets the leaves its own traversal meets, and
    /// whether any of their primitives blocks it does not depend on the
    /// order they are visited in. Only where [`Bvh4::any_packets_fit`].
    pub(super) fn any_stream(
        &self,
        rays: &[Ray],
        mut blocks: impl FnMut(usize, u32) -> bool,
    ) -> u32 {
        let n = rays.len();
        assert!(n <= STREAM_MAX && self.any_packets_fit());
        let mut lanes = [const { MaybeUninit::<AnyLane>::uninit() }; STREAM_MAX];
        for (i, r) in rays.iter().enumerate() {
            lanes[i].write(AnyLane {
                br: BoxRay::new(r),
                tr: TriangleRay4::new(r.o, r.d),
                t_max: r.t_max,
                cur: 0,
                sp: 0,
            });
        }
        // SAFETY: the first `n` lanes were written.
        let lanes =
            unsafe { &mut *(&mut lanes[..n] as *mut [MaybeUninit<AnyLane>] as *mut [AnyLane]) };
        let mut stacks = [[MaybeUninit::<u32>::uninit(); STACK]; STREAM_MAX];
        let mut blocked = 0u32;
        in_turn(n, |i| {
            let l = &mut lanes[i];
            let stack = &mut stacks[i];
            let cur = l.cur;
            if cur & LEAF == 0 {
                let node = &self.nodes[cur as usize];
                let mask = l.br.test(node, l.t_max).1.bitmask();
                if mask != 0 {
                    // The first child met next, the others stacked (every
                    // slot written, the pointer moved past the met ones).
                    let first = mask.trailing_zeros() as usize;
                    let rest = mask & !(1 << first);
                    for c in 0..4 {
                        stack[l.sp] = MaybeUninit::new(node.child[c]);
                        l.sp += ((rest >> c) & 1) as usize;
                    }
                    l.cur = node.child[first];
                    return true;
                }
            } else {
                let leaf = &self.leaves[(cur & !LEAF) as usize];
                let mut hit =
                    leaf.triangles != 0 && l.tr.any4_any_axis(&leaf.v, l.t_max, leaf.triangles);
                let mut others = ((1u32 << leaf.count) - 1) & !leaf.triangles;
                while !hit && others != 0 {
                    hit = blocks(i, leaf.first + others.trailing_zeros());
                    others &= others - 1;
                }
                if hit {
                    blocked |= 1 << i;
                    return false;
                }
            }
            if l.sp == 0 {
                return false;
            }
            l.sp -= 1;
            // SAFETY: entries below the pointer were written.
            l.cur = unsafe { stack[l.sp].assume_init() };
            true
        });
        blocked
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::bvh4::tests::build;
    use crate::accel::packet::tests::{
        closest_alone, each_ray_gets_its_own_occlusion, hit_bits, packet, point, scene,
    };
    use crate::sampling::rng::Pcg32;

    /// Shadow rays side by side, over triangles alone and mixed with
    /// spheres (the callback's): each gets what `Bvh4::any` answers for it
    /// alone.
    #[test]
    fn each_ray_side_by_side_gets_its_own_occlusion() {
        each_ray_gets_its_own_occlusion(13, mixed, |bvh, rays, blocks| {
            bvh.any_stream(rays, blocks)
        });
    }

    /// `len` rays from several packets (coherent, aimed at grid vertices
    /// and edges, anywhere, some of limited reach), so that rays side by
    /// side go different ways and have different axes.
    fn mixed(rng: &mut Pcg32, len: usize) -> Vec<Ray> {
        let mut rays = Vec::new();
        while rays.len() < len {
            let k = 1 + rng.uniform_u32_below(4) as usize;
            rays.extend(packet(rng, k.min(len - rays.len())));
        }
        rays
    }

    /// Rays of every kind mixed (a few of them from each of several
    /// packets: coherent, aimed at grid vertices and edges, anywhere, some
    /// of limited reach), so that rays side by side go different ways and
    /// have different axes: each finds what it finds alone, bit for bit.
    #[test]
    fn each_ray_side_by_side_finds_its_own_closest_hit() {
        let mut rng = Pcg32::with_sequence(5);
        let (mut hits, mut misses) = (0, 0);
        for n in [1, 4, 20, 300, 3000] {
            let tris = scene(&mut rng, n);
            let (bvh, _) = build(&tris, &[]);
            assert!(bvh.traces_packets());
            for _ in 0..400 {
                let len = 1 + rng.uniform_u32_below(STREAM_MAX as u32) as usize;
                let mut rays = mixed(&mut rng, len);
                if rng.uniform_u32_below(8) == 0 {
                    // A ray starting on a triangle of the scene.
                    let v = tris[rng.uniform_u32_below(tris.len() as u32) as usize];
                    rays[0] = Ray::new((v[0] + v[1] + v[2]) / 3.0, point(&mut rng, 1.0));
                }
                let mut out = [Some((0, 0.0, [0.0; 3])); STREAM_MAX];
                bvh.closest_stream(&rays, &mut out[..len]);
                for (r, got) in rays.iter().zip(&out) {
                    let alone = closest_alone(&bvh, r);
                    assert_eq!(hit_bits(got), hit_bits(&alone), "ray {r:?}");
                    if alone.is_some() {
                        hits += 1;
                    } else {
                        misses += 1;
                    }
                }
            }
        }
        assert!(hits > 5000 && misses > 2000, "{hits} hits, {misses} misses");
    }
}
