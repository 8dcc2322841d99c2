//! A BVH over the lights (Conty Estevez and Kulla 2018, "Importance
//! Sampling of Many Lights with Adaptive Tree Splitting"; as pbrt-v4's
//! BVHLightSampler): each node bounds its lights' positions, emission
//! directions (a cone) and power, and a light is chosen by walking down from
//! the root, taking each child with probability proportional to an
//! importance that accounts for the distance and orientation of the node's
//! bounds to the shading point and its normal. The probability of any light
//! is the product of the choices on its path, found in O(depth) from the bit
//! trail stored per light, so MIS weights are exact.
//!
//! Lights with no bounds (distant and infinite) are chosen as pbrt-v4 does:
//! uniformly with probability `n_infinite / (n_infinite + 1)`, the BVH the
//! rest of the time. Point and spot lights are in the tree (a point with a
//! sphere or cone of directions).

use super::Light;
use crate::accel::Aggregate;
use crate::geometry::Bounds3;
use crate::sampling::ONE_MINUS_EPSILON;
use glam::Vec3;
use std::f32::consts::PI;

/// Bounds of one light or of a node's lights: where (`bounds`), which way
/// (the cone around `w` of half-angle acos(`cos_theta_o`) holds every
/// emitting normal, and emission spreads a further acos(`cos_theta_e`)
/// beyond it), and how much (`phi`, luminance of power).
#[derive(Clone, Copy, Debug)]
pub struct LightBounds {
    pub bounds: Bounds3,
    pub w: Vec3,
    pub phi: f32,
    pub cos_theta_o: f32,
    pub cos_theta_e: f32,
    pub two_sided: bool,
}

#[inline]
fn safe_sqrt(x: f32) -> f32 {
    x.max(0.0).sqrt()
}

#[inline]
pub(super) fn safe_acos(x: f32) -> f32 {
    x.clamp(-1.0, 1.0).acos()
}

/// cos(max(0, a - b)) from the sines and cosines of a and b.
#[inline]
fn cos_sub_clamped(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> f32 {
    if cos_a > cos_b {
        1.0
    } else {
        cos_a * cos_b + sin_a * sin_b
    }
}

/// sin(max(0, a - b)) from the sines and cosines of a and b.
#[inline]
fn sin_sub_clamped(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> f32 {
    if cos_a > cos_b {
        0.0
    } else {
        sin_a * cos_b - cos_a * sin_b
    }
}

impl LightBounds {
    /// pbrt-v4's LightBounds::Importance: an estimate of the light's
    /// contribution at `p` (normal `n`, zero in a medium), conservative in
    /// angle (zero only where no light in the bounds can reach `p`).
    #[inline]
    pub fn importance(&self, p: Vec3, n: Vec3) -> f32 {
        let pc = self.bounds.center();
        let diag = self.bounds.diagonal().length();
        let d2 = p.distance_squared(pc).max(diag * 0.5);
        let wi = (p - pc).normalize_or_zero();
        let mut cos_theta_w = self.w.dot(wi);
        if self.two_sided {
            cos_theta_w = cos_theta_w.abs();
        }
        let sin_theta_w = safe_sqrt(1.0 - cos_theta_w * cos_theta_w);
        // The cone of directions from p that the bounds subtend.
        let (_, r) = self.bounds.bounding_sphere();
        let dc2 = p.distance_squared(pc);
        let cos_theta_b = if dc2 < r * r {
            -1.0
        } else {
            safe_sqrt(1.0 - r * r / dc2)
        };
        let sin_theta_b = safe_sqrt(1.0 - cos_theta_b * cos_theta_b);
        let sin_theta_o = safe_sqrt(1.0 - self.cos_theta_o * self.cos_theta_o);
        let cos_theta_x = cos_sub_clamped(sin_theta_w, cos_theta_w, sin_theta_o, self.cos_theta_o);
        let sin_theta_x = sin_sub_clamped(sin_theta_w, cos_theta_w, sin_theta_o, self.cos_theta_o);
        let cos_theta_p = cos_sub_clamped(sin_theta_x, cos_theta_x, sin_theta_b, cos_theta_b);
        if cos_theta_p <= self.cos_theta_e {
            return 0.0;
        }
        let mut importance = self.phi * cos_theta_p / d2;
        if n != Vec3::ZERO {
            let cos_theta_i = wi.dot(n).abs();
            let sin_theta_i = safe_sqrt(1.0 - cos_theta_i * cos_theta_i);
            importance *= cos_sub_clamped(sin_theta_i, cos_theta_i, sin_theta_b, cos_theta_b);
        }
        if importance.is_finite() {
            importance.max(0.0)
        } else {
            0.0
        }
    }

    pub fn union(&self, b: &LightBounds) -> LightBounds {
        if self.phi == 0.0 {
            return *b;
        }
        if b.phi == 0.0 {
            return *self;
        }
        let (w, cos_theta_o) = cone_union(self.w, self.cos_theta_o, b.w, b.cos_theta_o);
        LightBounds {
            bounds: self.bounds.union(&b.bounds),
            w,
            phi: self.phi + b.phi,
            cos_theta_o,
            cos_theta_e: self.cos_theta_e.min(b.cos_theta_e),
            two_sided: self.two_sided | b.two_sided,
        }
    }

    fn centroid(&self) -> Vec3 {
        self.bounds.center()
    }
}

/// pbrt-v4's Union of two direction cones.
fn cone_union(wa: Vec3, cos_a: f32, wb: Vec3, cos_b: f32) -> (Vec3, f32) {
    let theta_a = safe_acos(cos_a);
    let theta_b = safe_acos(cos_b);
    let theta_d = safe_acos(wa.dot(wb));
    if (theta_d + theta_b).min(PI) <= theta_a {
        return (wa, cos_a);
    }
    if (theta_d + theta_a).min(PI) <= theta_b {
        return (wb, cos_b);
    }
    let theta_o = (theta_a + theta_d + theta_b) / 2.0;
    if theta_o >= PI {
        return (Vec3::Z, -1.0);
    }
    let theta_r = theta_o - theta_a;
    let wr = wa.cross(wb);
    if wr.length_squared() == 0.0 {
        return (Vec3::Z, -1.0);
    }
    let k = wr.normalize();
    // Rodrigues' rotation of wa about k (k ⟂ wa).
    let w = wa * theta_r.cos() + k.cross(wa) * theta_r.sin();
    (w.normalize(), theta_o.cos())
}

/// The bounds of a light (each kind's [`LightModel::bounds`](super::LightModel::bounds)),
/// None for lights at infinity (distant, infinite) and lights that emit
/// nothing.
pub fn light_bounds(light: &Light, geom: &Aggregate) -> Option<LightBounds> {
    let b = light.bounds(geom)?;
    if !(b.phi > 0.0 && b.phi.is_finite()) {
        return None;
    }
    (b.bounds.min.is_finite() && b.bounds.max.is_finite()).then_some(b)
}

#[derive(Clone, Copy, Debug)]
struct Node {
    lb: LightBounds,
    /// Leaf: the light (scene index). Interior: the second child (the
    /// first is the next node).
    index: u32,
    leaf: bool,
}

/// The light BVH and the lights outside it.
pub struct LightBvh {
    nodes: Vec<Node>,
    /// Scene indices of lights at infinity.
    infinite: Vec<u32>,
    /// Per scene light: its bit trail (bit `d` is the choice at depth `d`,
    /// 1 for the second child), u64::MAX if it is not in the tree.
    trail: Vec<u64>,
    /// Per scene light: it is one of `infinite`.
    is_infinite: Vec<bool>,
    pub max_depth: usize,
}

/// Depth from which the build splits at the median count, so that no bit
/// trail exceeds 64 choices: 30 + log2(2^32) < 64.
const SAH_MAX_DEPTH: usize = 30;
const BUCKETS: usize = 12;

impl LightBvh {
    /// Builds over the scene lights listed in `active` (those that emit).
    pub fn new(active: &[u32], lights: &[Light], geom: &Aggregate) -> LightBvh {
        let mut infinite = Vec::new();
        let mut is_infinite = vec![false; lights.len()];
        let mut items: Vec<(u32, LightBounds)> = Vec::new();
        for &i in active {
            match light_bounds(&lights[i as usize], geom) {
                Some(b) => items.push((i, b)),
                None => {
                    if lights[i as usize].at_infinity() {
                        infinite.push(i);
                        is_infinite[i as usize] = true;
                    }
                }
            }
        }
        let mut bvh = LightBvh {
            nodes: Vec::with_capacity(items.len().saturating_mul(2)),
            infinite,
            trail: vec![u64::MAX; lights.len()],
            is_infinite,
            max_depth: 0,
        };
        if !items.is_empty() {
            let n = items.len();
            bvh.build(&mut items, 0, n, 0, 0);
        }
        bvh
    }

    /// pbrt-v4's buildBVH, iterative over an explicit stack would need the
    /// node bounds afterwards; recursion depth is at most 64.
    fn build(
        &mut self,
        items: &mut [(u32, LightBounds)],
        start: usize,
        end: usize,
        trail: u64,
        depth: usize,
    ) -> LightBounds {
        self.max_depth = self.max_depth.max(depth);
        if end - start == 1 {
            let (light, lb) = items[start];
            self.nodes.push(Node {
                lb,
                index: light,
                leaf: true,
            });
            self.trail[light as usize] = trail;
            return lb;
        }
        let range = &mut items[start..end];
        let mut bounds = Bounds3::EMPTY;
        let mut cb = Bounds3::EMPTY;
        for (_, lb) in range.iter() {
            bounds = bounds.union(&lb.bounds);
            cb = cb.union_point(lb.centroid());
        }
        let mut mid = None;
        if depth < SAH_MAX_DEPTH {
            mid = sah_split(range, &bounds, &cb);
        }
        let mid = mid.unwrap_or_else(|| {
            let m = range.len() / 2;
            let axis = cb.diagonal().max_position();
            range.select_nth_unstable_by(m, |a, b| {
                a.1.centroid()[axis].total_cmp(&b.1.centroid()[axis])
            });
            m
        });
        let node = self.nodes.len();
        self.nodes.push(Node {
            lb: items[start].1,
            index: 0,
            leaf: false,
        });
        let a = self.build(items, start, start + mid, trail, depth + 1);
        self.nodes[node].index = self.nodes.len() as u32;
        let b = self.build(items, start + mid, end, trail | (1u64 << depth), depth + 1);
        let lb = a.union(&b);
        self.nodes[node].lb = lb;
        lb
    }

    pub fn infinite_count(&self) -> usize {
        self.infinite.len()
    }

    pub fn tree_lights(&self) -> usize {
        self.nodes.len().div_ceil(2)
    }

    fn p_infinite(&self) -> f32 {
        let ni = self.infinite.len() as f32;
        let tree = if self.nodes.is_empty() { 0.0 } else { 1.0 };
        if ni + tree == 0.0 {
            0.0
        } else {
            ni / (ni + tree)
        }
    }

    /// Chooses a light for a point `p` with normal `n` (zero in a medium):
    /// (scene light index, probability).
    #[inline]
    pub fn sample(&self, p: Vec3, n: Vec3, u: f32) -> Option<(u32, f32)> {
        let p_inf = self.p_infinite();
        if u < p_inf {
            let ni = self.infinite.len();
            let i = ((u / p_inf * ni as f32) as usize).min(ni - 1);
            return Some((self.infinite[i], p_inf / ni as f32));
        }
        if self.nodes.is_empty() {
            return None;
        }
        let mut u = ((u - p_inf) / (1.0 - p_inf)).min(ONE_MINUS_EPSILON);
        let mut pmf = 1.0 - p_inf;
        let mut node = 0usize;
        loop {
            let nd = &self.nodes[node];
            if nd.leaf {
                if node > 0 || nd.lb.importance(p, n) > 0.0 {
                    return (pmf > 0.0).then_some((nd.index, pmf));
                }
                return None;
            }
            let (c0, c1) = (node + 1, nd.index as usize);
            let i0 = self.nodes[c0].lb.importance(p, n);
            let i1 = self.nodes[c1].lb.importance(p, n);
            if i0 == 0.0 && i1 == 0.0 {
                return None;
            }
            let p0 = i0 / (i0 + i1);
            if u < p0 {
                u = (u / p0).min(ONE_MINUS_EPSILON);
                pmf *= p0;
                node = c0;
            } else {
                u = ((u - p0) / (1.0 - p0)).min(ONE_MINUS_EPSILON);
                pmf *= 1.0 - p0;
                node = c1;
            }
        }
    }

    /// Probability that `sample(p, n, ·)` chooses scene light `light`.
    #[inline]
    pub fn pmf(&self, p: Vec3, n: Vec3, light: u32) -> f32 {
        let l = light as usize;
        if l >= self.trail.len() {
            return 0.0;
        }
        if self.is_infinite[l] {
            return self.p_infinite() / self.infinite.len() as f32;
        }
        let mut trail = self.trail[l];
        if trail == u64::MAX || self.nodes.is_empty() {
            return 0.0;
        }
        let mut pmf = 1.0 - self.p_infinite();
        let mut node = 0usize;
        loop {
            let nd = &self.nodes[node];
            if nd.leaf {
                if node == 0 && nd.lb.importance(p, n) == 0.0 {
                    return 0.0;
                }
                return pmf;
            }
            let (c0, c1) = (node + 1, nd.index as usize);
            let i0 = self.nodes[c0].lb.importance(p, n);
            let i1 = self.nodes[c1].lb.importance(p, n);
            let total = i0 + i1;
            if total == 0.0 {
                return 0.0;
            }
            if trail & 1 == 0 {
                pmf *= i0 / total;
                node = c0;
            } else {
                pmf *= i1 / total;
                node = c1;
            }
            trail >>= 1;
        }
    }

    /// The importance of the whole tree at `p` (for the spatial fallback's
    /// notes and tests).
    pub fn root_importance(&self, p: Vec3, n: Vec3) -> f32 {
        self.nodes.first().map_or(0.0, |r| r.lb.importance(p, n))
    }
}

/// pbrt-v4's EvaluateCost of a candidate child.
fn cost(b: &LightBounds, bounds: &Bounds3, dim: usize) -> f32 {
    let theta_o = safe_acos(b.cos_theta_o);
    let theta_e = safe_acos(b.cos_theta_e);
    let theta_w = (theta_o + theta_e).min(PI);
    let sin_theta_o = safe_sqrt(1.0 - b.cos_theta_o * b.cos_theta_o);
    let m_omega = 2.0 * PI * (1.0 - b.cos_theta_o)
        + PI / 2.0
            * (2.0 * theta_w * sin_theta_o
                - (theta_o - 2.0 * theta_w).cos()
                - 2.0 * theta_o * sin_theta_o
                + b.cos_theta_o);
    let d = bounds.diagonal();
    let kr = if d[dim] > 0.0 {
        d.max_element() / d[dim]
    } else {
        1.0
    };
    let db = b.bounds.diagonal();
    let area = 2.0 * (db.x * db.y + db.x * db.z + db.y * db.z);
    b.phi * m_omega * kr * area
}

/// pbrt-v4's bucketed split: 12 buckets per axis of the centroid bounds,
/// the split of least `cost`; None if the centroids coincide or no split
/// separates anything.
fn sah_split(range: &mut [(u32, LightBounds)], bounds: &Bounds3, cb: &Bounds3) -> Option<usize> {
    let d = cb.diagonal();
    let mut best = (f32::INFINITY, 0usize, 0usize);
    for dim in 0..3 {
        if d[dim] <= 0.0 || d[dim].is_nan() {
            continue;
        }
        let bucket = |c: Vec3| {
            (((c[dim] - cb.min[dim]) / d[dim] * BUCKETS as f32) as usize).min(BUCKETS - 1)
        };
        let mut buckets: [Option<LightBounds>; BUCKETS] = [None; BUCKETS];
        for (_, lb) in range.iter() {
            let b = bucket(lb.centroid());
            buckets[b] = Some(match buckets[b] {
                Some(x) => x.union(lb),
                None => *lb,
            });
        }
        // Bounds of buckets 0..=i and i+1.., by one sweep each way.
        let join = |a: Option<LightBounds>, b: &Option<LightBounds>| match (a, b) {
            (Some(a), Some(b)) => Some(a.union(b)),
            (a, None) => a,
            (None, b) => *b,
        };
        let mut below = [None; BUCKETS];
        let mut acc = None;
        for i in 0..BUCKETS {
            acc = join(acc, &buckets[i]);
            below[i] = acc;
        }
        let mut acc = None;
        for i in (1..BUCKETS).rev() {
            acc = join(acc, &buckets[i]);
            if let (Some(a), Some(b)) = (below[i - 1], acc) {
                let c = cost(&a, bounds, dim) + cost(&b, bounds, dim);
                if c > 0.0 && c < best.0 {
                    best = (c, dim, i - 1);
                }
            }
        }
    }
    if !best.0.is_finite() {
        return None;
    }
    let (_, dim, split) = best;
    let lo = cb.min[dim];
    let bucket = |c: Vec3| (((c[dim] - lo) / d[dim] * BUCKETS as f32) as usize).min(BUCKETS - 1);
    let mut i = 0;
    let mut j = range.len();
    while i < j {
        if bucket(range[i].1.centroid()) <= split {
            i += 1;
        } else {
            j -= 1;
            range.swap(i, j);
        }
    }
    (i > 0 && i < range.len()).then_some(i)
}
