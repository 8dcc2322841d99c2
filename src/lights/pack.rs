//! Triangle area lights four to a pack, in structure-of-arrays form, so
//! that directlighting's strategy "all" samples four lights in one pass of
//! four-lane arithmetic (`integrators::direct_lanes`). Lane `i` of pack `k` is
//! light `4k + i`; a pack's unused lanes repeat its first light and are
//! masked off by `count`.

use super::diffuse::HIT_SLACK;
use super::{AreaShape, DiffuseLight, Light};
use crate::geometry::gamma;
use glam::{BVec4A, Vec3, Vec4};

/// Three four-lane vectors: x, y and z of four points or directions.
pub type Vec3x4 = [Vec4; 3];

#[inline(always)]
pub fn dot3(a: &Vec3x4, b: &Vec3x4) -> Vec4 {
    // The order of `Vec3::dot`: (x·x + y·y) + z·z.
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline(always)]
pub fn splat3(v: Vec3) -> Vec3x4 {
    [Vec4::splat(v.x), Vec4::splat(v.y), Vec4::splat(v.z)]
}

/// Lane `i` of `v`. Read through the lanes' arrays: glam's `Vec4` index
/// is a `match` on the lane, compiled as a jump table whose indirect jump
/// is mispredicted almost every time.
#[inline(always)]
pub fn lane3(v: &Vec3x4, i: usize) -> Vec3 {
    Vec3::new(lane(&v[0], i), lane(&v[1], i), lane(&v[2], i))
}

/// Lane `i` of `v`, without a jump table (see [`lane3`]).
#[inline(always)]
pub fn lane(v: &Vec4, i: usize) -> f32 {
    let a: &[f32; 4] = v.as_ref();
    a[i]
}

/// Four triangle lights of constant normal.
#[derive(Clone, Copy, Debug)]
pub struct TriangleLightPack {
    /// Lanes in use (1 ..= 4).
    pub count: usize,
    /// `p[k]` is vertex `k` of each lane's triangle.
    pub p: [Vec3x4; 3],
    pub n: Vec3x4,
    pub plane: Vec3x4,
    pub bary: [Vec3x4; 2],
    pub area: Vec4,
    pub l: Vec3x4,
    pub two_sided: BVec4A,
    /// Lanes whose radiance is not black.
    pub emits: BVec4A,
}

/// Packs `lights` if every one is a triangle light with a constant normal
/// (the case `TriangleCache::sample_li` handles); None otherwise.
pub fn pack_triangle_lights(lights: &[Light]) -> Option<Vec<TriangleLightPack>> {
    if lights.is_empty() {
        return None;
    }
    let mut packs = Vec::with_capacity(lights.len().div_ceil(4));
    for chunk in lights.chunks(4) {
        let mut lanes = Vec::with_capacity(4);
        for light in chunk {
            match *light {
                Light::Diffuse(DiffuseLight {
                    shape: AreaShape::Triangle { .. },
                    l,
                    two_sided,
                    area,
                    tri,
                    ..
                }) if tri.n != Vec3::ZERO => lanes.push((tri, l, two_sided, area)),
                _ => return None,
            }
        }
        let get = |i: usize| lanes[i.min(lanes.len() - 1)];
        let mask = |f: &dyn Fn(usize) -> bool| BVec4A::new(f(0), f(1), f(2), f(3));
        let gather = |f: &dyn Fn(usize) -> Vec3| -> Vec3x4 {
            let v: [Vec3; 4] = std::array::from_fn(f);
            [
                Vec4::new(v[0].x, v[1].x, v[2].x, v[3].x),
                Vec4::new(v[0].y, v[1].y, v[2].y, v[3].y),
                Vec4::new(v[0].z, v[1].z, v[2].z, v[3].z),
            ]
        };
        packs.push(TriangleLightPack {
            count: lanes.len(),
            p: std::array::from_fn(|k| gather(&|i| get(i).0.p[k])),
            n: gather(&|i| get(i).0.n),
            plane: gather(&|i| get(i).0.plane),
            bary: std::array::from_fn(|k| gather(&|i| get(i).0.bary[k])),
            area: Vec4::from_array(std::array::from_fn(|i| get(i).3)),
            l: gather(&|i| get(i).1),
            two_sided: mask(&|i| get(i).2),
            emits: mask(&|i| get(i).1 != Vec3::ZERO),
        });
    }
    Some(packs)
}

/// What `TriangleCache::sample_li` gives, lane by lane: the point, its error
/// bound, the unit direction, the solid-angle density, and the lanes whose
/// sample is usable and faces the reference point (or the light is
/// two-sided), i.e. whose `li` is the light's radiance rather than zero.
pub struct PackLightSample {
    pub q: Vec3x4,
    pub q_error: Vec3x4,
    /// `q - p`, the unnormalised direction.
    pub d: Vec3x4,
    pub wi: Vec3x4,
    pub pdf: Vec4,
    pub lit: BVec4A,
}

impl TriangleLightPack {
    /// The pack of light `lane` in all four lanes (to sample one light
    /// from four points at once).
    pub fn uniform(&self, lane: usize) -> TriangleLightPack {
        let one = |v: &Vec3x4| splat3(lane3(v, lane));
        TriangleLightPack {
            count: 4,
            p: [one(&self.p[0]), one(&self.p[1]), one(&self.p[2])],
            n: one(&self.n),
            plane: one(&self.plane),
            bary: [one(&self.bary[0]), one(&self.bary[1])],
            area: Vec4::splat(self::lane(&self.area, lane)),
            l: one(&self.l),
            two_sided: BVec4A::splat(self.two_sided.test(lane)),
            emits: BVec4A::splat(self.emits.test(lane)),
        }
    }

    /// `TriangleCache::sample_li` for the four lanes (lane `i` from point
    /// `p` lane `i`), operation for operation (the same values bit for
    /// bit).
    #[inline(always)]
    pub fn sample_li(&self, p: &Vec3x4, u: [Vec4; 2]) -> PackLightSample {
        // uniform_sample_triangle and sample_triangle_point.
        let su0 = u[0].sqrt();
        let b0 = Vec4::ONE - su0;
        let b1 = u[1] * su0;
        let b2 = Vec4::ONE - b0 - b1;
        let g6 = Vec4::splat(gamma(6));
        let q: Vec3x4 =
            std::array::from_fn(|a| b0 * self.p[0][a] + b1 * self.p[1][a] + b2 * self.p[2][a]);
        let q_error: Vec3x4 = std::array::from_fn(|a| {
            g6 * ((b0 * self.p[0][a]).abs() + (b1 * self.p[1][a]).abs() + (b2 * self.p[2][a]).abs())
        });
        let d: Vec3x4 = std::array::from_fn(|a| q[a] - p[a]);
        let dist2 = dot3(&d, &d);
        let dist = dist2.sqrt();
        let inv = Vec4::ONE / dist;
        let wi: Vec3x4 = std::array::from_fn(|a| d[a] * inv);
        let n_dot_d = dot3(&self.n, &d);
        let pdf = dist2 * dist / (n_dot_d.abs() * self.area);
        let ok = pdf.cmpgt(Vec4::ZERO) & pdf.cmplt(Vec4::INFINITY);
        let lit = ok & self.emits & (self.two_sided | n_dot_d.cmplt(Vec4::ZERO));
        PackLightSample {
            q,
            q_error,
            d,
            wi,
            pdf,
            lit,
        }
    }

    /// `TriangleCache::hit_pdf` for four rays from `o` (one origin a lane)
    /// with unit directions `d` and no distance bound, each against its
    /// lane's triangle, operation for operation.
    #[inline(always)]
    pub fn hit_pdf(&self, o: &Vec3x4, d: &Vec3x4) -> Vec4 {
        let inv = Vec4::ONE / dot3(&self.plane, d);
        let p0_o: Vec3x4 = std::array::from_fn(|a| self.p[0][a] - o[a]);
        let t = dot3(&self.plane, &p0_o) * inv;
        let q: Vec3x4 = std::array::from_fn(|a| (o[a] - self.p[0][a]) + t * d[a]);
        let b1 = dot3(&q, &self.bary[0]);
        let b2 = dot3(&q, &self.bary[1]);
        let pdf = Vec4::splat(2.0) * t * t * inv.abs();
        let slack = Vec4::splat(-HIT_SLACK);
        let hit = t.cmpgt(Vec4::ZERO)
            & t.cmplt(Vec4::INFINITY)
            & b1.cmpge(slack)
            & b2.cmpge(slack)
            & (b1 + b2).cmple(Vec4::splat(1.0 + HIT_SLACK))
            & pdf.cmplt(Vec4::INFINITY);
        Vec4::select(hit, pdf, Vec4::ZERO)
    }
}
