//! Integrators, as pbrt-v3 defines them: `path` (next-event estimation with
//! power-heuristic MIS, Russian roulette), `volpath` (the same with
//! participating media), `directlighting` (strategy all or one, specular
//! lobes followed recursively), `whitted`, `ambientocclusion`, `sppm`
//! (stochastic progressive photon mapping), `bdpt` (bidirectional path
//! tracing, whose light tracing lands on the film as [`Splat`]s) and `mlt`
//! (Metropolis light transport over bdpt's paths, all splats).
//!
//! One file per integrator: [`path`] (with the per-vertex step `path` and
//! `volpath` share, over the medium the path is in), [`volpath`] (the
//! medium tracking and transmittance of that step), [`directlighting`],
//! [`whitted`], [`ambientocclusion`], [`sppm`] (photon mapping, which
//! has its own render loop, [`sppm::Sppm::render`], that the driver calls
//! instead of the tile loop), [`bdpt`] and [`mlt`] (its own loop too,
//! [`mlt::Mlt::render`]); the recursive specular tree that directlighting and
//! whitted share ([`specular`]); the batch of samples a thread renders
//! together ([`batch`]: `path` and `volpath` one vertex of every lane at a
//! time); directlighting's four-lane estimate ([`direct_lanes`]); and what
//! several of them share, written once ([`common`]: shading, emission,
//! light choice and sampling, MIS weights, Russian roulette;
//! [`subsurface`]: the BSSRDF exit of path and volpath).
//!
//! [`INTEGRATORS`] is the table of kinds the loader, `--check`,
//! `grammar/REFERENCE.md` and the tests read; a kind's builder gives its
//! settings (one struct per kind), which the scene description holds;
//! [`Integrator::new`] makes the runtime integrator from them (one struct
//! per kind, built from its settings and the scene, implementing
//! [`Integrate`]). The `integrators!` macro declares the kinds' modules
//! and generates both enums, [`IntegratorSettings`] and [`Integrator`],
//! which only delegate (a `match`, no dynamic dispatch). A new kind is its
//! file, its row of [`INTEGRATORS`] and its line of `integrators!`.

use crate::geometry::{Bounds2i, Ray, RayDiff};
use crate::lights::LightSampler;
use crate::samplers::Sampler;
use crate::scene::kind::{Kind, Report};
use crate::scene::{ParamSpec, ParamValues};
use glam::{Vec2, Vec3};

mod batch;
mod common;
mod direct_lanes;
mod render_scene;
mod specular;
mod subsurface;

pub use batch::Batch;
pub use mlt::{MltDone, MltRun};
pub use render_scene::{RenderScene, SurfaceMedia};
use specular::Work;
pub use sppm::{SppmRun, PIXEL_BYTES as SPPM_PIXEL_BYTES};

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

/// A contribution that lands on the film at a position of its own, not
/// filtered (pbrt-v3's `Film::AddSplat`: bdpt's light tracing). `layer` 0
/// is the image; layer k > 0 is extra image k − 1 (bdpt's images per
/// strategy).
#[derive(Clone, Copy, Debug)]
pub struct Splat {
    pub p_film: Vec2,
    pub l: Vec3,
    pub layer: u32,
}

/// Per-tile scratch space, so the per-sample path never allocates.
#[derive(Default)]
pub struct Scratch {
    u_light: Vec<Vec2>,
    u_scatter: Vec<Vec2>,
    work: Vec<Work>,
    counts: RayCounts,
    /// The tile's splats, in sample order.
    splats: Vec<Splat>,
    /// bdpt's subpath vertices, reused from sample to sample.
    bdpt: bdpt::Subpaths,
}

impl Scratch {
    pub fn counts(&self) -> RayCounts {
        self.counts
    }

    /// The splats of the samples rendered with this scratch space, in
    /// sample order (leaving none).
    pub fn take_splats(&mut self) -> Vec<Splat> {
        std::mem::take(&mut self.splats)
    }
}

/// Rays crossing more than this many `Material "none"` surfaces in a row stop.
const MAX_PASS_THROUGH: u32 = 256;

/// What an integrator kind builds from its parameters: its settings (the
/// builder reports pbrt-v3's checks of them).
pub type IntegratorBuild = fn(&ParamValues, &mut dyn Report) -> IntegratorSettings;

/// One integrator kind: its pbrt-v3 name, its parameters, its builder.
pub type IntegratorKind = Kind<IntegratorBuild>;

/// Every integrator pbrt-v3 knows.
pub static INTEGRATORS: &[IntegratorKind] = &[
    path::KIND,
    volpath::KIND,
    directlighting::KIND,
    whitted::KIND,
    ambientocclusion::KIND,
    sppm::KIND,
    bdpt::KIND,
    mlt::KIND,
];

/// `maxdepth`, which every integrator reads.
const MAX_DEPTH: ParamSpec = ParamSpec::int("maxdepth", 5, "maximum number of bounces (≥ 0)");

/// `pixelbounds`, which every integrator of pbrt-v3 reads and pbrs ignores.
const PIXEL_BOUNDS: ParamSpec = ParamSpec::unsupported(
    "pixelbounds",
    "\"pixelbounds\" is not supported by pbrs: the whole film is rendered (use --cropwindow)",
);

/// The deepest `maxdepth` pbrs follows: 100 times the depth at which
/// pbrt-v3's Halton and Sobol samplers run out of dimensions (1000) and
/// abort, and the depth its stress scenes use. It bounds the work of a
/// sample in a closed room of perfect mirrors, and what `directlighting`
/// requests from the sampler per depth.
pub const MAX_DEPTH_BOUND: u32 = 100_000;

/// pbrt-v3's `maxdepth`, checked: a negative one is an error (and 5 is
/// used); one beyond [`MAX_DEPTH_BOUND`] is clamped with a warning.
fn max_depth(p: &ParamValues, r: &mut dyn Report) -> u32 {
    let md = p.int("maxdepth");
    if md < 0 {
        r.error(
            Some("maxdepth"),
            format!("\"maxdepth\" is {md}: it must be ≥ 0"),
            "negative depth",
        );
        5
    } else if md as u32 > MAX_DEPTH_BOUND {
        r.warn(
            Some("maxdepth"),
            format!("\"maxdepth\" is {md}: pbrs follows paths at most {MAX_DEPTH_BOUND} deep, which is used"),
            "depth clamped",
        );
        MAX_DEPTH_BOUND
    } else {
        md as u32
    }
}

/// The deepest `maxdepth` bdpt and mlt follow. Their work per sample grows
/// with the square of the depth (every pair of subpath lengths is
/// connected, and each connection's MIS weight walks both subpaths), and
/// they have no Russian roulette: in a closed room every path reaches
/// `maxdepth`. pbrt-v3's own bdpt stops near depth 110, where its Halton
/// and Sobol samplers run out of dimensions (about 9 per bounce).
pub const MAX_BIDIRECTIONAL_DEPTH: u32 = 128;

/// [`max_depth`] for bdpt and mlt: beyond [`MAX_BIDIRECTIONAL_DEPTH`] it
/// is clamped with a warning.
fn max_depth_bidirectional(p: &ParamValues, r: &mut dyn Report, kind: &str) -> u32 {
    let md = p.int("maxdepth");
    if md > MAX_BIDIRECTIONAL_DEPTH as i32 {
        r.warn(
            Some("maxdepth"),
            format!("\"maxdepth\" is {md}: {kind} follows paths at most {MAX_BIDIRECTIONAL_DEPTH} deep in pbrs (its work per sample grows with the square of the depth, and pbrt-v3's samplers run out of dimensions near depth 110), which is used"),
            "depth clamped",
        );
        MAX_BIDIRECTIONAL_DEPTH
    } else {
        max_depth(p, r)
    }
}

/// What a runtime integrator does; each kind's struct implements it (only
/// `li` is required) and [`Integrator`] delegates to it.
pub trait Integrate {
    /// Requests the sampler arrays the integrator uses (pbrt-v3's
    /// Preprocess).
    fn prepare_sampler(&mut self, _scene: &RenderScene, _sampler: &mut Sampler) {}

    /// Takes the film's sample bounds, or says why the integrator cannot
    /// render this scene on it (bdpt's camera importance).
    fn prepare_film(
        &mut self,
        _scene: &RenderScene,
        _sample_bounds: Bounds2i,
    ) -> Result<(), String> {
        Ok(())
    }

    /// The extra images the integrator splats to (each a [`Splat`] layer
    /// k > 0) and their file names.
    fn splat_images(&self) -> Vec<(u32, String)> {
        Vec::new()
    }

    /// What the integrator built beyond the light distribution.
    fn notes(&self) -> Vec<String> {
        Vec::new()
    }

    /// The light distribution, for kinds that choose lights.
    fn light_sampler(&self) -> Option<&LightSampler> {
        None
    }

    /// Radiance arriving at the camera along `ray` at scene time `time`
    /// (every ray of the path is traced at it), with its differentials if
    /// it has them.
    fn li(
        &self,
        ray: Ray,
        time: f32,
        diff: Option<RayDiff>,
        scene: &RenderScene,
        sampler: &mut Sampler,
        scratch: &mut Scratch,
    ) -> Vec3;

    /// A batch of `lanes` lanes for [`Integrate::li_batch`], each with a
    /// copy of `sampler`, with room for what the kind keeps per lane.
    fn batch(&self, lanes: usize, sampler: &Sampler) -> Batch {
        Batch::new(lanes, sampler)
    }

    /// [`Integrate::li`] for the camera rays of a batch of samples, lane by
    /// lane the same values bit for bit. Each lane has its own sampler,
    /// positioned at its sample; lanes of weight 0 get no radiance. Unless
    /// the kind does better, lane by lane.
    fn li_batch(&self, b: &mut Batch, scene: &RenderScene, scratch: &mut Scratch) {
        for j in 0..b.len {
            let (ray, time, diff) = (b.rays[j], b.times[j], b.diffs[j]);
            // The scalar loop's test: a NaN weight gets no radiance.
            b.l[j] = if b.weights[j] > 0.0 {
                self.li(ray, time, diff, scene, &mut b.samplers[j], scratch)
            } else {
                Vec3::ZERO
            };
        }
    }
}

/// The kinds pbrs renders, each `Variant(Settings) => module::Runtime`:
/// declares the kinds' modules and generates the settings enum
/// ([`IntegratorSettings`], made by the kind's builder and held by the
/// scene description) and the runtime enum ([`Integrator`], made from the
/// settings and the scene), whose methods only delegate to the kinds'
/// files.
macro_rules! integrators {
    ($($variant:ident($settings:ident) => $module:ident::$runtime:ident),* $(,)?) => {
        $(
            mod $module;
            pub use $module::$settings;
        )*

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

        /// The runtime integrator: one variant per kind, each the kind's
        /// struct (its settings and what it builds from the scene).
        pub enum Integrator {
            $($variant($module::$runtime),)*
        }

        impl Integrator {
            /// Builds the kind's integrator from its settings and the
            /// scene; `scalar` (`RenderOptions::scalar`) leaves out the
            /// four-lane paths (which give the same image).
            pub fn new(settings: &IntegratorSettings, scene: &RenderScene, scalar: bool) -> Integrator {
                match settings {
                    $(IntegratorSettings::$variant(s) => {
                        Integrator::$variant($module::$runtime::new(s, scene, scalar))
                    })*
                }
            }

            /// See [`Integrate::prepare_sampler`].
            pub fn prepare_sampler(&mut self, scene: &RenderScene, sampler: &mut Sampler) {
                match self {
                    $(Integrator::$variant(i) => i.prepare_sampler(scene, sampler),)*
                }
            }

            /// See [`Integrate::prepare_film`].
            pub fn prepare_film(&mut self, scene: &RenderScene, sample_bounds: Bounds2i) -> Result<(), String> {
                match self {
                    $(Integrator::$variant(i) => i.prepare_film(scene, sample_bounds),)*
                }
            }

            /// See [`Integrate::splat_images`].
            pub fn splat_images(&self) -> Vec<(u32, String)> {
                match self {
                    $(Integrator::$variant(i) => i.splat_images(),)*
                }
            }

            /// See [`Integrate::notes`].
            pub fn notes(&self) -> Vec<String> {
                match self {
                    $(Integrator::$variant(i) => i.notes(),)*
                }
            }

            /// See [`Integrate::light_sampler`].
            pub fn light_sampler(&self) -> Option<&LightSampler> {
                match self {
                    $(Integrator::$variant(i) => i.light_sampler(),)*
                }
            }

            /// See [`Integrate::li`].
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
                    $(Integrator::$variant(i) => i.li(ray, time, diff, scene, sampler, scratch),)*
                }
            }

            /// See [`Integrate::batch`].
            pub fn batch(&self, lanes: usize, sampler: &Sampler) -> Batch {
                match self {
                    $(Integrator::$variant(i) => i.batch(lanes, sampler),)*
                }
            }

            /// See [`Integrate::li_batch`].
            #[inline]
            pub fn li_batch(&self, b: &mut Batch, scene: &RenderScene, scratch: &mut Scratch) {
                match self {
                    $(Integrator::$variant(i) => i.li_batch(b, scene, scratch),)*
                }
            }
        }
    };
}

integrators! {
    Path(PathSettings) => path::Path,
    VolPath(VolPathSettings) => volpath::VolPath,
    DirectLighting(DirectLightingSettings) => directlighting::DirectLighting,
    Whitted(WhittedSettings) => whitted::Whitted,
    AmbientOcclusion(AmbientOcclusionSettings) => ambientocclusion::AmbientOcclusion,
    Sppm(SppmSettings) => sppm::Sppm,
    Bdpt(BdptSettings) => bdpt::Bdpt,
    Mlt(MltSettings) => mlt::Mlt,
}

/// Without an `Integrator` statement: `path` with pbrt-v3's defaults.
impl Default for IntegratorSettings {
    fn default() -> IntegratorSettings {
        IntegratorSettings::Path(PathSettings::default())
    }
}
