//! A parallel top-down binned-SAH builder that makes the four-wide tree
//! directly, for big levels (millions of triangles), where obvhs's PLOC and
//! the binary tree it collapses from cost about 250 bytes per primitive and
//! a mostly single-threaded reinsertion pass.
//!
//! The build works on one array of 32-byte references (a primitive's box,
//! its index and its weight), partitioned in place: a node's range is split
//! in two at the cheapest of 32 bins across its widest centroid axis by the
//! surface area heuristic (ranges of 5 to 16 triangles where whole leaves
//! come out on the left, sorted along each axis), and its widest part split
//! again until it has four children; a range of weight at most four (a
//! triangle weighs one, any other primitive four, as in [`super::bvh4`]'s
//! collapse) is a leaf. Where the centroids coincide it
//! splits the range in the middle, and below a depth of `2·log2(n) + 16` at
//! the median of the widest centroid axis, so any input builds in
//! O(n log n) with a bounded depth.
//!
//! Parallel and deterministic: binning and bounds are reduced with min, max
//! and integer sums (exact in any order); the partition of a big range works
//! on fixed-size chunks and swaps the misplaced runs; subtrees of big ranges
//! are built as separate tasks into their own node arrays, joined once at
//! the end in pre-order ([`flatten`]). The tree is the same for any number
//! of threads. The references are freed before the join and the leaves
//! (which copy their triangles' vertices) are made last, so the peak is the
//! finished BVH and the mesh: about 67 bytes per triangle plus the mesh.

use super::bvh4::{Leaf, Node, LEAF, LEAF_SIZE};
use glam::{BVec4A, Vec3, Vec4};
use rayon::prelude::*;

/// A primitive's box: `lo.w` holds its index (as bits), `hi.w` its weight.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub(super) struct Ref {
    lo: Vec4,
    hi: Vec4,
}

impl Ref {
    pub(super) fn new(lo: Vec3, hi: Vec3, prim: u32, triangle: bool) -> Ref {
        Ref {
            lo: lo.extend(f32::from_bits(prim)),
            hi: hi.extend(if triangle { 1.0 } else { LEAF_SIZE as f32 }),
        }
    }
    /// A reference that [`Ref::is_void`] (a primitive left out).
    pub(super) const VOID: Ref = Ref {
        lo: Vec4::NAN,
        hi: Vec4::NAN,
    };
    pub(super) fn is_void(&self) -> bool {
        self.lo.x.is_nan()
    }
    #[inline(always)]
    pub(super) fn prim(&self) -> u32 {
        self.lo.w.to_bits()
    }
    #[inline(always)]
    fn weight(&self) -> u32 {
        self.hi.w as u32
    }
    /// Twice the centroid (in x, y, z).
    #[inline(always)]
    fn centroid2(&self) -> Vec4 {
        self.lo + self.hi
    }
}

const BINS: usize = 32;
/// Ranges at least this long are binned, bounded and partitioned in
/// parallel chunks of `CHUNK`.
const PAR_PASS: usize = 1 << 16;
const CHUNK: usize = 1 << 14;
/// Subtrees of ranges at least this long are built as tasks of their own.
const PAR_TREE: usize = 1 << 12;

/// A box of x, y, z (the w lanes are ignored).
#[derive(Clone, Copy, Debug)]
struct Box4 {
    lo: Vec4,
    hi: Vec4,
}

impl Box4 {
    const EMPTY: Box4 = Box4 {
        lo: Vec4::splat(f32::INFINITY),
        hi: Vec4::splat(f32::NEG_INFINITY),
    };
    #[inline(always)]
    fn grow(&mut self, lo: Vec4, hi: Vec4) {
        self.lo = self.lo.min(lo);
        self.hi = self.hi.max(hi);
    }
    #[inline(always)]
    fn union(self, o: Box4) -> Box4 {
        Box4 {
            lo: self.lo.min(o.lo),
            hi: self.hi.max(o.hi),
        }
    }
    /// Half the surface area (0 for an empty box).
    fn half_area(&self) -> f32 {
        let d = (self.hi - self.lo).truncate().max(Vec3::ZERO);
        d.x * d.y + d.y * d.z + d.z * d.x
    }
}

/// A range of references with its bounds.
#[derive(Clone, Copy, Debug)]
struct Range {
    start: usize,
    end: usize,
    bounds: Box4,
    /// Bounds of the doubled centroids.
    cent: Box4,
    weight: u64,
}

impl Range {
    fn len(&self) -> usize {
        self.end - self.start
    }
}

/// Bounds, centroid bounds and weight of `refs` (which sit at `start`).
fn range_of(refs: &[Ref], start: usize) -> Range {
    let one = |rs: &[Ref]| {
        let (mut b, mut c, mut w) = (Box4::EMPTY, Box4::EMPTY, 0u64);
        for r in rs {
            b.grow(r.lo, r.hi);
            let m = r.centroid2();
            c.grow(m, m);
            w += r.weight() as u64;
        }
        (b, c, w)
    };
    let (bounds, cent, weight) = if refs.len() >= PAR_PASS {
        refs.par_chunks(CHUNK).map(one).reduce(
            || (Box4::EMPTY, Box4::EMPTY, 0),
            |a, b| (a.0.union(b.0), a.1.union(b.1), a.2 + b.2),
        )
    } else {
        one(refs)
    };
    Range {
        start,
        end: start + refs.len(),
        bounds,
        cent,
        weight,
    }
}

#[derive(Clone, Copy)]
struct Bins<const B: usize> {
    b: [Box4; B],
    n: [u32; B],
}

/// The split plane: primitives whose centroid falls in a bin below `bin`
/// on `axis` go left.
#[derive(Clone, Copy)]
struct Plane {
    bins: usize,
    axis: usize,
    bin: usize,
    lo: f32,
    scale: f32,
}

impl Plane {
    #[inline(always)]
    fn bin_of(c: f32, lo: f32, scale: f32, bins: usize) -> usize {
        (((c - lo) * scale) as usize).min(bins - 1)
    }
    #[inline(always)]
    fn left(&self, r: &Ref) -> bool {
        Self::bin_of(r.centroid2()[self.axis], self.lo, self.scale, self.bins) < self.bin
    }
}

/// The cheapest SAH split of `range` (centroid extent > 0 on some axis)
/// across the widest axis of its centroids (as Wald's fast binned
/// builders: a third of the binning of all three axes, and about the same
/// trees): over 32 bins, or 8 for short ranges (whose bins would mostly be
/// empty).
fn sah_plane(refs: &[Ref], range: &Range) -> Option<Plane> {
    if range.len() >= 64 {
        sah_plane_in::<BINS>(refs, range)
    } else {
        sah_plane_in::<8>(refs, range)
    }
}

fn sah_plane_in<const B: usize>(refs: &[Ref], range: &Range) -> Option<Plane> {
    let ext = (range.cent.hi - range.cent.lo).truncate();
    let axis = ext.max_position();
    if ext[axis] <= 0.0 {
        return None;
    }
    let lo = range.cent.lo[axis];
    let scale = B as f32 / ext[axis];
    let bin = |rs: &[Ref]| {
        let mut bins = Bins::<B> {
            b: [Box4::EMPTY; B],
            n: [0; B],
        };
        for r in rs {
            let k = Plane::bin_of(r.centroid2()[axis], lo, scale, B);
            bins.b[k].grow(r.lo, r.hi);
            bins.n[k] += 1;
        }
        bins
    };
    let slice = &refs[range.start..range.end];
    let bins = if slice.len() >= PAR_PASS {
        slice.par_chunks(CHUNK).map(bin).reduce_with(|mut a, b| {
            for k in 0..B {
                a.b[k] = a.b[k].union(b.b[k]);
                a.n[k] += b.n[k];
            }
            a
        })?
    } else {
        bin(slice)
    };
    let (b, n) = (&bins.b, &bins.n);
    let mut right_area = [0.0f32; B];
    let mut right_n = [0u32; B];
    let (mut acc, mut acc_n) = (Box4::EMPTY, 0u32);
    for k in (1..B).rev() {
        acc = acc.union(b[k]);
        acc_n += n[k];
        right_area[k] = acc.half_area();
        right_n[k] = acc_n;
    }
    let mut best: Option<(f32, usize)> = None;
    let (mut left, mut left_n) = (Box4::EMPTY, 0u32);
    for k in 1..B {
        left = left.union(b[k - 1]);
        left_n += n[k - 1];
        if left_n == 0 || right_n[k] == 0 {
            continue;
        }
        let cost = left.half_area() * left_n as f32 + right_area[k] * right_n[k] as f32;
        if best.is_none_or(|(c, _)| cost < c) {
            best = Some((cost, k));
        }
    }
    best.map(|(_, bin)| Plane {
        bins: B,
        axis,
        bin,
        lo,
        scale,
    })
}

fn partition_seq(refs: &mut [Ref], left: &(impl Fn(&Ref) -> bool + Sync)) -> usize {
    let (mut i, mut j) = (0, refs.len());
    while i < j {
        if left(&refs[i]) {
            i += 1;
        } else {
            j -= 1;
            refs.swap(i, j);
        }
    }
    i
}

struct SharedRefs(*mut Ref);
// SAFETY: the tasks given this pointer write disjoint ranges.
unsafe impl Send for SharedRefs {}
unsafe impl Sync for SharedRefs {}

/// Partitions `refs` so that those `left` says go first; returns their
/// count. Big ranges: each chunk is partitioned on its own, then the right
/// parts inside the final left part are swapped, run by run, with the left
/// parts beyond it (the same result for any number of threads).
fn partition(refs: &mut [Ref], left: &(impl Fn(&Ref) -> bool + Sync)) -> usize {
    let n = refs.len();
    if n < PAR_PASS {
        return partition_seq(refs, left);
    }
    let lefts: Vec<usize> = refs
        .par_chunks_mut(CHUNK)
        .map(|c| partition_seq(c, left))
        .collect();
    let m: usize = lefts.iter().sum();
    // Misplaced runs: rights below m, lefts at or above m.
    let (mut a, mut b) = (Vec::new(), Vec::new());
    for (i, &l) in lefts.iter().enumerate() {
        let s = i * CHUNK;
        let e = (s + CHUNK).min(n);
        if s + l < e.min(m) {
            a.push((s + l, e.min(m)));
        }
        if s.max(m) < s + l {
            b.push((s.max(m), s + l));
        }
    }
    // Pair them up in pieces of at most CHUNK.
    let mut swaps = Vec::new();
    let (mut ia, mut ib) = (0, 0);
    let (mut pa, mut pb) = (a.first().map_or(0, |r| r.0), b.first().map_or(0, |r| r.0));
    while ia < a.len() && ib < b.len() {
        let len = (a[ia].1 - pa).min(b[ib].1 - pb).min(CHUNK);
        swaps.push((pa, pb, len));
        pa += len;
        pb += len;
        if pa == a[ia].1 {
            ia += 1;
            pa = a.get(ia).map_or(0, |r| r.0);
        }
        if pb == b[ib].1 {
            ib += 1;
            pb = b.get(ib).map_or(0, |r| r.0);
        }
    }
    debug_assert!(ia == a.len() && ib == b.len());
    let base = SharedRefs(refs.as_mut_ptr());
    swaps.par_iter().for_each(|&(x, y, len)| {
        let base = &base;
        // SAFETY: [x, x + len) lies below m and [y, y + len) at or above
        // it, inside `refs`; the pieces are disjoint.
        unsafe { std::ptr::swap_nonoverlapping(base.0.add(x), base.0.add(y), len) };
    });
    m
}

/// Short ranges of triangles: the cheapest split by the surface area
/// heuristic among those that leave whole leaves on the left (sorted by
/// centroid along each axis in turn), so that leaves come out full.
fn split_packed(refs: &mut [Ref]) -> usize {
    let n = refs.len();
    let key = |a: &Ref, b: &Ref, axis: usize| {
        a.centroid2()[axis]
            .total_cmp(&b.centroid2()[axis])
            .then(a.prim().cmp(&b.prim()))
    };
    let mut best = (f32::INFINITY, 0usize, LEAF_SIZE);
    for axis in 0..3 {
        refs.sort_unstable_by(|a, b| key(a, b, axis));
        let mut right = [0.0f32; 4 * LEAF_SIZE + 1];
        let mut acc = Box4::EMPTY;
        for k in (1..n).rev() {
            acc.grow(refs[k].lo, refs[k].hi);
            right[k] = acc.half_area();
        }
        let mut left = Box4::EMPTY;
        for (k, r) in refs.iter().enumerate().take(n - 1) {
            left.grow(r.lo, r.hi);
            let m = k + 1;
            if m % LEAF_SIZE == 0 {
                let cost = left.half_area() * m as f32 + right[m] * (n - m) as f32;
                if cost < best.0 {
                    best = (cost, axis, m);
                }
            }
        }
    }
    refs.sort_unstable_by(|a, b| key(a, b, best.1));
    best.2
}

/// Splits `range` in two (it holds at least two references).
fn split(refs: &mut [Ref], range: &Range, depth: usize, sah_depth: usize) -> (Range, Range) {
    let ext = (range.cent.hi - range.cent.lo).truncate();
    let has_extent = ext.max_element() > 0.0;
    let mut mid = None;
    let len = range.len();
    if len > LEAF_SIZE && len <= 4 * LEAF_SIZE && range.weight == len as u64 {
        mid = Some(split_packed(&mut refs[range.start..range.end]));
    } else if has_extent && depth < sah_depth {
        if let Some(p) = sah_plane(refs, range) {
            let m = partition(&mut refs[range.start..range.end], &|r: &Ref| p.left(r));
            if m > 0 && m < range.len() {
                mid = Some(m);
            }
        }
    }
    let mid = mid.unwrap_or_else(|| {
        // Coincident centroids: the middle by position; too deep: the
        // median of the widest centroid axis.
        let m = range.len() / 2;
        if has_extent {
            let axis = ext.max_position();
            refs[range.start..range.end].select_nth_unstable_by(m, |a, b| {
                a.centroid2()[axis]
                    .total_cmp(&b.centroid2()[axis])
                    .then(a.prim().cmp(&b.prim()))
            });
        }
        m
    });
    let (l, r) = refs[range.start..range.end].split_at(mid);
    if range.len() >= PAR_PASS {
        rayon::join(
            || range_of(l, range.start),
            || range_of(r, range.start + mid),
        )
    } else {
        (range_of(l, range.start), range_of(r, range.start + mid))
    }
}

/// A subtree under construction: its nodes (the root first; inner children
/// local to this array, `SUB | k` for the root of `subs[k]`, leaf children
/// `LEAF | first << 2 | count - 1` with `first` absolute), the subtrees
/// built as tasks of their own, and its depth. [`flatten`] joins them.
struct Subtree {
    nodes: Vec<Node>,
    subs: Vec<Subtree>,
    depth: usize,
}

/// Marks a child that is the root of another [`Subtree`].
const SUB: u32 = 1 << 30;

/// A leaf child over `r` (whose start is relative to `base`).
fn leaf_ref(r: &Range, base: usize) -> u32 {
    debug_assert!((1..=LEAF_SIZE).contains(&r.len()));
    LEAF | ((base + r.start) as u32) << 2 | (r.len() as u32 - 1)
}

/// The (at most four) children of a node over `range`: its widest part
/// split again while it is heavier than a leaf.
fn children(refs: &mut [Ref], range: Range, depth: usize, sah_depth: usize) -> Kids {
    let mut kids = Kids::new();
    kids.push(range);
    while kids.len() < 4 {
        let widest = kids
            .iter()
            .enumerate()
            .filter(|(_, k)| k.weight > LEAF_SIZE as u64 && k.len() > 1)
            .max_by(|(i, a), (j, b)| {
                a.bounds
                    .half_area()
                    .total_cmp(&b.bounds.half_area())
                    .then(j.cmp(i))
            })
            .map(|(i, _)| i);
        let Some(i) = widest else { break };
        let (l, r) = split(refs, &kids[i], depth, sah_depth);
        kids[i] = l;
        kids.insert(i + 1, r);
    }
    kids
}

type Kids = arrayvec::ArrayVec<Range, 4>;

fn is_leaf(r: &Range) -> bool {
    r.weight <= LEAF_SIZE as u64 || r.len() == 1
}

fn make_node(kids: &[Range], child: [u32; 4]) -> Node {
    let mut node = super::bvh4::empty_node();
    node.valid = BVec4A::new(true, kids.len() > 1, kids.len() > 2, kids.len() > 3);
    for (slot, k) in kids.iter().enumerate() {
        for axis in 0..3 {
            node.b[axis][slot] = k.bounds.lo[axis];
            node.b[3 + axis][slot] = k.bounds.hi[axis];
        }
    }
    node.child = child;
    node
}

/// Builds the subtree of `range` (heavier than a leaf; `refs[0]` is
/// reference `base`) sequentially, appending its nodes to `out`; returns
/// its root's index and its depth.
fn build_seq(
    refs: &mut [Ref],
    base: usize,
    range: Range,
    depth: usize,
    sah_depth: usize,
    out: &mut Vec<Node>,
) -> (u32, usize) {
    let kids = children(refs, range, depth, sah_depth);
    let at = out.len();
    out.push(super::bvh4::empty_node());
    let mut child = [u32::MAX; 4];
    let mut deepest = depth;
    for (slot, k) in kids.iter().enumerate() {
        child[slot] = if is_leaf(k) {
            leaf_ref(k, base)
        } else {
            let (c, d) = build_seq(refs, base, *k, depth + 1, sah_depth, out);
            deepest = deepest.max(d);
            c
        };
    }
    out[at] = make_node(&kids, child);
    (at as u32, deepest)
}

/// Builds the subtree over all of `refs` (reference `base` first; heavier
/// than a leaf), big children as parallel tasks.
fn build_par(
    refs: &mut [Ref],
    base: usize,
    range: Range,
    depth: usize,
    sah_depth: usize,
) -> Subtree {
    debug_assert!(range.start == 0 && range.end == refs.len());
    if range.len() < PAR_TREE {
        // About one node per 7.6 triangles in practice: reserve a little
        // more, so that the array is not regrown (fresh pages are costly).
        let mut nodes = Vec::with_capacity(range.len() / 6 + 8);
        let (_, d) = build_seq(refs, base, range, depth, sah_depth, &mut nodes);
        return Subtree {
            nodes,
            subs: Vec::new(),
            depth: d,
        };
    }
    let kids = children(refs, range, depth, sah_depth);
    // Each child gets its own part of the references (disjoint, in order).
    let mut parts: Vec<(&mut [Ref], Range)> = Vec::with_capacity(kids.len());
    let mut rest = &mut refs[..];
    let mut at = 0;
    for k in &kids {
        let (head, tail) = rest.split_at_mut(k.end - at);
        parts.push((head, *k));
        rest = tail;
        at = k.end;
    }
    let subs: Vec<Option<Subtree>> = parts
        .into_par_iter()
        .map(|(part, k)| {
            let local = Range {
                start: 0,
                end: k.len(),
                ..k
            };
            (!is_leaf(&k)).then(|| build_par(part, base + k.start, local, depth + 1, sah_depth))
        })
        .collect();
    let mut child = [u32::MAX; 4];
    let mut deepest = depth;
    let mut kept = Vec::new();
    for (slot, (k, sub)) in kids.iter().zip(subs).enumerate() {
        child[slot] = match sub {
            None => leaf_ref(k, base),
            Some(s) => {
                deepest = deepest.max(s.depth);
                kept.push(s);
                SUB | (kept.len() - 1) as u32
            }
        };
    }
    Subtree {
        nodes: vec![make_node(&kids, child)],
        subs: kept,
        depth: deepest,
    }
}

/// The subtrees joined into one node array, in pre-order (the root first),
/// copied in parallel with their child references made global.
fn flatten(root: Subtree) -> Vec<Node> {
    // Pre-order list of the subtrees, each with its first node and the
    // list positions of its own subtrees.
    let mut list: Vec<(&Subtree, usize, Vec<usize>)> = Vec::new();
    let mut stack = vec![(&root, usize::MAX)];
    let mut total = 0usize;
    while let Some((t, parent)) = stack.pop() {
        let me = list.len();
        if parent != usize::MAX {
            list[parent].2.push(me);
        }
        list.push((t, total, Vec::new()));
        total += t.nodes.len();
        // Reversed, so that subs[0] comes out first (its index in the
        // parent's list is then its slot number).
        for s in t.subs.iter().rev() {
            stack.push((s, me));
        }
    }
    // (A subtree's own subtrees are popped in order, each after the whole
    // of the one before it, so `list[i].2[k]` is the position of subs[k].)
    let mut out = vec![super::bvh4::empty_node(); total];
    let mut slices = Vec::with_capacity(list.len());
    let mut rest = &mut out[..];
    for (t, _, _) in &list {
        let (head, tail) = rest.split_at_mut(t.nodes.len());
        slices.push(head);
        rest = tail;
    }
    let firsts: Vec<usize> = list.iter().map(|l| l.1).collect();
    slices
        .into_par_iter()
        .zip(list.par_iter())
        .for_each(|(dst, (t, first, subs))| {
            for (d, n) in dst.iter_mut().zip(&t.nodes) {
                *d = *n;
                for c in &mut d.child {
                    if *c == u32::MAX || *c & LEAF != 0 {
                        continue;
                    }
                    *c = if *c & SUB != 0 {
                        firsts[subs[(*c & !SUB) as usize]] as u32
                    } else {
                        *c + *first as u32
                    };
                }
            }
        });
    out
}

/// Hands the heap's free pages back to the system. The subtrees' small
/// node arrays come from malloc's heap, and once joined their pages would
/// stay resident under the leaves allocated next (about 20 bytes per
/// triangle of peak memory).
fn release_free_heap() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        extern "C" {
            fn malloc_trim(pad: usize) -> std::ffi::c_int;
        }
        // SAFETY: glibc's malloc_trim has no preconditions.
        unsafe {
            malloc_trim(0);
        }
    }
}

/// The built tree: four-wide nodes (the root first), the leaves, the
/// primitives in BVH order and the depth.
pub(super) struct Built {
    pub nodes: Vec<Node>,
    pub leaves: Vec<Leaf>,
    pub order: Vec<u32>,
    pub depth: usize,
    pub bounds: (Vec3, Vec3),
}

/// Builds over `refs` (not empty; at most 2^29); `triangle(i)` gives
/// primitive `i`'s vertices if it is a triangle. The references are freed
/// before the leaves are made.
pub(super) fn build(
    mut refs: Vec<Ref>,
    triangle: impl Fn(usize) -> Option<[Vec3; 3]> + Sync,
) -> Built {
    let n = refs.len();
    assert!(n > 0 && n < 1 << 29);
    let root = range_of(&refs, 0);
    let sah_depth = 2 * (usize::BITS - n.leading_zeros()) as usize + 16;
    let (tree, depth) = if is_leaf(&root) {
        let mut child = [u32::MAX; 4];
        child[0] = leaf_ref(&root, 0);
        let nodes = vec![make_node(&[root], child)];
        let tree = Subtree {
            nodes,
            subs: Vec::new(),
            depth: 1,
        };
        (tree, 1)
    } else {
        let s = build_par(&mut refs, 0, root, 1, sah_depth);
        let depth = s.depth;
        (s, depth)
    };
    let order: Vec<u32> = refs.par_iter().map(Ref::prim).collect();
    drop(refs);
    let nodes = flatten(tree);
    release_free_heap();
    // Leaves in node order, numbered by a prefix count.
    let mut nodes = nodes;
    let mut next = 0u32;
    let mut spans = Vec::new();
    for n in &mut nodes {
        for c in &mut n.child {
            if *c != u32::MAX && *c & LEAF != 0 {
                let first = (*c & !LEAF) >> 2;
                let count = (*c & 3) + 1;
                spans.push((first, count));
                *c = LEAF | next;
                next += 1;
            }
        }
    }
    let leaves: Vec<Leaf> = spans
        .par_iter()
        .map(|&(first, count)| super::bvh4::make_leaf(&order, first, count, &triangle))
        .collect();
    Built {
        nodes,
        leaves,
        order,
        depth,
        bounds: (root.bounds.lo.truncate(), root.bounds.hi.truncate()),
    }
}
