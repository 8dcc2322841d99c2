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
//!
//! [`INTEGRATORS`] is the table of kinds the loader, `--check`,
//! `grammar/REFERENCE.md` and the tests read; a kind's builder gives its
//! settings (one struct per kind, [`IntegratorSettings`] the enum that only
//! delegates), which the scene description holds; [`Integrator::new`] makes
//! the runtime integrator from them.

use crate::geometry::{Ray, RayDiff};
use crate::lights::{pack_triangle_lights, LightSampler, LightSamplerKind, TriangleLightPack};
use crate::materials::Bsdf;
use crate::samplers::Sampler;
use crate::scene::kind::{Kind, Report, Support};
use crate::scene::{DirectStrategy, LightSampleStrategy, ParamSpec, ParamValues};
use glam::{Vec2, Vec3};

mod batch;
mod common;
mod direct_lanes;
mod directlighting;
mod path;
mod render_scene;
mod specular;
mod subsurface;
mod volpath;
mod whitted;

pub use batch::Batch;
pub use directlighting::DirectLightingSettings;
pub use path::PathSettings;
pub use render_scene::{RenderScene, SurfaceMedia};
use specular::{First, Work};
pub use volpath::VolPathSettings;
pub use whitted::WhittedSettings;

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

/// What an integrator kind builds from its parameters: its settings (the
/// builder reports pbrt-v3's checks of them).
pub type IntegratorBuild = fn(&ParamValues, &mut dyn Report) -> IntegratorSettings;

/// One integrator kind: its pbrt-v3 name, its parameters, its builder.
pub type IntegratorKind = Kind<IntegratorBuild>;

/// Every integrator pbrt-v3 knows: the four pbrs renders, then those it
/// substitutes by `path` (with the statement's `maxdepth`, and a warning).
pub static INTEGRATORS: &[IntegratorKind] = &[
    path::KIND,
    volpath::KIND,
    directlighting::KIND,
    whitted::KIND,
    unsupported("bdpt", "bidirectional path tracing is not implemented"),
    unsupported("mlt", "Metropolis light transport is not implemented"),
    unsupported(
        "sppm",
        "stochastic progressive photon mapping is not implemented",
    ),
    unsupported("ambientocclusion", "ambient occlusion is not implemented"),
];

/// `maxdepth`, which every integrator reads.
const MAX_DEPTH: ParamSpec = ParamSpec::int("maxdepth", 5, "maximum number of bounces (≥ 0)");

/// `pixelbounds`, which every integrator of pbrt-v3 reads and pbrs ignores.
const PIXEL_BOUNDS: ParamSpec = ParamSpec::unsupported(
    "pixelbounds",
    "\"pixelbounds\" is not supported by pbrs: the whole film is rendered (use --cropwindow)",
);

/// The parameters of the kinds pbrs substitutes by `path`.
const UNSUPPORTED_PARAMS: &[ParamSpec] = &[MAX_DEPTH, PIXEL_BOUNDS];

/// A kind pbrs does not render: `path` with the statement's `maxdepth`
/// (the loader says so).
const fn unsupported(name: &'static str, why: &'static str) -> IntegratorKind {
    IntegratorKind {
        name,
        aliases: &[],
        support: Support::Unsupported(why),
        params: UNSUPPORTED_PARAMS,
        doc: "substituted by `path` with the same `maxdepth`, with a warning",
        build: |p, r| {
            IntegratorSettings::Path(PathSettings {
                max_depth: max_depth(p, r),
                ..PathSettings::default()
            })
        },
    }
}

/// pbrt-v3's `maxdepth`, checked: a negative one is an error (and 5 is used).
fn max_depth(p: &ParamValues, r: &mut dyn Report) -> u32 {
    let md = p.int("maxdepth");
    if md < 0 {
        r.error(
            Some("maxdepth"),
            format!("\"maxdepth\" is {md}: it must be ≥ 0"),
            "negative depth",
        );
        5
    } else {
        md as u32
    }
}

/// The integrator's settings, one variant per kind pbrs renders: made by
/// the kind's builder, held by the scene description and by the runtime
/// [`Integrator`]. Its methods only delegate to the kinds' files.
macro_rules! integrators {
    ($($variant:ident($settings:ident) in $module:ident),* $(,)?) => {
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub enum IntegratorSettings {
            $($variant($settings),)*
        }

        impl IntegratorSettings {
            /// The kind's row of [`INTEGRATORS`].
            pub fn kind(&self) -> &'static IntegratorKind {
                match self {
                    $(IntegratorSettings::$variant(_) => &$module::KIND,)*
                }
            }

            /// pbrt-v3's name of the kind.
            pub fn name(&self) -> &'static str {
                self.kind().name
            }

            pub fn max_depth(&self) -> u32 {
                match self {
                    $(IntegratorSettings::$variant(s) => s.max_depth,)*
                }
            }

            /// Sets `maxdepth` (the command line's and the tests' override).
            pub fn set_max_depth(&mut self, d: u32) {
                match self {
                    $(IntegratorSettings::$variant(s) => s.max_depth = d,)*
                }
            }

            /// The kind and its settings in a line, for `--check` and `--stats`.
            pub fn summary(&self) -> String {
                let settings = match self {
                    $(IntegratorSettings::$variant(s) => s.summary(),)*
                };
                format!("{}, {settings}", self.name())
            }

            /// True if it renders participating media.
            pub fn renders_media(&self) -> bool {
                match self {
                    $(IntegratorSettings::$variant(_) => $module::RENDERS_MEDIA,)*
                }
            }

            /// True if it samples subsurface scattering.
            pub fn samples_subsurface(&self) -> bool {
                match self {
                    $(IntegratorSettings::$variant(_) => $module::SAMPLES_SUBSURFACE,)*
                }
            }
        }
    };
}

integrators! {
    Path(PathSettings) in path,
    VolPath(VolPathSettings) in volpath,
    DirectLighting(DirectLightingSettings) in directlighting,
    Whitted(WhittedSettings) in whitted,
}

/// Without an `Integrator` statement: `path` with pbrt-v3's defaults.
impl Default for IntegratorSettings {
    fn default() -> IntegratorSettings {
        IntegratorSettings::Path(PathSettings::default())
    }
}

/// The runtime integrator: a kind's settings and what it builds from the
/// scene (its light distribution, directlighting's sample counts and
/// four-lane light packs).
pub enum Integrator {
    Path {
        settings: PathSettings,
        lights: LightSampler,
    },
    Direct {
        settings: DirectLightingSettings,
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
        settings: WhittedSettings,
    },
    VolPath {
        settings: VolPathSettings,
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
    pub fn new(settings: &IntegratorSettings, scene: &RenderScene, simd: bool) -> Integrator {
        let lights = |strategy: LightSampleStrategy| {
            let kind = light_sampler_kind(strategy);
            LightSampler::new(kind, &scene.lights, &scene.geometry)
        };
        match *settings {
            IntegratorSettings::Path(settings) => Integrator::Path {
                settings,
                lights: lights(settings.light_sample_strategy),
            },
            IntegratorSettings::DirectLighting(settings) => Integrator::Direct {
                settings,
                // pbrt-v3's directlighting chooses uniformly for strategy "one".
                lights: lights(LightSampleStrategy::Uniform),
                n_light_samples: Vec::new(),
                packs: match settings.strategy {
                    DirectStrategy::All if simd => {
                        pack_triangle_lights(&scene.lights).unwrap_or_default()
                    }
                    _ => Vec::new(),
                },
                uniform: Vec::new(),
            },
            IntegratorSettings::Whitted(settings) => Integrator::Whitted { settings },
            IntegratorSettings::VolPath(settings) => Integrator::VolPath {
                settings,
                lights: lights(settings.light_sample_strategy),
            },
        }
    }

    /// Requests the sampler arrays the integrator uses (pbrt-v3's Preprocess).
    pub fn prepare_sampler(&mut self, scene: &RenderScene, sampler: &mut Sampler) {
        if let Integrator::Direct {
            settings:
                DirectLightingSettings {
                    max_depth,
                    strategy: DirectStrategy::All,
                },
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
            Integrator::Path { settings, lights } => path::path_li(
                ray,
                time,
                diff,
                scene,
                sampler,
                scratch,
                settings.max_depth,
                settings.rr_threshold,
                lights,
            ),
            Integrator::VolPath { settings, lights } => volpath::volpath_li(
                ray,
                time,
                diff,
                scene,
                sampler,
                scratch,
                settings.max_depth,
                settings.rr_threshold,
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
