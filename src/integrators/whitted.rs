//! `whitted`: pbrt-v3's WhittedIntegrator, every light sampled once at
//! every vertex of the specular tree ([`super::specular`]), no MIS.
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `maxdepth` | integer | 5 | maximum depth of the specular tree (≥ 0) |
//! | `pixelbounds` | | | ignored, with a warning |

use super::batch::{trace_camera_rays, Batch};
use super::specular::{tree_lanes, tree_li, SpecularTree};
use super::{Integrate, IntegratorKind, IntegratorSettings, Scratch, MAX_DEPTH, PIXEL_BOUNDS};
use crate::accel::SurfaceHit;
use crate::geometry::{Ray, RayDiff};
use crate::materials::{Bsdf, BxdfFlags};
use crate::samplers::Sampler;
use crate::integrators::RenderScene;
use crate::scene::kind::{Report, Support};
use crate::scene::{ParamSpec, ParamValues};
use glam::Vec3;

pub const PARAMS: &[ParamSpec] = &[MAX_DEPTH, PIXEL_BOUNDS];

pub const KIND: IntegratorKind = IntegratorKind {
    name: "whitted",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "Whitted ray tracing: every light sampled once at every vertex, no MIS, specular reflection and transmission followed recursively",
    build: |p, r| IntegratorSettings::Whitted(WhittedSettings::read(p, r)),
};

/// whitted ignores participating media and subsurface scattering (as
/// pbrt-v3's).
pub const RENDERS_MEDIA: bool = false;
pub const SAMPLES_SUBSURFACE: bool = false;

/// `whitted`'s settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WhittedSettings {
    pub max_depth: u32,
}

impl Default for WhittedSettings {
    fn default() -> WhittedSettings {
        WhittedSettings { max_depth: 5 }
    }
}

impl WhittedSettings {
    /// The settings of a statement's parameters, checked as pbrt-v3 does.
    pub fn read(p: &ParamValues, r: &mut dyn Report) -> WhittedSettings {
        WhittedSettings {
            max_depth: super::max_depth(p, r),
        }
    }

    pub fn summary(&self) -> String {
        format!("maxdepth {}", self.max_depth)
    }
}

/// The runtime `whitted`: its settings.
pub struct Whitted {
    settings: WhittedSettings,
}

impl Whitted {
    pub fn new(settings: &WhittedSettings, _scene: &RenderScene, _scalar: bool) -> Whitted {
        Whitted {
            settings: *settings,
        }
    }
}

impl Integrate for Whitted {
    #[inline]
    fn li(
        &self,
        ray: Ray,
        time: f32,
        diff: Option<RayDiff>,
        scene: &RenderScene,
        sampler: &mut Sampler,
        scratch: &mut Scratch,
    ) -> Vec3 {
        tree_li(self, ray, time, diff, scene, sampler, scratch)
    }

    /// The camera rays first, then the specular tree lane by lane.
    fn li_batch(&self, b: &mut Batch, scene: &RenderScene, scratch: &mut Scratch) {
        trace_camera_rays(b, scene);
        tree_lanes(self, b, scene, scratch);
    }
}

impl SpecularTree for Whitted {
    fn max_depth(&self) -> u32 {
        self.settings.max_depth
    }

    /// Adds to `local` the light of every light at `s`: one sample each, its
    /// shadow ray traced, no MIS.
    #[inline(always)]
    fn add_direct(
        &self,
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
            let Some(ls) = light.sample_li(&s.point, u, &scene.aggregate) else {
                continue;
            };
            if ls.li == Vec3::ZERO || ls.pdf == 0.0 {
                continue;
            }
            let f = bsdf.f(wo, ls.wi, BxdfFlags::ALL);
            if f != Vec3::ZERO {
                scratch.counts.shadow += 1;
                if !scene.aggregate.occluded_at(&ls.shadow, s.time) {
                    *local += f * ls.li * ls.wi.dot(s.point.ns).abs() / ls.pdf;
                }
            }
        }
    }
}
