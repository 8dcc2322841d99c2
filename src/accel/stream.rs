//! Independent rays traced side by side: up to [`STREAM_MAX`] incoherent
//! rays (a batch's bounces, photons) each walk the four-wide BVH on their
//! own, one step of each in turn, so that one ray's chain of dependent
//! steps (a node's loads, its box test, the choice of the next child)
//! overlaps the others' instead of the processor waiting on it. Each ray
//! finds what [`Bvh4::closest_hinted`] finds for it alone: the same
//! arithmetic in the same order, ray by ray.

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
        let mut active: u32 = (1u32 << lanes.len()) - 1;
        while active != 0 {
            let mut m = active;
            while m != 0 {
                let i = m.trailing_zeros() as usize;
                m &= m - 1;
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
                        continue;
                    }
                } else {
                    let leaf = &self.leaves[(cur & !LEAF) as usize];
                    if let Some((lane, t, b)) = l.tr.intersect4_any_axis(
                        &leaf.v,
                        lane_limit(l.t_max, l.limit),
                        leaf.triangles,
                    ) {
                        let pos = leaf.first + lane;
                        if closer(t, pos, l.t_max, l.best_pos) {
                            l.t_max = t;
                            l.best_pos = pos;
                            out[i] = Some((pos, t, b));
                        }
                    }
                }
                match pop_within(stack, &mut l.sp, l.t_max) {
                    Some(c) => l.cur = c,
                    None => active &= !(1 << i),
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::bvh4::tests::build;
    use crate::accel::packet::tests::{closest_alone, hit_bits, packet, point, scene};
    use crate::sampling::rng::Pcg32;

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
                let mut rays = Vec::new();
                while rays.len() < len {
                    let k = 1 + rng.uniform_u32_below(4) as usize;
                    rays.extend(packet(&mut rng, k.min(len - rays.len())));
                }
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
