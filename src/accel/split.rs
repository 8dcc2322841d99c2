//! A top-down binned-SAH BVH builder with a bounded cost, for the inputs
//! where obvhs's PLOC degrades: many primitives with the same box (the same
//! triangle indexed again and again, instanced copies in one place). PLOC
//! merges mutual nearest neighbours; when neighbouring merge costs tie, only
//! the last of a run of equal boxes finds a mutual partner, so a run of `k`
//! equal boxes takes `k` passes over all `n` nodes (`n·k` work, 20,000
//! coincident triangles took 40 s) and becomes a chain of depth `k`.
//!
//! This builder splits by the surface-area heuristic over 16 bins of the
//! centroids on each axis; where the centroids coincide, the SAH finds no
//! split or the tree grows deeper than `2·log2(n) + 16`, it splits at the
//! median instead (coincident primitives: by position in the list). Every
//! range is touched a constant number of times per level and the depth is at
//! most `3·log2(n) + 17`, so the work is O(n log n) for any input; `work`
//! counts the primitive touches so that tests can check it without timing.

use obvhs::aabb::Aabb;
use obvhs::bvh2::node::Bvh2Node;
use obvhs::bvh2::Bvh2;

const BINS: usize = 16;

/// Builds a binary BVH with one primitive per leaf (as PLOC does) over
/// `aabbs`; adds the primitive touches to `work`.
pub(super) fn build(aabbs: &[Aabb], work: &mut u64) -> Bvh2 {
    let n = aabbs.len();
    assert!(n > 0);
    let centroids: Vec<[f32; 3]> = aabbs
        .iter()
        .map(|b| {
            let c = b.center();
            [c.x, c.y, c.z]
        })
        .collect();
    let mut prims: Vec<u32> = (0..n as u32).collect();
    let mut nodes = vec![Bvh2Node::default(); 2 * n - 1];
    let mut next = 1usize;
    let sah_depth = 2 * (usize::BITS - n.leading_zeros()) as usize + 16;
    // (node, start, end, depth)
    let mut stack = vec![(0usize, 0usize, n, 0usize)];
    while let Some((node, start, end, depth)) = stack.pop() {
        let range = &mut prims[start..end];
        *work += range.len() as u64;
        let mut bounds = Aabb::empty();
        let mut cb = Aabb::empty();
        for &p in range.iter() {
            bounds = bounds.union(&aabbs[p as usize]);
            let c = centroids[p as usize];
            cb.extend(glam::Vec3A::new(c[0], c[1], c[2]));
        }
        if range.len() == 1 {
            nodes[node] = Bvh2Node::new(bounds, 1, start as u32);
            continue;
        }
        let extent = cb.diagonal();
        let axis = cb.largest_axis();
        let mut mid = None;
        if depth < sah_depth && extent[axis] > 0.0 {
            *work += 2 * range.len() as u64;
            mid = sah_split(range, aabbs, &centroids, &cb);
        }
        let mid = match mid {
            Some(m) => m,
            None => {
                let m = range.len() / 2;
                if extent[axis] > 0.0 {
                    *work += range.len() as u64;
                    range.select_nth_unstable_by(m, |&a, &b| {
                        centroids[a as usize][axis].total_cmp(&centroids[b as usize][axis])
                    });
                }
                m
            }
        };
        let first = next;
        next += 2;
        nodes[node] = Bvh2Node::new(bounds, 0, first as u32);
        stack.push((first + 1, start + mid, end, depth + 1));
        stack.push((first, start, start + mid, depth + 1));
    }
    debug_assert_eq!(next, 2 * n - 1);
    let mut bvh = Bvh2 {
        nodes,
        primitive_indices: prims,
        ..Default::default()
    };
    bvh.max_depth = bvh.max_depth.max(3 * sah_depth);
    bvh.children_are_ordered_after_parents = true;
    bvh
}

/// Partitions `range` at the cheapest SAH split over 16 bins per axis;
/// returns the size of the first part, or None if no split separates
/// anything (all centroids in one bin) or splitting costs more than a leaf
/// of the whole range would.
fn sah_split(
    range: &mut [u32],
    aabbs: &[Aabb],
    centroids: &[[f32; 3]],
    cb: &Aabb,
) -> Option<usize> {
    let d = cb.diagonal();
    let mut best = (f32::INFINITY, 0usize, 0usize); // (cost, axis, bins left)
    for axis in 0..3 {
        if d[axis] <= 0.0 {
            continue;
        }
        let scale = BINS as f32 / d[axis];
        let lo = cb.min[axis];
        let bin_of = |c: f32| (((c - lo) * scale) as usize).min(BINS - 1);
        let mut count = [0u32; BINS];
        let mut bb = [Aabb::empty(); BINS];
        for &p in range.iter() {
            let b = bin_of(centroids[p as usize][axis]);
            count[b] += 1;
            bb[b] = bb[b].union(&aabbs[p as usize]);
        }
        // Sweep from the right, then from the left.
        let mut right_area = [0.0f32; BINS];
        let mut acc = Aabb::empty();
        let mut acc_n = 0u32;
        let mut right_n = [0u32; BINS];
        for i in (1..BINS).rev() {
            acc = acc.union(&bb[i]);
            acc_n += count[i];
            right_area[i] = acc.half_area();
            right_n[i] = acc_n;
        }
        let mut left = Aabb::empty();
        let mut left_n = 0u32;
        for i in 1..BINS {
            left = left.union(&bb[i - 1]);
            left_n += count[i - 1];
            if left_n == 0 || right_n[i] == 0 {
                continue;
            }
            let cost = left.half_area() * left_n as f32 + right_area[i] * right_n[i] as f32;
            if cost < best.0 {
                best = (cost, axis, i);
            }
        }
    }
    if !best.0.is_finite() {
        return None;
    }
    let (_, axis, split) = best;
    let scale = BINS as f32 / d[axis];
    let lo = cb.min[axis];
    let mut i = 0;
    let mut j = range.len();
    while i < j {
        let c = centroids[range[i] as usize][axis];
        if ((((c - lo) * scale) as usize).min(BINS - 1)) < split {
            i += 1;
        } else {
            j -= 1;
            range.swap(i, j);
        }
    }
    (i > 0 && i < range.len()).then_some(i)
}

/// Largest number of primitives sharing one box, found by sorting hashes
/// of the boxes' bits (a collision can only overstate it): O(n log n).
pub(super) fn largest_coincident_run(aabbs: &[Aabb], work: &mut u64) -> usize {
    let mut keys: Vec<u64> = aabbs
        .iter()
        .map(|b| {
            let mut h = 0xcbf2_9ce4_8422_2325u64;
            for v in [b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z] {
                h = (h ^ v.to_bits() as u64).wrapping_mul(0x0100_0000_01b3);
                h ^= h >> 29;
            }
            h
        })
        .collect();
    keys.sort_unstable();
    let n = keys.len() as u64;
    *work += n * (64 - n.leading_zeros() as u64).max(1);
    let mut best = 0;
    let mut run = 0;
    for i in 0..keys.len() {
        run = if i > 0 && keys[i] == keys[i - 1] {
            run + 1
        } else {
            1
        };
        best = best.max(run);
    }
    best
}
