//! directlighting's strategy "all" in four SIMD lanes: pbrt-v3's
//! UniformSampleAllLights with one sample per light, for scenes whose lights
//! are all triangles of constant normal, at Lambertian vertices. Each
//! light's EstimateDirect (a light sample and a BSDF sample weighted by the
//! power heuristic) is computed four lanes at a time: triangle sampling, the
//! solid-angle densities, the BSDF values, the cosine-weighted directions
//! and the BSDF rays' tests against the lights' triangles. Then the lanes'
//! shadow rays are traced side by side ([`crate::accel::Aggregate::occluded_stream`]),
//! and the BSDF rays that can still reach the light one by one.
//!
//! The lanes are either four lights at one vertex
//! ([`sample_all_lights_packed`], for one sample at a time) or one light at
//! four vertices ([`sample_all_lights_lanes`], for the camera vertices of a
//! batch of samples: with fewer than four lights, lights in lanes leave
//! lanes idle). Both run [`estimate4`] on a [`Vertex4`] and a
//! [`TriangleLightPack`]: a vertex splatted into lanes with a pack of four
//! lights, or four vertices with a pack of one light repeated.
//!
//! [`DirectLanes`] holds a batch's Lambertian camera vertices and their
//! samples between the two passes.
//!
//! Every operation is the scalar path's (`estimate_direct` with
//! `TriangleCache::sample_li`, `Bsdf::f_pdf`, `Bsdf::sample` and
//! `TriangleCache::hit_pdf`), in the same order, so the image is the same
//! bit for bit; tests render both ways and compare.

use super::common::light_along;
use super::Scratch;
use crate::accel::SurfaceHit;
use crate::geometry::{offset_ray_origin, spawn_ray_from_to, Ray};
use crate::integrators::RenderScene;
use crate::lights::{dot3, lane3, splat3, TriangleLightPack, Vec3x4};
use crate::materials::Bsdf;
use crate::samplers::Sampler;
use crate::sampling::{power_heuristic, sin_cos_quarter};
use arrayvec::ArrayVec;
use glam::{BVec4A, Vec2, Vec3, Vec4};
use std::f32::consts::{FRAC_1_PI, FRAC_PI_4};

/// directlighting's Lambertian camera vertices of a batch (see
/// [`super::directlighting`]'s `li_batch`): the batch lane of each, the vertex, its
/// emission, its light and BSDF samples for every light, and the sums of
/// the light estimates. Grown to the batch's need on the first batch.
#[derive(Default)]
pub(super) struct DirectLanes {
    pub(super) lanes: Vec<u32>,
    pub(super) verts: Vec<LambertVertex>,
    pub(super) emitted: Vec<Vec3>,
    pub(super) u: Vec<Vec2>,
    pub(super) sums: Vec<Vec3>,
}

impl DirectLanes {
    /// Bytes held (after a batch has grown them).
    pub(super) fn bytes(&self) -> usize {
        use std::mem::size_of;
        self.lanes.capacity() * size_of::<u32>()
            + self.verts.capacity() * size_of::<LambertVertex>()
            + (self.emitted.capacity() + self.sums.capacity()) * size_of::<Vec3>()
            + self.u.capacity() * size_of::<Vec2>()
    }

    pub(super) fn clear(&mut self) {
        self.lanes.clear();
        self.verts.clear();
        self.emitted.clear();
        self.u.clear();
        self.sums.clear();
    }
}

/// A Lambertian vertex, as the estimate reads it.
#[derive(Clone, Copy, Debug)]
pub(super) struct LambertVertex {
    p: Vec3,
    /// The geometric normal of the surface point (ray offsets).
    n: Vec3,
    /// The shading normal (cosines).
    ns: Vec3,
    /// The BSDF's geometric normal (reflection against transmission).
    ng: Vec3,
    /// The BSDF's frame.
    s: Vec3,
    t: Vec3,
    fz: Vec3,
    /// `wo` in the frame (its z) and against `ng`.
    wo_z: f32,
    wo_ng: f32,
    /// The two origins offset_ray_origin can give here: pushed along +n
    /// or along -n.
    o_up: Vec3,
    o_down: Vec3,
    /// The Lambertian's value, reflectance / π.
    f: Vec3,
    time: f32,
}

impl LambertVertex {
    /// The vertex at `s`, whose BSDF is the Lambertian of reflectance `r`.
    #[inline]
    pub(super) fn new(s: &SurfaceHit, bsdf: &Bsdf, r: Vec3, wo: Vec3) -> LambertVertex {
        let sp = &s.point;
        LambertVertex {
            p: sp.p,
            n: sp.n,
            ns: sp.ns,
            ng: bsdf.ng,
            s: bsdf.frame.s,
            t: bsdf.frame.t,
            fz: bsdf.frame.n,
            wo_z: bsdf.frame.to_local(wo).z,
            wo_ng: wo.dot(bsdf.ng),
            o_up: offset_ray_origin(sp.p, sp.p_error, sp.n, sp.n),
            o_down: offset_ray_origin(sp.p, sp.p_error, sp.n, -sp.n),
            f: r * FRAC_1_PI,
            time: s.time,
        }
    }
}

/// Four lanes of vertices (one vertex splatted, or four).
struct Vertex4 {
    p: Vec3x4,
    n: Vec3x4,
    ns: Vec3x4,
    ng: Vec3x4,
    s: Vec3x4,
    t: Vec3x4,
    fz: Vec3x4,
    o_up: Vec3x4,
    o_down: Vec3x4,
    wo_z: Vec4,
    wo_ng: Vec4,
}

impl Vertex4 {
    #[inline(always)]
    fn splat(v: &LambertVertex) -> Vertex4 {
        Vertex4 {
            p: splat3(v.p),
            n: splat3(v.n),
            ns: splat3(v.ns),
            ng: splat3(v.ng),
            s: splat3(v.s),
            t: splat3(v.t),
            fz: splat3(v.fz),
            o_up: splat3(v.o_up),
            o_down: splat3(v.o_down),
            wo_z: Vec4::splat(v.wo_z),
            wo_ng: Vec4::splat(v.wo_ng),
        }
    }

    /// Lane `i` from `vs[i]` (lanes past `vs.len()` repeat its first).
    #[inline(always)]
    fn gather(vs: &[LambertVertex]) -> Vertex4 {
        let at = |i: usize| &vs[if i < vs.len() { i } else { 0 }];
        let g3 = |f: fn(&LambertVertex) -> Vec3| -> Vec3x4 {
            let v = [f(at(0)), f(at(1)), f(at(2)), f(at(3))];
            [
                Vec4::new(v[0].x, v[1].x, v[2].x, v[3].x),
                Vec4::new(v[0].y, v[1].y, v[2].y, v[3].y),
                Vec4::new(v[0].z, v[1].z, v[2].z, v[3].z),
            ]
        };
        let g1 = |f: fn(&LambertVertex) -> f32| Vec4::new(f(at(0)), f(at(1)), f(at(2)), f(at(3)));
        Vertex4 {
            p: g3(|v| v.p),
            n: g3(|v| v.n),
            ns: g3(|v| v.ns),
            ng: g3(|v| v.ng),
            s: g3(|v| v.s),
            t: g3(|v| v.t),
            fz: g3(|v| v.fz),
            o_up: g3(|v| v.o_up),
            o_down: g3(|v| v.o_down),
            wo_z: g1(|v| v.wo_z),
            wo_ng: g1(|v| v.wo_ng),
        }
    }
}

/// Both strategies' values in four lanes, and the lanes that still
/// contribute (`try_l`, `try_b`: bit masks).
struct Estimate4 {
    try_l: u32,
    /// Lanes whose shadow ray leaves by the -n side.
    down_l: u32,
    q: Vec3x4,
    q_error: Vec3x4,
    pdf_l: [f32; 4],
    abs_cos_l: [f32; 4],
    scatter_pdf_l: [f32; 4],
    try_b: u32,
    wi_b: Vec3x4,
    o_b: Vec3x4,
    pdf_b: [f32; 4],
    abs_cos_b: [f32; 4],
    light_pdf_b: [f32; 4],
}

/// EstimateDirect's arithmetic for lane `i`'s light of `pack` at lane
/// `i`'s vertex of `v`, with light samples `ul` and BSDF samples `us`, in
/// the lanes of `active`.
#[inline(always)]
fn estimate4(
    pack: &TriangleLightPack,
    v: &Vertex4,
    ul: [Vec4; 2],
    us: [Vec4; 2],
    active: BVec4A,
) -> Estimate4 {
    // Bsdf::f_pdf and Bsdf::sample: nothing when wo is in the tangent plane.
    let active = active & v.wo_z.cmpne(Vec4::ZERO);

    // Light strategy (light_strategy with pmf 1).
    let ls = pack.sample_li(&v.p, ul);
    let cos_l = dot3(&ls.wi, &v.ns);
    let reflect_l = (dot3(&ls.wi, &v.ng) * v.wo_ng).cmpgt(Vec4::ZERO);
    let same_side_l = (v.wo_z * cos_l).cmpgt(Vec4::ZERO);
    let scatter_pdf_l = Vec4::select(
        same_side_l,
        cos_l.abs() * Vec4::splat(FRAC_1_PI),
        Vec4::ZERO,
    );
    let abs_cos_l = cos_l.abs();
    // f · |cos| is zero where the BSDF is (not reflecting) or cos is.
    let try_l = active & ls.lit & reflect_l & abs_cos_l.cmpne(Vec4::ZERO);
    // The shadow rays' near ends: spawn_ray_to's offset towards q.
    let down_l = dot3(&ls.d, &v.n).cmplt(Vec4::ZERO).bitmask();

    // BSDF strategy (Bsdf::sample of the Lambertian lobe).
    let disk = concentric_sample_disk4(us);
    let z = (Vec4::ONE - disk[0] * disk[0] - disk[1] * disk[1])
        .max(Vec4::ZERO)
        .sqrt();
    let z = Vec4::select(v.wo_z.cmplt(Vec4::ZERO), -z, z);
    let same_side_b = (v.wo_z * z).cmpgt(Vec4::ZERO);
    let pdf_b = Vec4::select(same_side_b, z.abs() * Vec4::splat(FRAC_1_PI), Vec4::ZERO);
    let wi_b: Vec3x4 = std::array::from_fn(|a| v.s[a] * disk[0] + v.t[a] * disk[1] + v.fz[a] * z);
    let reflect_b = (dot3(&wi_b, &v.ng) * v.wo_ng).cmpgt(Vec4::ZERO);
    let abs_cos_b = dot3(&wi_b, &v.ns).abs();
    let down = dot3(&wi_b, &v.n).cmplt(Vec4::ZERO);
    let o_b: Vec3x4 = std::array::from_fn(|a| Vec4::select(down, v.o_down[a], v.o_up[a]));
    let light_pdf_b = pack.hit_pdf(&o_b, &wi_b);
    let try_b = active
        & pdf_b.cmpgt(Vec4::ZERO)
        & reflect_b
        & abs_cos_b.cmpne(Vec4::ZERO)
        & light_pdf_b.cmpgt(Vec4::ZERO);

    Estimate4 {
        try_l: try_l.bitmask(),
        down_l,
        q: ls.q,
        q_error: ls.q_error,
        pdf_l: ls.pdf.to_array(),
        abs_cos_l: abs_cos_l.to_array(),
        scatter_pdf_l: scatter_pdf_l.to_array(),
        try_b: try_b.bitmask(),
        wi_b,
        o_b,
        pdf_b: pdf_b.to_array(),
        abs_cos_b: abs_cos_b.to_array(),
        light_pdf_b: light_pdf_b.to_array(),
    }
}

/// The shadow ray of lane `lane` of `e` at vertex `v`, if it is traced
/// (the light sample has a value).
#[inline(always)]
fn lane_shadow(
    e: &Estimate4,
    lane: usize,
    pack: &TriangleLightPack,
    v: &LambertVertex,
) -> Option<Ray> {
    let bit = 1 << lane;
    if e.try_l & bit == 0 || v.f * e.abs_cos_l[lane] == Vec3::ZERO {
        return None;
    }
    let pf = if e.down_l & bit != 0 {
        v.o_down
    } else {
        v.o_up
    };
    Some(spawn_ray_from_to(
        pf,
        lane3(&e.q, lane),
        lane3(&e.q_error, lane),
        lane3(&pack.n, lane),
    ))
}

/// The lanes of `e` whose shadow rays (at the vertex `v(lane)`) nothing
/// blocks, as bits: the rays traced side by side, and counted.
#[inline(always)]
fn open_lanes<'v>(
    scene: &RenderScene,
    e: &Estimate4,
    pack: &TriangleLightPack,
    v: impl Fn(usize) -> &'v LambertVertex,
    scratch: &mut Scratch,
) -> u32 {
    let mut rays = [Ray::new(Vec3::ZERO, Vec3::Z); 4];
    let mut times = [0f32; 4];
    let mut lanes = [0usize; 4];
    let mut n = 0;
    for lane in 0..4 {
        if let Some(r) = lane_shadow(e, lane, pack, v(lane)) {
            rays[n] = r;
            times[n] = v(lane).time;
            lanes[n] = lane;
            n += 1;
        }
    }
    scratch.counts.shadow += n as u64;
    let mut blocked = [false; 4];
    scene
        .aggregate
        .occluded_stream(&rays[..n], &times[..n], &mut blocked[..n]);
    let mut open = 0;
    for (&lane, &b) in lanes[..n].iter().zip(&blocked[..n]) {
        open |= u32::from(!b) << lane;
    }
    open
}

/// Lane `lane` of `e` finished at vertex `v`: its BSDF ray traced, the
/// light's contribution (EstimateDirect's `Ld`), the light sample counted
/// if its shadow ray is `open` (see [`open_lanes`]). The light is
/// `light_index`, lane `lane` of `pack`.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn lane_ld(
    scene: &RenderScene,
    e: &Estimate4,
    lane: usize,
    light_index: u32,
    pack: &TriangleLightPack,
    v: &LambertVertex,
    open: u32,
    scratch: &mut Scratch,
) -> Vec3 {
    let bit = 1 << lane;
    let mut ld = Vec3::ZERO;
    if open & bit != 0 {
        let f = v.f * e.abs_cos_l[lane];
        let li = lane3(&pack.l, lane);
        let light_pdf = 1.0 * e.pdf_l[lane];
        ld = f * li * power_heuristic(1, light_pdf, 1, e.scatter_pdf_l[lane]) / light_pdf;
    }
    if e.try_b & bit != 0 {
        let f = v.f * e.abs_cos_b[lane];
        if f != Vec3::ZERO {
            let wi = lane3(&e.wi_b, lane);
            let weight = power_heuristic(1, e.pdf_b[lane], 1, e.light_pdf_b[lane]);
            let ray = Ray::new(lane3(&e.o_b, lane), wi);
            let li = light_along(scene, &ray, wi, v.time, light_index, scratch);
            ld += f * li * weight / e.pdf_b[lane];
        }
    }
    ld
}

/// The samples of `count` lights as `sample_all_lights` draws them (per
/// light: the two one-entry arrays, or two 2D samples when there are no
/// arrays left), light by light: light sample, then BSDF sample.
#[inline]
pub(super) fn draw_samples(sampler: &mut Sampler, count: usize) -> ArrayVec<Vec2, 8> {
    let mut both = [Vec2::ZERO; 8];
    draw_samples_into(sampler, &mut both[..2 * count]);
    both[..2 * count].iter().copied().collect()
}

/// [`draw_samples`] into `out`, whose length is twice the light count.
#[inline]
pub(super) fn draw_samples_into(sampler: &mut Sampler, out: &mut [Vec2]) {
    if sampler.get_2d_arrays1(out) {
        return;
    }
    for pair in out.chunks_exact_mut(2) {
        let got_light = sampler.get_2d_array1();
        let got_scatter = sampler.get_2d_array1();
        let (a, b) = match (got_light, got_scatter) {
            (Some(a), Some(b)) => (a, b),
            _ => (sampler.get_2d(), sampler.get_2d()),
        };
        pair[0] = a;
        pair[1] = b;
    }
}

/// The sum over all lights of EstimateDirect at `s`, whose BSDF is the
/// Lambertian of reflectance `r`: four lights at a time.
#[allow(clippy::too_many_arguments)]
pub(super) fn sample_all_lights_packed(
    scene: &RenderScene,
    s: &SurfaceHit,
    bsdf: &Bsdf,
    r: Vec3,
    wo: Vec3,
    sampler: &mut Sampler,
    scratch: &mut Scratch,
    packs: &[TriangleLightPack],
) -> Vec3 {
    let v = LambertVertex::new(s, bsdf, r, wo);
    let v4 = Vertex4::splat(&v);
    let mut l = Vec3::ZERO;
    for (k, pack) in packs.iter().enumerate() {
        let u = draw_samples(sampler, pack.count);
        let lanes = |k: usize| x4(|i| u.get(2 * i + k).copied().unwrap_or_default());
        let e = estimate4(pack, &v4, lanes(0), lanes(1), first_lanes(pack.count));
        let open = open_lanes(scene, &e, pack, |_| &v, scratch);
        for lane in 0..pack.count {
            l += lane_ld(
                scene,
                &e,
                lane,
                (4 * k + lane) as u32,
                pack,
                &v,
                open,
                scratch,
            );
        }
    }
    l
}

/// [`sample_all_lights_packed`] at each of `verts`, four vertices at a
/// time, into `out` (one sum per vertex). `u` holds each vertex's samples
/// as [`draw_samples`] gives them for all lights (2 per light, vertex after
/// vertex); `lights[i]` is light `i` in every lane.
pub(super) fn sample_all_lights_lanes(
    scene: &RenderScene,
    verts: &[LambertVertex],
    u: &[Vec2],
    lights: &[TriangleLightPack],
    out: &mut [Vec3],
    scratch: &mut Scratch,
) {
    let stride = 2 * lights.len();
    for (g, group) in verts.chunks(4).enumerate() {
        let v4 = Vertex4::gather(group);
        let n = group.len();
        let active = first_lanes(n);
        let first = 4 * g;
        for (i, light) in lights.iter().enumerate() {
            let lanes = |k: usize| x4(|lane| u[(first + lane.min(n - 1)) * stride + 2 * i + k]);
            let e = estimate4(light, &v4, lanes(0), lanes(1), active);
            let open = open_lanes(scene, &e, light, |lane| &group[lane.min(n - 1)], scratch);
            for (lane, v) in group.iter().enumerate() {
                out[first + lane] += lane_ld(scene, &e, lane, i as u32, light, v, open, scratch);
            }
        }
    }
}

/// Four 2D samples in lanes: lane `i` is `at(i)`.
#[inline(always)]
fn x4(at: impl Fn(usize) -> Vec2) -> [Vec4; 2] {
    let v = [at(0), at(1), at(2), at(3)];
    [
        Vec4::new(v[0].x, v[1].x, v[2].x, v[3].x),
        Vec4::new(v[0].y, v[1].y, v[2].y, v[3].y),
    ]
}

/// The first `n` of four lanes.
#[inline(always)]
fn first_lanes(n: usize) -> BVec4A {
    BVec4A::new(n > 0, n > 1, n > 2, n > 3)
}

/// `concentric_sample_disk` in four lanes, both of its cases computed and
/// selected (the same operations per lane).
#[inline(always)]
fn concentric_sample_disk4(u: [Vec4; 2]) -> [Vec4; 2] {
    let ox = Vec4::splat(2.0) * u[0] - Vec4::ONE;
    let oy = Vec4::splat(2.0) * u[1] - Vec4::ONE;
    let x_major = ox.abs().cmpgt(oy.abs());
    let num = Vec4::select(x_major, oy, ox);
    let den = Vec4::select(x_major, ox, oy);
    let (s, c) = sin_cos_quarter(Vec4::splat(FRAC_PI_4) * (num / den));
    let zero = ox.cmpeq(Vec4::ZERO) & oy.cmpeq(Vec4::ZERO);
    [
        Vec4::select(zero, Vec4::ZERO, den * Vec4::select(x_major, c, s)),
        Vec4::select(zero, Vec4::ZERO, den * Vec4::select(x_major, s, c)),
    ]
}
