//! `whitted`: pbrt-v3's WhittedIntegrator, every light sampled once at
//! every vertex of the specular tree ([`super::specular`]), no MIS.

use super::Scratch;
use crate::render::accel::SurfaceHit;
use crate::render::materials::{Bsdf, BxdfFlags};
use crate::render::samplers::Sampler;
use crate::render::scene::RenderScene;
use glam::Vec3;

/// Adds to `local` the light of every light at `s`: one sample each, its
/// shadow ray traced, no MIS.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn add_direct(
    local: &mut Vec3,
    scene: &RenderScene,
    s: &SurfaceHit,
    bsdf: &Bsdf,
    wo: Vec3,
    sampler: &mut Sampler,
    scratch: &mut Scratch,
) {
    for light in &scene.lights {
        let u = sampler.get_2d();
        let Some(ls) = light.sample_li(&s.point, u, &scene.geometry) else {
            continue;
        };
        if ls.li == Vec3::ZERO || ls.pdf == 0.0 {
            continue;
        }
        let f = bsdf.f(wo, ls.wi, BxdfFlags::ALL);
        if f != Vec3::ZERO {
            scratch.counts.shadow += 1;
            if !scene.geometry.occluded_at(&ls.shadow, s.time) {
                *local += f * ls.li * ls.wi.dot(s.point.ns).abs() / ls.pdf;
            }
        }
    }
}
