//! Integrators, as pbrt-v3 defines them: `path` (next-event estimation with
//! power-heuristic MIS, Russian roulette), `volpath` (the same with
//! participating media, in [`volpath`]), `directlighting` (strategy all or
//! one, specular lobes followed recursively) and `whitted`.
//!
//! One file per integrator: [`path`], [`volpath`], [`directlighting`] and
//! [`whitted`]; the recursive specular tree that directlighting and
//! whitted share ([`specular`]); the batch of samples a thread renders
//! together ([`batch`]); directlighting's four-lane estimate
//! ([`direct_lanes`]); and what several of them share, written once
//! ([`common`]: shading, emission, light choice and sampling, MIS weights,
//! Russian roulette; [`subsurface`]: the BSSRDF exit of path and volpath).

use crate::render::geometry::{Ray, RayDiff};
use crate::render::lights::{
    pack_triangle_lights, LightSampler, LightSamplerKind, TriangleLightPack,
};
use crate::render::materials::Bsdf;
use crate::render::samplers::Sampler;
use crate::render::scene::RenderScene;
use crate::scene::{DirectStrategy, IntegratorDesc, LightSampleStrategy};
use glam::{Vec2, Vec3};

mod batch;
mod common;
mod direct_lanes;
mod directlighting;
mod path;
mod specular;
mod subsurface;
mod volpath;
mod whitted;

pub use batch::Batch;
use specular::{First, Work};

/// Rays traced, counted per tile and summed at the end (no shared counters).
#[derive(Clone, Copy, Debug, Default)]
pub struct RayCounts {
    /// Closest-hit rays (camera rays included).
    pub closest: u64,
    /// Occlusion (shadow) rays.
    pub shadow: u64,
}

impl RayCounts {
    pub fn add(&mut self, o: &RayCounts) {
        self.closest += o.closest;
        self.shadow += o.shadow;
    }
    pub fn total(&self) -> u64 {
        self.closest + self.shadow
    }
}

/// Per-tile scratch space, so the per-sample path never allocates.
#[derive(Default)]
pub struct Scratch {
    u_light: Vec<Vec2>,
    u_scatter: Vec<Vec2>,
    work: Vec<Work>,
    counts: RayCounts,
}

impl Scratch {
    pub fn counts(&self) -> RayCounts {
        self.counts
    }
}

/// Rays crossing more than this many `Material "none"` surfaces in a row stop.
const MAX_PASS_THROUGH: u32 = 256;

pub enum Integrator {
    Path {
        max_depth: u32,
        rr_threshold: f32,
        lights: LightSampler,
    },
    Direct {
        max_depth: u32,
        strategy: DirectStrategy,
        lights: LightSampler,
        n_light_samples: Vec<u32>,
        /// The lights four to a pack, for strategy "all" when every light is
        /// a triangle of constant normal with one sample (else empty).
        packs: Vec<TriangleLightPack>,
        /// Light `i` of `packs` in all four lanes, for the camera vertices
        /// of a batch (one light at four vertices).
        uniform: Vec<TriangleLightPack>,
    },
    Whitted {
        max_depth: u32,
    },
    VolPath {
        max_depth: u32,
        rr_threshold: f32,
        lights: LightSampler,
    },
}

/// The light distribution a `lightsamplestrategy` names.
fn light_sampler_kind(s: LightSampleStrategy) -> LightSamplerKind {
    match s {
        LightSampleStrategy::Uniform => LightSamplerKind::Uniform,
        LightSampleStrategy::Power => LightSamplerKind::Power,
        LightSampleStrategy::Spatial => LightSamplerKind::Spatial,
        LightSampleStrategy::Bvh => LightSamplerKind::Bvh,
    }
}

impl Integrator {
    /// Builds the integrator and only the light distribution it uses;
    /// `simd` allows the four-lane paths (which give the same image).
    pub fn new(desc: &IntegratorDesc, scene: &RenderScene, simd: bool) -> Integrator {
        match *desc {
            IntegratorDesc::Path {
                max_depth,
                rr_threshold,
                light_sample_strategy,
            } => {
                let kind = light_sampler_kind(light_sample_strategy);
                Integrator::Path {
                    max_depth,
                    rr_threshold,
                    lights: LightSampler::new(kind, &scene.lights, &scene.geometry),
                }
            }
            IntegratorDesc::DirectLighting {
                max_depth,
                strategy,
            } => Integrator::Direct {
                max_depth,
                strategy,
                // pbrt-v3's directlighting chooses uniformly for strategy "one".
                lights: LightSampler::new(
                    LightSamplerKind::Uniform,
                    &scene.lights,
                    &scene.geometry,
                ),
                n_light_samples: Vec::new(),
                packs: match strategy {
                    DirectStrategy::All if simd => {
                        pack_triangle_lights(&scene.lights).unwrap_or_default()
                    }
                    _ => Vec::new(),
                },
                uniform: Vec::new(),
            },
            IntegratorDesc::Whitted { max_depth } => Integrator::Whitted { max_depth },
            IntegratorDesc::VolPath {
                max_depth,
                rr_threshold,
                light_sample_strategy,
            } => {
                let kind = light_sampler_kind(light_sample_strategy);
                Integrator::VolPath {
                    max_depth,
                    rr_threshold,
                    lights: LightSampler::new(kind, &scene.lights, &scene.geometry),
                }
            }
        }
    }

    /// Requests the sampler arrays the integrator uses (pbrt-v3's Preprocess).
    pub fn prepare_sampler(&mut self, scene: &RenderScene, sampler: &mut Sampler) {
        if let Integrator::Direct {
            max_depth,
            strategy: DirectStrategy::All,
            n_light_samples,
            packs,
            uniform,
            ..
        } = self
        {
            *n_light_samples = scene
                .lights
                .iter()
                .map(|l| sampler.round_count(l.n_samples()))
                .collect();
            if n_light_samples.iter().any(|&n| n != 1) {
                packs.clear();
            }
            *uniform = packs
                .iter()
                .flat_map(|p| (0..p.count).map(|lane| p.uniform(lane)))
                .collect();
            for _ in 0..*max_depth {
                for &n in n_light_samples.iter() {
                    sampler.request_2d_array(n);
                    sampler.request_2d_array(n);
                }
            }
        }
    }

    /// What the integrator built beyond the light distribution.
    pub fn notes(&self) -> Vec<String> {
        match self {
            Integrator::Direct { packs, .. } if !packs.is_empty() => vec![format!(
                "directlighting \"all\": {} triangle lights in {} four-lane packs (Lambertian vertices sample four lights at once)",
                packs.iter().map(|p| p.count).sum::<usize>(),
                packs.len()
            )],
            _ => Vec::new(),
        }
    }

    pub fn light_sampler(&self) -> Option<&LightSampler> {
        match self {
            Integrator::Path { lights, .. }
            | Integrator::Direct { lights, .. }
            | Integrator::VolPath { lights, .. } => Some(lights),
            Integrator::Whitted { .. } => None,
        }
    }

    /// Radiance arriving at the camera along `ray` at scene time `time`
    /// (every ray of the path is traced at it), with its differentials if it
    /// has them.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub fn li(
        &self,
        ray: Ray,
        time: f32,
        diff: Option<RayDiff>,
        scene: &RenderScene,
        sampler: &mut Sampler,
        scratch: &mut Scratch,
    ) -> Vec3 {
        match self {
            Integrator::Path {
                max_depth,
                rr_threshold,
                lights,
            } => path::path_li(
                ray,
                time,
                diff,
                scene,
                sampler,
                scratch,
                *max_depth,
                *rr_threshold,
                lights,
            ),
            Integrator::VolPath {
                max_depth,
                rr_threshold,
                lights,
            } => volpath::volpath_li(
                ray,
                time,
                diff,
                scene,
                sampler,
                scratch,
                *max_depth,
                *rr_threshold,
                lights,
            ),
            Integrator::Direct { .. } | Integrator::Whitted { .. } => {
                let mut bsdf = Bsdf::empty();
                self.specular_tree_li(
                    ray,
                    First::Trace,
                    time,
                    diff,
                    scene,
                    sampler,
                    scratch,
                    &mut bsdf,
                )
            }
        }
    }
}
