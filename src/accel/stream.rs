//! Independent rays traced side by side: up to [`STREAM_MAX`] incoherent
//! rays (a batch's bounces, photons) each walk the four-wide BVH on their
//! own, one step of each in turn, so that one ray's chain of dependent
//! steps (a node's loads, its box test, the choice of the next child)
//! overlaps the others' instead of the processor waiting on it. Each ray
//! finds what [`Bvh4::closest_hinted`] finds for it alone: the same
//! arithmetic in the same order, ray by ray.

use super::bvh4::{closer, lane_limit, reach, BoxRay, Bvh4, LEAF};
use super::packet::PacketHit;
use crate::geometry::Ray;
use crate::shapes::TriangleRay4;
use glam::Vec4;
use std::mem::MaybeUninit;

/// Most rays traced side by side.
pub const STREAM_MAX: usize = 16;

/// Stack entries each ray has room for (a deeper tree is traced ray by
/// ray).
const STACK: usize = 64;

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
    /// Whether [`Bvh4::closest_stream`] can trace this tree (triangles
    /// only, and a stack it has room for).
    pub(super) fn traces_streams(&self) -> bool {
        self.only_triangles && self.stack_need <= STACK
    }

    /// The closest hit of each of `rays` (at most [`STREAM_MAX`]) with
    /// `t <= ray.t_max`, in `out`. Only where [`Bvh4::traces_streams`].
    pub(super) fn closest_stream(&self, rays: &[Ray], out: &mut [PacketHit]) {
        let n = rays.len();
        assert!(n <= STREAM_MAX && out.len() == n && self.traces_streams());
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
                let j = m.trailing_zeros() as usize;
                m &= m - 1;
                let i = j;
                let l = &mut lanes[i];
                let stack = &mut stacks[j];
                let cur = l.cur;
                if cur & LEAF == 0 {
                    let n = &self.nodes[cur as usize];
                    let (t0, hit_box) = l.br.test(n, reach(l.t_max));
                    let mask = hit_box.bitmask();
                    if mask != 0 {
                        let t0m = Vec4::select(hit_box, t0, Vec4::INFINITY);
                        let near = (t0m.cmpeq(Vec4::splat(t0m.min_element())).bitmask() & mask)
                            .trailing_zeros() as usize;
                        let rest = mask & !(1 << near);
                        let ts = t0.to_array();
                        let mut sp = l.sp;
                        if rest & rest.wrapping_sub(1) == 0 {
                            for (i, (&c, t)) in n.child.iter().zip(ts).enumerate() {
                                stack[sp] = MaybeUninit::new((c, t));
                                sp += ((rest >> i) & 1) as usize;
                            }
                        } else {
                            let mut e = [(0u32, 0f32); 3];
                            let mut k = 0;
                            let mut r = rest;
                            while r != 0 {
                                let i = r.trailing_zeros() as usize;
                                e[k] = (n.child[i], ts[i]);
                                k += 1;
                                r &= r - 1;
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
                            for (slot, &x) in stack[sp..sp + 3].iter_mut().zip(&e) {
                                *slot = MaybeUninit::new(x);
                            }
                            sp += k;
                        }
                        l.sp = sp;
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
                loop {
                    if l.sp == 0 {
                        active &= !(1 << j);
                        break;
                    }
                    l.sp -= 1;
                    // SAFETY: entries below the stack pointer were written.
                    let (c, t0) = unsafe { stack[l.sp].assume_init() };
                    if t0 <= reach(l.t_max) {
                        l.cur = c;
                        break;
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::bvh4::tests::build;
    use crate::accel::bvh4::Closest;
    use crate::accel::packet::tests::{packet, point, scene};
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
            assert!(bvh.traces_streams());
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
                    let alone = match bvh.closest(r, r.t_max, |_, _| None) {
                        Closest::Triangle { pos, t, b } => Some((pos, t, b)),
                        Closest::Nothing => None,
                        Closest::Other => unreachable!("triangles only"),
                    };
                    let bits = |h: &PacketHit| {
                        h.map(|(pos, t, b)| (pos, t.to_bits(), b.map(f32::to_bits)))
                    };
                    assert_eq!(bits(got), bits(&alone), "ray {r:?}");
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
