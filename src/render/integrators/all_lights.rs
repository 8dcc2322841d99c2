//! directlighting's strategy "all" four lights at a time: pbrt-v3's
//! UniformSampleAllLights with one sample per light, for scenes whose lights
//! are all triangles of constant normal, at Lambertian vertices. Each light's
//! EstimateDirect (a light sample and a BSDF sample weighted by the power
//! heuristic) is computed in four SIMD lanes, one light a lane: triangle
//! sampling, the solid-angle densities, the BSDF values, the cosine-weighted
//! directions and the BSDF rays' tests against the lights' triangles. Rays
//! are then traced one by one, for the lanes that still contribute.
//!
//! Every operation is the scalar path's (`estimate_direct` with
//! `TriangleCache::sample_li`, `Bsdf::f_pdf`, `Bsdf::sample` and
//! `TriangleCache::hit_pdf`), in the same order, so the image is the same
//! bit for bit; a test renders both ways and compares.

use super::Scratch;
use crate::render::accel::SurfaceHit;
use crate::render::geometry::{offset_ray_origin, spawn_ray_from_to, Ray};
use crate::render::lights::{dot3, lane3, splat3, TriangleLightPack, Vec3x4};
use crate::render::materials::Bsdf;
use crate::render::samplers::Sampler;
use crate::render::sampling::{power_heuristic, sin_cos_quarter};
use crate::render::scene::RenderScene;
use glam::{BVec4A, Vec2, Vec3, Vec4};
use std::f32::consts::{FRAC_1_PI, FRAC_PI_4};

/// The sum over all lights of EstimateDirect at `s`, whose BSDF is the
/// Lambertian of reflectance `r`; the samples are drawn as
/// `sample_all_lights` draws them (per light: the two one-entry arrays, or
/// two 2D samples when there are no arrays left).
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
    let sp = &s.point;
    let frame = &bsdf.frame;
    // Bsdf::f_pdf and Bsdf::sample: nothing when wo is in the tangent plane.
    let wo_z = frame.to_local(wo).z;
    let wo_ng = wo.dot(bsdf.ng);
    let f_lambert = r * FRAC_1_PI;
    // The two origins offset_ray_origin can give at this point: pushed
    // along +n or along -n.
    let o_up = offset_ray_origin(sp.p, sp.p_error, sp.n, sp.n);
    let o_down = offset_ray_origin(sp.p, sp.p_error, sp.n, -sp.n);
    let n3 = splat3(sp.n);
    let ns3 = splat3(sp.ns);
    let ng3 = splat3(bsdf.ng);
    let mut l = Vec3::ZERO;
    for (k, pack) in packs.iter().enumerate() {
        // The samples, light by light in pbrt-v3's order.
        let mut ul = [Vec2::ZERO; 4];
        let mut us = [Vec2::ZERO; 4];
        let mut both = [Vec2::ZERO; 8];
        if sampler.get_2d_arrays1(&mut both[..2 * pack.count]) {
            for lane in 0..pack.count {
                ul[lane] = both[2 * lane];
                us[lane] = both[2 * lane + 1];
            }
        } else {
            for lane in 0..pack.count {
                let got_light = sampler.get_2d_array1();
                let got_scatter = sampler.get_2d_array1();
                if let (Some(a), Some(b)) = (got_light, got_scatter) {
                    ul[lane] = a;
                    us[lane] = b;
                } else {
                    ul[lane] = sampler.get_2d();
                    us[lane] = sampler.get_2d();
                }
            }
        }
        if wo_z == 0.0 {
            continue;
        }
        let active = BVec4A::new(
            pack.count > 0,
            pack.count > 1,
            pack.count > 2,
            pack.count > 3,
        );
        let x4 = |v: &[Vec2; 4]| {
            [
                Vec4::new(v[0].x, v[1].x, v[2].x, v[3].x),
                Vec4::new(v[0].y, v[1].y, v[2].y, v[3].y),
            ]
        };

        // Light strategy (light_strategy with pmf 1).
        let ls = pack.sample_li(sp.p, x4(&ul));
        let cos_l = dot3(&ls.wi, &ns3);
        let reflect_l = (dot3(&ls.wi, &ng3) * Vec4::splat(wo_ng)).cmpgt(Vec4::ZERO);
        let same_side_l = (Vec4::splat(wo_z) * cos_l).cmpgt(Vec4::ZERO);
        let scatter_pdf_l = Vec4::select(
            same_side_l,
            cos_l.abs() * Vec4::splat(FRAC_1_PI),
            Vec4::ZERO,
        );
        let abs_cos_l = cos_l.abs();
        // f · |cos| is zero where the BSDF is (not reflecting) or cos is.
        let try_l = active & ls.lit & reflect_l & abs_cos_l.cmpne(Vec4::ZERO);
        // The shadow rays' near ends: spawn_ray_to's offset towards q.
        let down_l = dot3(&ls.d, &n3).cmplt(Vec4::ZERO).bitmask();

        // BSDF strategy (Bsdf::sample of the Lambertian lobe).
        let u = x4(&us);
        let disk = concentric_sample_disk4(u);
        let z = (Vec4::ONE - disk[0] * disk[0] - disk[1] * disk[1])
            .max(Vec4::ZERO)
            .sqrt();
        let z = if wo_z < 0.0 { -z } else { z };
        let same_side_b = (Vec4::splat(wo_z) * z).cmpgt(Vec4::ZERO);
        let pdf_b = Vec4::select(same_side_b, z.abs() * Vec4::splat(FRAC_1_PI), Vec4::ZERO);
        let wi_b: Vec3x4 = std::array::from_fn(|a| {
            Vec4::splat(frame.s[a]) * disk[0]
                + Vec4::splat(frame.t[a]) * disk[1]
                + Vec4::splat(frame.n[a]) * z
        });
        let reflect_b = (dot3(&wi_b, &ng3) * Vec4::splat(wo_ng)).cmpgt(Vec4::ZERO);
        let abs_cos_b = dot3(&wi_b, &ns3).abs();
        let down = dot3(&wi_b, &n3).cmplt(Vec4::ZERO);
        let o_b: Vec3x4 = std::array::from_fn(|a| {
            Vec4::select(down, Vec4::splat(o_down[a]), Vec4::splat(o_up[a]))
        });
        let light_pdf_b = pack.hit_pdf(&o_b, &wi_b);
        let try_b = active
            & pdf_b.cmpgt(Vec4::ZERO)
            & reflect_b
            & abs_cos_b.cmpne(Vec4::ZERO)
            & light_pdf_b.cmpgt(Vec4::ZERO);

        let (pdf_l, abs_cos_l, scatter_pdf_l) = (
            ls.pdf.to_array(),
            abs_cos_l.to_array(),
            scatter_pdf_l.to_array(),
        );
        let (pdf_b, abs_cos_b, light_pdf_b) = (
            pdf_b.to_array(),
            abs_cos_b.to_array(),
            light_pdf_b.to_array(),
        );
        let (mask_l, mask_b) = (try_l.bitmask(), try_b.bitmask());
        for lane in 0..pack.count {
            let light_index = (4 * k + lane) as u32;
            let mut ld = Vec3::ZERO;
            if mask_l & (1 << lane) != 0 {
                let f = f_lambert * abs_cos_l[lane];
                if f != Vec3::ZERO {
                    scratch.counts.shadow += 1;
                    let pf = if down_l & (1 << lane) != 0 {
                        o_down
                    } else {
                        o_up
                    };
                    let shadow = spawn_ray_from_to(
                        pf,
                        lane3(&ls.q, lane),
                        lane3(&ls.q_error, lane),
                        lane3(&pack.n, lane),
                    );
                    if !scene.geometry.occluded_at(&shadow, s.time) {
                        let li = lane3(&pack.l, lane);
                        let light_pdf = 1.0 * pdf_l[lane];
                        ld = f * li * power_heuristic(1, light_pdf, 1, scatter_pdf_l[lane])
                            / light_pdf;
                    }
                }
            }
            if mask_b & (1 << lane) != 0 {
                let f = f_lambert * abs_cos_b[lane];
                if f != Vec3::ZERO {
                    let wi = lane3(&wi_b, lane);
                    let weight = power_heuristic(1, pdf_b[lane], 1, light_pdf_b[lane]);
                    scratch.counts.closest += 1;
                    let ray = Ray::new(lane3(&o_b, lane), wi);
                    let li = match scene.geometry.intersect_at(&ray, s.time) {
                        Some(h) => {
                            let hs = scene.geometry.surface_at(&h, s.time);
                            if hs.light == Some(light_index) {
                                scene.lights[light_index as usize].emitted(hs.point.n, -wi)
                            } else {
                                Vec3::ZERO
                            }
                        }
                        None => scene.lights[light_index as usize].le(wi),
                    };
                    ld += f * li * weight / pdf_b[lane];
                }
            }
            l += ld;
        }
    }
    l
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
