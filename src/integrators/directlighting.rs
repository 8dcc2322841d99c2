//! `directlighting`: pbrt-v3's DirectLightingIntegrator, direct light at
//! every vertex of the specular tree ([`super::specular`]) by strategy
//! `all` (every light, its sample counts in sampler arrays; four lights at
//! a time at Lambertian vertices when they are triangles, see
//! [`super::direct_lanes`]) or `one` (one light chosen uniformly).
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `maxdepth` | integer | 5 | maximum depth of the specular tree (≥ 0) |
//! | `strategy` | string | `all` | `all` lights at every vertex, or `one` chosen uniformly |
//! | `pixelbounds` | | | ignored, with a warning |

use super::batch::{trace_camera_rays, Batch};
use super::common::{
    choose_light, emitted, light_along, light_sampler, light_strategy, shade_geom, with_diff,
    KeepShadow, LightSampleFirst, ShadowRay, SurfaceScatter, Unoccluded,
};
use super::direct_lanes;
use super::specular::{specular_tree_li, tree_lanes, tree_li, First, SpecularTree};
use super::{Integrate, IntegratorKind, IntegratorSettings, Scratch, MAX_DEPTH, PIXEL_BOUNDS};
use crate::accel::SurfaceHit;
use crate::geometry::{spawn_ray, Bounds3, Ray, RayDiff};
use crate::lights::{pack_triangle_lights, LightSampler, TriangleLightPack};
use crate::bxdf::{GlossyPair, GLOSSY_LANES};
use crate::materials::{Bsdf, BxdfFlags};
use crate::samplers::Sampler;
use crate::sampling::power_heuristic;
use crate::integrators::RenderScene;
use crate::scene::kind::{Report, Support};
use crate::scene::{DirectStrategy, LightSampleStrategy, ParamSpec, ParamValues};
use glam::{Vec2, Vec3};
use std::cell::Cell;

pub const PARAMS: &[ParamSpec] = &[
    MAX_DEPTH,
    ParamSpec::string(
        "strategy",
        "all",
        "`all`: every light at every vertex (its sample count from the light's `nsamples`); `one`: one light chosen uniformly",
    ),
    PIXEL_BOUNDS,
];

pub const KIND: IntegratorKind = IntegratorKind {
    name: "directlighting",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "direct lighting with MIS at every vertex, specular reflection and transmission followed recursively",
    build: |p, r| IntegratorSettings::DirectLighting(DirectLightingSettings::read(p, r)),
};

/// directlighting ignores participating media and subsurface scattering
/// (as pbrt-v3's).
pub const RENDERS_MEDIA: bool = false;
pub const SAMPLES_SUBSURFACE: bool = false;

/// `directlighting`'s settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectLightingSettings {
    pub max_depth: u32,
    pub strategy: DirectStrategy,
}

impl Default for DirectLightingSettings {
    fn default() -> DirectLightingSettings {
        DirectLightingSettings {
            max_depth: 5,
            strategy: DirectStrategy::All,
        }
    }
}

impl DirectLightingSettings {
    /// The settings of a statement's parameters, checked as pbrt-v3 does:
    /// an unknown strategy is a warning, and `all` is used.
    pub fn read(p: &ParamValues, r: &mut dyn Report) -> DirectLightingSettings {
        let max_depth = super::max_depth(p, r);
        let strategy = match p.string("strategy") {
            "all" => DirectStrategy::All,
            "one" => DirectStrategy::One,
            other => {
                r.warn(
                    Some("strategy"),
                    format!("unknown strategy \"{other}\": \"all\" is used (as pbrt-v3)"),
                    "expected all or one",
                );
                DirectStrategy::All
            }
        };
        DirectLightingSettings {
            max_depth,
            strategy,
        }
    }

    pub fn summary(&self) -> String {
        let DirectLightingSettings {
            max_depth,
            strategy,
        } = self;
        format!("maxdepth {max_depth}, strategy {strategy:?}").to_lowercase()
    }
}

/// The runtime `directlighting`: its settings, its light distribution
/// (strategy `one`), the sample counts (strategy `all`) and the four-lane
/// light packs.
pub struct DirectLighting {
    settings: DirectLightingSettings,
    lights: LightSampler,
    n_light_samples: Vec<u32>,
    /// Each area light's world bounds (`None` for the other lights), for
    /// strategy "all": see [`sample_all_lights`]. Empty with the options'
    /// `scalar` switch (which gives the same image).
    light_boxes: Vec<Option<Bounds3>>,
    scalar: bool,
    /// The lights four to a pack, for strategy "all" when every light is
    /// a triangle of constant normal with one sample (else empty).
    packs: Vec<TriangleLightPack>,
    /// Light `i` of `packs` in all four lanes, for the camera vertices of
    /// a batch (one light at four vertices).
    uniform: Vec<TriangleLightPack>,
    /// Strategy "all" with two to four lights, all delta lights of one
    /// sample (and not the scalar switch): a plastic-like BSDF's values
    /// for all of them are then computed at once ([`delta_lights_glossy`]).
    delta_lanes: bool,
}

impl DirectLighting {
    /// `scalar` (the options' switch) leaves out the four-lane packs and
    /// the lights' boxes (which give the same image).
    pub fn new(settings: &DirectLightingSettings, scene: &RenderScene, scalar: bool) -> DirectLighting {
        DirectLighting {
            settings: *settings,
            // pbrt-v3's directlighting chooses uniformly for strategy "one".
            lights: light_sampler(LightSampleStrategy::Uniform, scene),
            n_light_samples: Vec::new(),
            light_boxes: Vec::new(),
            scalar,
            packs: match settings.strategy {
                DirectStrategy::All if !scalar => {
                    pack_triangle_lights(&scene.lights).unwrap_or_default()
                }
                _ => Vec::new(),
            },
            uniform: Vec::new(),
            delta_lanes: false,
        }
    }

    /// The BSDF's [`GlossyPair`] where [`delta_lights_glossy`] applies.
    #[inline]
    fn glossy_pair(&self, bsdf: &Bsdf) -> Option<GlossyPair> {
        if self.delta_lanes {
            GlossyPair::of(bsdf, BxdfFlags::NON_SPECULAR)
        } else {
            None
        }
    }
}

impl Integrate for DirectLighting {
    /// Strategy `all`: the sample counts of every light, and two arrays
    /// per light and depth (pbrt-v3's Preprocess); the packs are dropped
    /// unless every light has one sample.
    fn prepare_sampler(&mut self, scene: &RenderScene, sampler: &mut Sampler) {
        if self.settings.strategy != DirectStrategy::All {
            return;
        }
        self.n_light_samples = scene
            .lights
            .iter()
            .map(|l| sampler.round_count(l.n_samples()))
            .collect();
        self.light_boxes = if self.scalar {
            Vec::new()
        } else {
            scene
                .lights
                .iter()
                .map(|l| {
                    if l.is_delta() || l.is_infinite() {
                        return None;
                    }
                    l.bounds(&scene.aggregate).map(|b| b.bounds)
                })
                .collect()
        };
        if self.n_light_samples.iter().any(|&n| n != 1) {
            self.packs.clear();
        }
        self.delta_lanes = !self.scalar
            && (2..=GLOSSY_LANES).contains(&scene.lights.len())
            && self.n_light_samples.iter().all(|&n| n == 1)
            && scene.lights.iter().all(|l| l.is_delta());
        self.uniform = self
            .packs
            .iter()
            .flat_map(|p| (0..p.count).map(|lane| p.uniform(lane)))
            .collect();
        for _ in 0..self.settings.max_depth {
            for &n in &self.n_light_samples {
                sampler.request_2d_array(n);
                sampler.request_2d_array(n);
            }
        }
    }

    fn notes(&self) -> Vec<String> {
        let mut notes = Vec::new();
        let boxes = self.light_boxes.iter().flatten().count();
        if boxes > 0 {
            notes.push(format!(
                "directlighting \"all\": {boxes} area lights bounded (no estimates of one wholly behind a surface that only reflects)"
            ));
        }
        if self.packs.is_empty() {
            return notes;
        }
        notes.push(format!(
            "directlighting \"all\": {} triangle lights in {} four-lane packs (Lambertian vertices sample four lights at once)",
            self.packs.iter().map(|p| p.count).sum::<usize>(),
            self.packs.len()
        ));
        notes
    }

    fn light_sampler(&self) -> Option<&LightSampler> {
        Some(&self.lights)
    }

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

    /// With room for the batch's Lambertian camera vertices when the
    /// lights are packed.
    fn batch(&self, lanes: usize, sampler: &Sampler) -> Batch {
        let mut b = Batch::new(lanes, sampler);
        if !self.uniform.is_empty() {
            let d = &mut b.direct;
            d.lanes.reserve(lanes);
            d.verts.reserve(lanes);
            d.emitted.reserve(lanes);
            d.sums.reserve(lanes);
            d.u.reserve(lanes * 2 * self.uniform.len());
        }
        b
    }

    /// The camera rays first; then the Lambertian camera vertices four at a
    /// time when the lights are packed ([`DirectLighting::direct_batch`]),
    /// else the specular tree lane by lane.
    fn li_batch(&self, b: &mut Batch, scene: &RenderScene, scratch: &mut Scratch) {
        trace_camera_rays(b, scene);
        if self.uniform.is_empty() {
            tree_lanes(self, b, scene, scratch);
        } else {
            self.direct_batch(b, scene, scratch);
        }
    }
}

impl SpecularTree for DirectLighting {
    fn max_depth(&self) -> u32 {
        self.settings.max_depth
    }

    /// The direct light at `s` by the strategy (nothing without lights).
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
        if !scene.lights.is_empty() {
            *local += match (self.settings.strategy, bsdf.single_lambertian()) {
                (DirectStrategy::All, Some(r)) if !self.packs.is_empty() => {
                    direct_lanes::sample_all_lights_packed(
                        scene,
                        s,
                        bsdf,
                        r,
                        wo,
                        sampler,
                        scratch,
                        &self.packs,
                    )
                }
                (DirectStrategy::All, _) => match self.glossy_pair(bsdf) {
                    Some(pair) => {
                        delta_lights_glossy(scene, s, bsdf, &pair, wo, sampler, scratch)
                    }
                    None => sample_all_lights(
                        scene,
                        s,
                        bsdf,
                        wo,
                        sampler,
                        scratch,
                        &self.n_light_samples,
                        &self.light_boxes,
                        !self.scalar,
                    ),
                },
                (DirectStrategy::One, _) => {
                    sample_one_light(scene, s, bsdf, wo, sampler, scratch, &self.lights)
                }
            };
        }
    }
}

impl DirectLighting {
    /// directlighting (strategy "all", triangle lights) for a batch whose
    /// camera rays are traced: camera vertices whose BSDF is one
    /// Lambertian are shaded and their samples drawn lane by lane, then
    /// their light estimates are computed four vertices at a time
    /// ([`direct_lanes::sample_all_lights_lanes`]); the other lanes go
    /// through [`specular_tree_li`] from their shaded vertex.
    /// Lane by lane the same values, samples and rays as `li`.
    fn direct_batch<'a>(
        &self,
        b: &mut Batch,
        scene: &'a RenderScene,
        scratch: &mut Scratch,
    ) {
        let (settings, packs, uniform) = (&self.settings, &self.packs, &self.uniform);
        let d = &mut b.direct;
        d.clear();
        let mut bsdf = Bsdf::empty();
        for j in 0..b.len {
            // The differentials are copied only where they are read (a
            // copy of every lane's stalled on the camera stage's stores).
            let (ray, time, diff) = (b.rays[j], b.times[j], &b.diffs[j]);
            let sampler = &mut b.samplers[j];
            b.l[j] = Vec3::ZERO;
            // The scalar loop's test: a NaN weight gets no radiance.
            if b.weights[j].partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                continue;
            }
            let mut go_on = |first: First, bsdf: &mut Bsdf<'a>| {
                specular_tree_li(self, ray, first, time, *diff, scene, sampler, scratch, bsdf)
            };
            let Some(hit) = b.hits[j] else {
                b.l[j] = go_on(First::Hit(None), &mut bsdf);
                continue;
            };
            let mut s = scene.aggregate.surface_at(&hit, time);
            let material = &scene.materials[s.material as usize];
            if material.is_none() {
                b.l[j] = go_on(First::Hit(Some(hit)), &mut bsdf);
                continue;
            }
            // specular_tree_li's shading of its first vertex.
            let geom = diff
                .as_ref()
                .filter(|_| scene.material_needs_geom[s.material as usize])
                .map(|dd| with_diff(scene, &hit, &s, dd));
            shade_geom(
                scene,
                &hit,
                &mut s,
                material,
                false,
                geom.as_ref(),
                &mut bsdf,
            );
            let Some(r) = bsdf.single_lambertian() else {
                b.l[j] = go_on(First::Shaded { hit, s, geom }, &mut bsdf);
                continue;
            };
            // What specular_tree_li does at a Lambertian first vertex: the
            // vertex counted, the light samples drawn, and no specular
            // children (their samples skipped).
            scratch.counts.closest += 1;
            let wo = -ray.d;
            for pack in packs {
                let start = d.u.len();
                d.u.resize(start + 2 * pack.count, Vec2::ZERO);
                direct_lanes::draw_samples_into(sampler, &mut d.u[start..]);
            }
            if 1 < settings.max_depth {
                sampler.skip_2d();
                sampler.skip_2d();
            }
            d.lanes.push(j as u32);
            d.emitted.push(emitted(scene, &s, wo));
            d.verts
                .push(direct_lanes::LambertVertex::new(&s, &bsdf, r, wo));
            d.sums.push(Vec3::ZERO);
        }
        direct_lanes::sample_all_lights_lanes(scene, &d.verts, &d.u, uniform, &mut d.sums, scratch);
        for ((&j, &e), &sum) in d.lanes.iter().zip(&d.emitted).zip(&d.sums) {
            // specular_tree_li's sums: local = emitted + estimate, then
            // l += beta · local with l = 0 and beta = 1.
            let local = e + sum;
            b.l[j as usize] = Vec3::ZERO + Vec3::ONE * local;
        }
    }
}

/// pbrt-v3's UniformSampleOneLight with a light distribution.
#[inline]
pub(super) fn sample_one_light(
    scene: &RenderScene,
    s: &SurfaceHit,
    bsdf: &Bsdf,
    wo: Vec3,
    sampler: &mut Sampler,
    scratch: &mut Scratch,
    lights: &LightSampler,
) -> Vec3 {
    let Some((light, pmf, u_light)) =
        choose_light(scene, &s.point, sampler, lights, LightSampleFirst::No)
    else {
        return Vec3::ZERO;
    };
    if !bsdf.has_component(BxdfFlags::NON_SPECULAR) {
        // The estimate is 0, as in `sample_all_lights`.
        sampler.skip_2d();
        return Vec3::ZERO / pmf;
    }
    let u_scatter = sampler.get_2d();
    estimate_direct(scene, s, bsdf, wo, light, None, u_light, u_scatter, sampler, scratch) / pmf
}

/// pbrt-v3's UniformSampleAllLights with per-pixel sample arrays; with
/// `together`, a many-sample light's shadow rays are traced side by side
/// ([`estimates_together`], the same values; off under the scalar switch).
#[allow(clippy::too_many_arguments)]
pub(super) fn sample_all_lights(
    scene: &RenderScene,
    s: &SurfaceHit,
    bsdf: &Bsdf,
    wo: Vec3,
    sampler: &mut Sampler,
    scratch: &mut Scratch,
    n_light_samples: &[u32],
    light_boxes: &[Option<Bounds3>],
    together: bool,
) -> Vec3 {
    let mut l = Vec3::ZERO;
    let mut u_light = std::mem::take(&mut scratch.u_light);
    let mut u_scatter = std::mem::take(&mut scratch.u_scatter);
    // Estimates known to be 0 (pbrt-v3 computes them to that) are left out,
    // their samples only consumed as the estimates would: every light's at
    // a specular (or lobe-less) BSDF, whose light samples and BSDF samples
    // have no value; and with reflection lobes only, those of an area light
    // wholly behind the surface (by the geometric normal, on the other side
    // than `wo`): its light samples are on the side no lobe reaches, and the
    // BSDF's samples with a value are on `wo`'s side (`Bsdf::sample` gives
    // the others none, as pbrt-v3), leaving away from it.
    let lit = bsdf.has_component(BxdfFlags::NON_SPECULAR);
    let reflecting = lit && bsdf.reflects_only(BxdfFlags::NON_SPECULAR);
    let (p, ng) = (s.point.p, s.point.n);
    for (j, &n) in n_light_samples.iter().enumerate() {
        let light = j as u32;
        let light_box = light_boxes.get(j).copied().flatten();
        if !lit || (reflecting && light_box.is_some_and(|b| wholly_behind(&b, p, ng, wo))) {
            let got_light = sampler.skip_2d_array(n, &mut u_light);
            let got_scatter = sampler.skip_2d_array(n, &mut u_scatter);
            if !(got_light && got_scatter) {
                sampler.skip_2d();
                sampler.skip_2d();
            }
            // The sum of the estimates.
            l += Vec3::ZERO;
            continue;
        }
        // Both arrays are always asked for, as pbrt-v3 does; a delta
        // light reads neither (its sample has no random values and its
        // light takes no BSDF sample), so their values are not made.
        let delta = scene.lights[j].is_delta();
        let mut take = |out: &mut Vec<Vec2>| {
            if delta {
                sampler.skip_2d_array(n, out)
            } else {
                sampler.fill_2d_array(n, out)
            }
        };
        let got_light = take(&mut u_light);
        let got_scatter = take(&mut u_scatter);
        let reach = light_box.and_then(|b| Reach::new(&b, p));
        let ld = if got_light && got_scatter {
            let u = |k: usize| {
                if delta {
                    (Vec2::ZERO, Vec2::ZERO)
                } else {
                    (u_light[k], u_scatter[k])
                }
            };
            let mut sum = Vec3::ZERO;
            if together && n > 1 {
                // Their shadow rays traced side by side, a run at a time.
                let mut first = 0;
                while first < n as usize {
                    let count = (n as usize - first).min(SHADOW_RUN);
                    estimates_together(
                        scene, s, bsdf, wo, light, reach, first, count, &u, &mut sum, sampler,
                        scratch,
                    );
                    first += count;
                }
            } else {
                for k in 0..n as usize {
                    let (ul, us) = u(k);
                    sum +=
                        estimate_direct(scene, s, bsdf, wo, light, reach, ul, us, sampler, scratch);
                }
            }
            sum / n as f32
        } else {
            let ul = sampler.get_2d();
            let us = sampler.get_2d();
            estimate_direct(scene, s, bsdf, wo, light, reach, ul, us, sampler, scratch)
        };
        l += ld;
    }
    scratch.u_light = u_light;
    scratch.u_scatter = u_scatter;
    l
}

/// [`sample_all_lights`] for two to four delta lights of one sample each
/// at a plastic-like BSDF ([`GlossyPair`]): the lights are sampled in
/// order (their arrays skipped as the loop there skips them: a delta light
/// reads neither, and has no box, so none is left out), the BSDF's values
/// for all of their directions are computed in one pass of lanes, then
/// each light's estimate is finished in order as `estimate_direct`
/// finishes it (no value, no density or a blocked shadow ray give 0, else
/// f·Li / pdf), and summed as there. Bit for bit `sample_all_lights`' sum.
#[inline(never)]
fn delta_lights_glossy(
    scene: &RenderScene,
    s: &SurfaceHit,
    bsdf: &Bsdf,
    pair: &GlossyPair,
    wo: Vec3,
    sampler: &mut Sampler,
    scratch: &mut Scratch,
) -> Vec3 {
    let count = scene.lights.len().min(GLOSSY_LANES);
    let mut u_light = std::mem::take(&mut scratch.u_light);
    let mut u_scatter = std::mem::take(&mut scratch.u_scatter);
    let mut samples = [None; GLOSSY_LANES];
    // Whether light j's arrays were there (its estimate is then summed as
    // one sample's, else taken as it is).
    let mut arrays = [false; GLOSSY_LANES];
    let mut wi = [Vec3::Z; GLOSSY_LANES];
    for j in 0..count {
        let got_light = sampler.skip_2d_array(1, &mut u_light);
        let got_scatter = sampler.skip_2d_array(1, &mut u_scatter);
        arrays[j] = got_light && got_scatter;
        let u_l = if arrays[j] {
            Vec2::ZERO
        } else {
            let u = sampler.get_2d();
            sampler.get_2d();
            u
        };
        samples[j] = scene.lights[j].sample_li(&s.point, u_l, &scene.aggregate);
        if let Some(ls) = &samples[j] {
            wi[j] = ls.wi;
        }
    }
    scratch.u_light = u_light;
    scratch.u_scatter = u_scatter;
    let mut f = [Vec3::ZERO; GLOSSY_LANES];
    pair.f(bsdf, s.point.ns, wo, &wi[..count], &mut f[..count]);
    let mut l = Vec3::ZERO;
    for j in 0..count {
        let ld = match &samples[j] {
            Some(ls) if !(ls.pdf.is_nan() || ls.pdf <= 0.0 || ls.li == Vec3::ZERO) => {
                if f[j] == Vec3::ZERO {
                    Vec3::ZERO
                } else {
                    scratch.counts.shadow += 1;
                    if scene.aggregate.occluded_at(&ls.shadow, s.time) {
                        Vec3::ZERO
                    } else {
                        f[j] * ls.li / (1.0 * ls.pdf)
                    }
                }
            }
            _ => Vec3::ZERO,
        };
        l += if arrays[j] {
            let mut sum = Vec3::ZERO;
            sum += ld;
            sum / 1.0
        } else {
            ld
        };
    }
    l
}

/// The sphere around an area light's box as seen from a point outside it:
/// directions outside its cone miss the light.
#[derive(Clone, Copy, Debug)]
pub(super) struct Reach {
    /// From the point to the sphere's centre.
    v: Vec3,
    /// `|v|² − r²` for the sphere's radius `r`, grown by a thousandth and
    /// by three thousandths of the coordinates' size: far beyond the
    /// rounding of the directions' lengths, of rays' origins and of this
    /// test.
    lim: f32,
}

impl Reach {
    /// `None` when `p` is within the sphere (every direction may hit).
    #[inline]
    fn new(b: &Bounds3, p: Vec3) -> Option<Reach> {
        let (c, h) = (b.center(), 0.5 * b.diagonal());
        let r = h.length();
        let r = 1.001 * r + 3e-3 * (c.abs().max_element() + p.abs().max_element());
        let v = c - p;
        let lim = v.length_squared() - r * r;
        (lim > 0.0 && lim.is_finite()).then_some(Reach { v, lim })
    }

    /// Whether unit direction `w` is within the cone.
    #[inline]
    fn may_hit(&self, w: Vec3) -> bool {
        let t = w.dot(self.v);
        !(t < 0.0 || t * t < self.lim)
    }
}

/// Whether box `b` lies wholly on the other side of the plane through `p`
/// with normal `n` than direction `wo`, by a margin of a thousandth of the
/// coordinates' size (far beyond the rounding of the points sampled on it
/// and of the rays' origins).
#[inline]
fn wholly_behind(b: &Bounds3, p: Vec3, n: Vec3, wo: Vec3) -> bool {
    let side = wo.dot(n);
    if side == 0.0 || !side.is_finite() {
        return false;
    }
    let (c, h) = (b.center(), 0.5 * b.diagonal());
    let d = (c - p).dot(n) * side.signum();
    let r = n.abs().dot(h);
    let margin = 1e-3 * (c.abs().max_element() + p.abs().max_element() + h.max_element());
    d + r < -margin
}

/// A many-sample light's estimates whose shadow rays are traced together.
const SHADOW_RUN: usize = crate::accel::PACKET_MAX;

/// `count` of a many-sample light's estimates (samples `first` onwards,
/// `u(k)` giving sample `k`'s light and BSDF values) added to `sum` in
/// order, each [`estimate_direct`]'s value bit for bit: their shadow rays are
/// kept and traced side by side ([`crate::accel::Aggregate::occluded_stream`]),
/// then each estimate is its light strategy's value if its ray is clear
/// (0 otherwise) plus its BSDF strategy's, as `estimate_direct` adds them.
#[allow(clippy::too_many_arguments)]
#[inline(never)]
fn estimates_together(
    scene: &RenderScene,
    s: &SurfaceHit,
    bsdf: &Bsdf,
    wo: Vec3,
    light_index: u32,
    reach: Option<Reach>,
    first: usize,
    count: usize,
    u: &impl Fn(usize) -> (Vec2, Vec2),
    sum: &mut Vec3,
    sampler: &mut Sampler,
    scratch: &mut Scratch,
) {
    let mut rays = [Ray::new(Vec3::ZERO, Vec3::Z); SHADOW_RUN];
    let mut which = [0usize; SHADOW_RUN];
    let mut parts = [(Vec3::ZERO, None); SHADOW_RUN];
    let mut n_rays = 0;
    for (i, part) in parts[..count].iter_mut().enumerate() {
        let (ul, us) = u(first + i);
        let kept = Cell::new(false);
        let shadow = KeepShadow {
            ray: Cell::from_mut(&mut rays[n_rays]),
            kept: &kept,
        };
        *part = estimate_parts(
            scene,
            s,
            bsdf,
            wo,
            light_index,
            reach,
            ul,
            us,
            shadow,
            sampler,
            scratch,
        );
        if kept.get() {
            which[n_rays] = i;
            n_rays += 1;
        }
    }
    scratch.counts.shadow += n_rays as u64;
    let times = [s.time; SHADOW_RUN];
    let mut blocked = [false; SHADOW_RUN];
    scene
        .aggregate
        .occluded_stream(&rays[..n_rays], &times[..n_rays], &mut blocked[..n_rays]);
    let mut clear = [false; SHADOW_RUN];
    for (&i, &b) in which[..n_rays].iter().zip(&blocked[..n_rays]) {
        clear[i] = !b;
    }
    for (&(light, by_bsdf), &clear) in parts[..count].iter().zip(&clear[..count]) {
        *sum += both_strategies(if clear { light } else { Vec3::ZERO }, by_bsdf);
    }
}

/// pbrt-v3's EstimateDirect: one light sample and one BSDF sample combined
/// with the power heuristic; the BSDF sample is skipped for delta lights.
#[allow(clippy::too_many_arguments)]
#[inline]
pub(super) fn estimate_direct(
    scene: &RenderScene,
    s: &SurfaceHit,
    bsdf: &Bsdf,
    wo: Vec3,
    light_index: u32,
    reach: Option<Reach>,
    u_light: Vec2,
    u_scatter: Vec2,
    sampler: &mut Sampler,
    scratch: &mut Scratch,
) -> Vec3 {
    let (light, by_bsdf) = estimate_parts(
        scene,
        s,
        bsdf,
        wo,
        light_index,
        reach,
        u_light,
        u_scatter,
        Unoccluded,
        sampler,
        scratch,
    );
    both_strategies(light, by_bsdf)
}

/// EstimateDirect's sum: the light strategy's value, plus the BSDF
/// strategy's when it has one (added to it, as pbrt-v3's `Ld +=`).
#[inline(always)]
fn both_strategies(light: Vec3, by_bsdf: Option<Vec3>) -> Vec3 {
    let mut ld = light;
    if let Some(b) = by_bsdf {
        ld += b;
    }
    ld
}

/// [`estimate_direct`]'s two strategies with the light sample's shadow ray
/// through `shadow`: the light sample's value, and the BSDF sample's when
/// it is added.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn estimate_parts(
    scene: &RenderScene,
    s: &SurfaceHit,
    bsdf: &Bsdf,
    wo: Vec3,
    light_index: u32,
    reach: Option<Reach>,
    u_light: Vec2,
    u_scatter: Vec2,
    shadow: impl ShadowRay,
    sampler: &mut Sampler,
    scratch: &mut Scratch,
) -> (Vec3, Option<Vec3>) {
    let light = &scene.lights[light_index as usize];
    let geom = &scene.aggregate;
    let ns = s.point.ns;
    let scatter = SurfaceScatter {
        bsdf,
        ns,
        flags: BxdfFlags::NON_SPECULAR,
    };
    let ld = light_strategy(
        scene,
        &s.point,
        s.time,
        &scatter,
        wo,
        light_index,
        u_light,
        1.0,
        shadow,
        sampler,
        scratch,
    );
    if !light.is_delta() {
        // A direction that misses the light's bounding sphere finds no light
        // (its density is 0, or its ray hits something else): its value
        // and density are not computed.
        let aimed = |wi: Vec3| reach.is_none_or(|r| r.may_hit(wi));
        if let Some(bs) = bsdf.sample_if(wo, u_scatter, BxdfFlags::NON_SPECULAR, aimed) {
            let f = bs.f * bs.wi.dot(ns).abs();
            if f != Vec3::ZERO && bs.pdf > 0.0 {
                let ray = spawn_ray(s.point.p, s.point.p_error, s.point.n, bs.wi);
                let light_pdf = light.pdf_li_ray(&s.point, &ray, geom);
                if light_pdf == 0.0 {
                    return (ld, None);
                }
                let weight = power_heuristic(1, bs.pdf, 1, light_pdf);
                let li = light_along(scene, &ray, bs.wi, s.time, light_index, scratch);
                return (ld, Some(f * li * weight / bs.pdf));
            }
        }
    }
    (ld, None)
}
