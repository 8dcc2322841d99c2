//! `bdpt`: pbrt-v3's BDPTIntegrator (src/integrators/bdpt.{h,cpp}),
//! bidirectional path tracing. Each sample traces a camera subpath (from
//! the driver's camera ray) and a light subpath (a light chosen by
//! `lightsamplestrategy` at the camera's position, its emitted ray from
//! the light's `sample_le`), each a random walk that records every
//! vertex's forward and reverse densities ([`vertex`]); then every
//! strategy (s light vertices, t camera vertices, s + t − 2 ≤ `maxdepth`)
//! connects them ([`connect`]), weighted by pbrt-v3's power heuristic over
//! all strategies that could have made the path. Strategies with t = 1
//! (light tracing) land anywhere on the film: they are
//! [`Splat`](super::Splat)s, which the film adds unfiltered and scales by
//! 1/spp (pbrt-v3's `AddSplat` and `splatScale`).
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `maxdepth` | integer | 5 | maximum number of bounces (≥ 0) |
//! | `lightsamplestrategy` | string | `power` | light choice for the light subpaths: `uniform`, `power`, `spatial` or `bvh` |
//! | `visualizestrategies` | bool | false | also write one image per strategy, unweighted |
//! | `visualizeweights` | bool | false | also write one image per strategy, MIS-weighted |
//! | `pixelbounds` | | | ignored, with a warning |
//!
//! With `visualizestrategies` or `visualizeweights` (`maxdepth` is then at
//! most 5, as pbrt-v3), strategy (s, t) of depth d = s + t − 2 is also
//! splatted to its own image, written next to the output image as
//! `bdpt_dDD_sSS_tTT.exr` (pbrt-v3's names; pbrt-v3 writes them to the
//! working directory), without filter and with scale 1.
//!
//! Camera importance is the perspective camera's (pbrt-v3 has no other);
//! another camera is an error before rendering. Media are sampled along
//! both subpaths and attenuate every connection; pbrs's lights have no
//! medium of their own, so a light subpath starts in the camera's medium.
//! Subsurface scattering is not sampled (as pbrt-v3's bdpt, which uses
//! only the BSDF of such a material: its dielectric boundary).

pub(super) mod connect;
mod draw_ahead;
pub(crate) mod mis_shared;
pub(crate) mod vertex;

use super::common::light_sampler;
use super::path::light_sample_strategy;
use super::{max_depth_bidirectional, Integrate, IntegratorKind, IntegratorSettings, Scratch, Splat};
use super::{MAX_DEPTH, PIXEL_BOUNDS};
use crate::cameras::CameraImportance;
use crate::geometry::{Bounds2i, Ray, RayDiff};
use crate::integrators::RenderScene;
use crate::lights::{Light, LightSampler};
use crate::samplers::Sampler;
use crate::scene::kind::{Report, Support};
use crate::scene::{LightSampleStrategy, ParamSpec, ParamValues};
use crate::shapes::SurfacePoint;
use glam::{Vec2, Vec3};
use mis_shared::finish_subpath;
use vertex::{push_at, random_walk, Kind, Mode, Vertex, Walk};

pub const PARAMS: &[ParamSpec] = &[
    MAX_DEPTH,
    ParamSpec::string(
        "lightsamplestrategy",
        "power",
        "how the light subpath's light is chosen: `uniform`, `power`, `spatial` (at the camera) or `bvh` (a pbrs extension)",
    ),
    ParamSpec::boolean(
        "visualizestrategies",
        false,
        "also write each strategy's unweighted image (bdpt_dDD_sSS_tTT.exr)",
    ),
    ParamSpec::boolean(
        "visualizeweights",
        false,
        "also write each strategy's MIS-weighted image (bdpt_dDD_sSS_tTT.exr)",
    ),
    PIXEL_BOUNDS,
];

pub const KIND: IntegratorKind = IntegratorKind {
    name: "bdpt",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "bidirectional path tracing: camera and light subpaths, every connection strategy weighted by the power heuristic, light tracing splatted onto the film; participating media; perspective camera only",
    build: |p, r| IntegratorSettings::Bdpt(BdptSettings::read(p, r)),
};

/// bdpt samples media along its subpaths; it does not sample subsurface
/// scattering (as pbrt-v3's).
pub const RENDERS_MEDIA: bool = true;
pub const SAMPLES_SUBSURFACE: bool = false;

/// `bdpt`'s settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BdptSettings {
    pub max_depth: u32,
    pub light_sample_strategy: LightSampleStrategy,
    pub visualize_strategies: bool,
    pub visualize_weights: bool,
}

impl Default for BdptSettings {
    fn default() -> BdptSettings {
        BdptSettings {
            max_depth: 5,
            light_sample_strategy: LightSampleStrategy::Power,
            visualize_strategies: false,
            visualize_weights: false,
        }
    }
}

impl BdptSettings {
    /// The settings of a statement's parameters, checked as pbrt-v3 does.
    pub fn read(p: &ParamValues, r: &mut dyn Report) -> BdptSettings {
        let mut max_depth = max_depth_bidirectional(p, r, "bdpt");
        let visualize_strategies = p.boolean("visualizestrategies");
        let visualize_weights = p.boolean("visualizeweights");
        if (visualize_strategies || visualize_weights) && max_depth > 5 {
            r.warn(
                Some("maxdepth"),
                "visualizestrategies/visualizeweights was enabled, limiting maxdepth to 5".into(),
                "limited to 5",
            );
            max_depth = 5;
        }
        BdptSettings {
            max_depth,
            light_sample_strategy: light_sample_strategy(p, r),
            visualize_strategies,
            visualize_weights,
        }
    }

    pub fn summary(&self) -> String {
        let mut s = format!(
            "maxdepth {}, light samples {:?}",
            self.max_depth, self.light_sample_strategy
        )
        .to_lowercase();
        if self.visualize_strategies {
            s += ", visualizestrategies";
        }
        if self.visualize_weights {
            s += ", visualizeweights";
        }
        s
    }

    /// True if strategies are written to images of their own.
    pub fn visualizes(&self) -> bool {
        self.visualize_strategies || self.visualize_weights
    }

    /// The images of the strategies when [`BdptSettings::visualizes`]:
    /// (splat layer, file name) for every (s, t) pbrt-v3 writes.
    pub fn strategy_images(&self) -> Vec<(u32, String)> {
        let mut out = Vec::new();
        if !self.visualizes() {
            return out;
        }
        for depth in 0..=self.max_depth as usize {
            for s in 0..=depth + 2 {
                let t = depth + 2 - s;
                if t == 0 || (s == 1 && t == 1) {
                    continue;
                }
                out.push((
                    buffer_index(s, t) as u32 + 1,
                    format!("bdpt_d{depth:02}_s{s:02}_t{t:02}.exr"),
                ));
            }
        }
        out
    }
}

/// pbrt-v3's `BufferIndex`: strategy (s, t)'s image among all of them.
#[inline]
fn buffer_index(s: usize, t: usize) -> usize {
    let above = s + t - 2;
    s + above * (5 + above) / 2
}

/// Each thread's subpaths, kept from sample to sample (their vertices'
/// storage is reused: nothing is allocated per sample once they have
/// grown to the longest subpaths).
#[derive(Default)]
pub struct Subpaths {
    pub(super) camera: Vec<Vertex<'static>>,
    pub(super) light: Vec<Vertex<'static>>,
    /// The s = 1 strategies' values drawn ahead.
    pub(super) drawn: Vec<Option<connect::LightDraw>>,
}

/// An empty vector's storage for vertices of another lifetime (the same
/// type but for the lifetime of the materials the BSDFs refer to: the
/// storage is reused in place, nothing is allocated).
pub(super) fn recycle<'x, 'y>(mut v: Vec<Vertex<'x>>) -> Vec<Vertex<'y>> {
    v.clear();
    v.into_iter().map(|_| unreachable!()).collect()
}

/// The runtime `bdpt`: its settings, its light distribution, the film's
/// sample bounds (where the camera's importance is not zero) and the
/// scene's bounding radius.
pub struct Bdpt {
    /// Whether the s = 1 strategies draw their values ahead
    /// (`draw_ahead::draw_ahead`, where `draw_ahead::draws_ahead`; not in the
    /// scalar loop, the tests' plain reference).
    draw_ahead: bool,
    /// The plain MIS weights ([`Ctx::plain`]).
    plain: bool,
    settings: BdptSettings,
    lights: LightSampler,
    sample_bounds: Option<Bounds2i>,
    scene_radius: f32,
}

impl Bdpt {
    pub fn new(settings: &BdptSettings, scene: &RenderScene, scalar: bool) -> Bdpt {
        Bdpt {
            draw_ahead: !scalar && draw_ahead::draws_ahead(scene),
            plain: scalar,
            settings: *settings,
            lights: light_sampler(settings.light_sample_strategy, scene),
            sample_bounds: None,
            scene_radius: scene.aggregate.bounds.bounding_sphere().1,
        }
    }
}

/// What the subpaths and their connections read of the scene and the
/// sample.
pub(crate) struct Ctx<'a> {
    pub scene: &'a RenderScene,
    pub camera: CameraImportance<'a>,
    pub lights: &'a LightSampler,
    /// The camera vertex: where the light distribution is looked up.
    pub p_camera: Vec3,
    pub camera_medium: Option<u32>,
    pub scene_radius: f32,
    /// The plain code (`RenderOptions::scalar`, the tests' reference):
    /// pbrt-v3's MIS weights computed as it computes them.
    pub plain: bool,
}

impl Ctx<'_> {
    /// The probability that the light subpath starts on light `i`.
    #[inline]
    pub fn light_pmf(&self, i: u32) -> f32 {
        let s = self.scene;
        self.lights
            .pmf(self.p_camera, Vec3::ZERO, i, &s.lights, &s.aggregate)
    }

    /// Asks for the cache lines of the infinite lights' radiance and
    /// density along a ray that has left the scene in direction `d`, which
    /// its strategies read after the light subpath is made.
    #[inline]
    pub fn prefetch_sky(&self, d: Vec3) {
        for &i in &self.scene.infinite_lights {
            if let Light::Infinite(l) = &self.scene.lights[i as usize] {
                l.map.prefetch(d);
            }
        }
    }

    /// pbrt-v3's `InfiniteLightDensity`: the density of the infinite
    /// lights emitting in direction −`w`, each by its probability.
    pub fn infinite_light_density(&self, w: Vec3) -> f32 {
        let s = self.scene;
        let r = SurfacePoint {
            p: Vec3::ZERO,
            p_error: Vec3::ZERO,
            n: Vec3::ZERO,
            ns: Vec3::ZERO,
        };
        s.infinite_lights
            .iter()
            .map(|&i| s.lights[i as usize].pdf_li(&r, -w, &s.aggregate) * self.light_pmf(i))
            .sum()
    }
}

impl Integrate for Bdpt {
    fn light_sampler(&self) -> Option<&LightSampler> {
        Some(&self.lights)
    }

    fn prepare_film(&mut self, scene: &RenderScene, sample_bounds: Bounds2i) -> Result<(), String> {
        CameraImportance::new(&scene.camera, sample_bounds, "bdpt")?;
        self.sample_bounds = Some(sample_bounds);
        Ok(())
    }

    fn splat_images(&self) -> Vec<(u32, String)> {
        self.settings.strategy_images()
    }

    fn li(
        &self,
        ray: Ray,
        time: f32,
        diff: Option<RayDiff>,
        scene: &RenderScene,
        sampler: &mut Sampler,
        scratch: &mut Scratch,
    ) -> Vec3 {
        let Some(bounds) = self.sample_bounds else {
            return Vec3::ZERO;
        };
        // pbrt-v3 renders nothing without lights.
        if scene.lights.is_empty() {
            return Vec3::ZERO;
        }
        let Ok(camera) = CameraImportance::new(&scene.camera, bounds, "bdpt") else {
            return Vec3::ZERO;
        };
        let c = Ctx {
            scene,
            camera,
            lights: &self.lights,
            p_camera: ray.o,
            camera_medium: if scene.media.is_empty() {
                None
            } else {
                scene.camera_medium
            },
            scene_radius: self.scene_radius,
            plain: self.plain,
        };
        let mut cam = recycle(std::mem::take(&mut scratch.bdpt.camera));
        let mut light = recycle(std::mem::take(&mut scratch.bdpt.light));
        let l = self.sample(
            &c,
            (ray, time, diff),
            &mut cam,
            &mut light,
            sampler,
            scratch,
        );
        scratch.bdpt.camera = recycle(cam);
        scratch.bdpt.light = recycle(light);
        l
    }
}

impl Bdpt {
    /// One sample: both subpaths, then every strategy; returns the sum of
    /// the strategies with t ≥ 2 and splats those with t = 1.
    fn sample<'a>(
        &self,
        c: &Ctx<'a>,
        (ray, time, diff): (Ray, f32, Option<RayDiff>),
        cam: &mut Vec<Vertex<'a>>,
        light: &mut Vec<Vertex<'a>>,
        sampler: &mut Sampler,
        scratch: &mut Scratch,
    ) -> Vec3 {
        let max_depth = self.settings.max_depth;
        let n_camera = camera_subpath(c, (ray, time, diff), max_depth + 1, cam, sampler, scratch);
        let n_light = light_subpath(c, time, max_depth, light, sampler, scratch);
        if !c.plain {
            // Every vertex is a connection's end in some strategy.
            finish_subpath(c, cam, 0);
            finish_subpath(c, light, 0);
        }
        let p_film = if self.settings.visualizes() {
            c.camera.we(ray.o, ray.d, time).1
        } else {
            Vec2::ZERO
        };
        let mut l = Vec3::ZERO;
        let ahead = self.draw_ahead && n_light >= 1;
        let mut drawn = std::mem::take(&mut scratch.bdpt.drawn);
        drawn.clear();
        for t in 1..=n_camera {
            if t == 2 && ahead {
                draw_ahead::draw_ahead(c, &cam[..n_camera], max_depth, sampler, &mut drawn);
            }
            for s in 0..=n_light {
                let depth = (t + s) as i64 - 2;
                if (s == 1 && t == 1) || depth < 0 || depth > max_depth as i64 {
                    continue;
                }
                let d = if s == 1 && t >= 2 {
                    drawn.get(t - 2).copied().flatten()
                } else {
                    None
                };
                let st = connect::connect(c, light, cam, (s, t), d, sampler, scratch);
                let at = st.p_raster.unwrap_or(p_film);
                if self.settings.visualizes() {
                    let value = if self.settings.visualize_weights {
                        st.l
                    } else if st.weight == 0.0 {
                        Vec3::ZERO
                    } else {
                        st.l / st.weight
                    };
                    scratch.splats.push(Splat {
                        p_film: at,
                        l: value,
                        layer: buffer_index(s, t) as u32 + 1,
                    });
                }
                if t != 1 {
                    l += st.l;
                } else if st.p_raster.is_some() {
                    scratch.splats.push(Splat {
                        p_film: at,
                        l: st.l,
                        layer: 0,
                    });
                }
            }
        }
        scratch.bdpt.drawn = drawn;
        l
    }
}

/// The camera subpath from the camera ray (pbrt-v3's GenerateCameraSubpath
/// after its ray): the camera vertex and up to `bounces` more; returns its
/// number of vertices.
pub(super) fn camera_subpath<'a>(
    c: &Ctx<'a>,
    (ray, time, diff): (Ray, f32, Option<RayDiff>),
    bounces: u32,
    cam: &mut Vec<Vertex<'a>>,
    sampler: &mut Sampler,
    scratch: &mut Scratch,
) -> usize {
    let pdf_dir = c.camera.pdf_we(ray.o, ray.d, time).1;
    push_at(
        cam,
        Kind::Camera,
        ray.o,
        Vec3::ZERO,
        Vec3::ONE,
        (time, c.camera_medium),
    );
    let walk = Walk {
        ray,
        diff,
        beta: Vec3::ONE,
        pdf: pdf_dir,
        medium: c.camera_medium,
        time,
        mode: Mode::Radiance,
    };
    1 + random_walk(c, walk, bounces, cam, sampler, scratch) as usize
}

/// The light subpath (pbrt-v3's GenerateLightSubpath): the light vertex
/// and up to `bounces` more; returns its number of vertices.
pub(super) fn light_subpath<'a>(
    c: &Ctx<'a>,
    time: f32,
    bounces: u32,
    path: &mut Vec<Vertex<'a>>,
    sampler: &mut Sampler,
    scratch: &mut Scratch,
) -> usize {
    let scene = c.scene;
    let u = sampler.get_1d();
    let chosen = c
        .lights
        .sample(c.p_camera, Vec3::ZERO, u, &scene.lights, &scene.aggregate);
    let (u1, u2) = (sampler.get_2d(), sampler.get_2d());
    let Some((i, pmf)) = chosen else {
        return 0;
    };
    let Some(e) = scene.lights[i as usize].sample_le(u1, u2, &scene.aggregate) else {
        return 0;
    };
    if e.pdf_pos == 0.0 || e.pdf_dir == 0.0 || e.le == Vec3::ZERO {
        return 0;
    }
    // The light's rays start in its own medium (pbrt-v3: a light at a
    // point or on a shape emits into the outside medium of its
    // definition; distant and infinite lights from no medium).
    let medium = scene.light_media[i as usize];
    push_at(path, Kind::Light, e.ray.o, e.n, e.le, (time, medium));
    let v = &mut path[0];
    v.light = Some(i);
    v.pdf_fwd = e.pdf_pos * pmf;
    let beta = e.le * e.n.dot(e.ray.d).abs() / (pmf * e.pdf_pos * e.pdf_dir);
    let walk = Walk {
        ray: e.ray,
        diff: None,
        beta,
        pdf: e.pdf_dir,
        medium,
        time,
        mode: Mode::Importance,
    };
    let n = random_walk(c, walk, bounces, path, sampler, scratch) as usize;
    if path[0].is_infinite_light(c) {
        if n > 0 {
            let v1 = &mut path[1];
            v1.pdf_fwd = e.pdf_pos;
            if v1.on_surface() {
                v1.pdf_fwd *= e.ray.d.dot(v1.n).abs();
            }
        }
        path[0].pdf_fwd = c.infinite_light_density(e.ray.d);
    }
    n + 1
}
