//! `ambientocclusion`: pbrt-v3's AOIntegrator. At the first surface with a
//! BSDF the camera ray meets (surfaces of `Material "none"` are crossed),
//! `nsamples` directions of the hemisphere around the geometric normal
//! turned towards the camera are sampled, by cosine or uniformly, and each
//! unoccluded one adds cos θ / (pdf · nsamples): the image is the fraction
//! of the hemisphere, cosine-weighted, that is open. Lights, materials'
//! colours and media play no part; rays that meet nothing are black.
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `cossample` | bool | true | sample by cosine (else uniformly over the hemisphere) |
//! | `nsamples` | integer | 64 | directions per camera ray (≥ 1), one 2D sampler array |
//! | `pixelbounds` | | | ignored, with a warning |
//!
//! As pbrt-v3, the hemisphere's frame is (dp/du normalised, n × dp/du, n
//! turned towards the camera), from the surface's geometric dp/du and normal.

use super::batch::trace_camera_rays;
use super::{Batch, Integrate, IntegratorKind, IntegratorSettings, Scratch, MAX_PASS_THROUGH, PIXEL_BOUNDS};
use crate::accel::{Hit, PACKET_MAX};
use crate::geometry::{face_forward, spawn_ray, Ray, RayDiff};
use crate::integrators::RenderScene;
use crate::samplers::Sampler;
use crate::sampling::{
    cosine_hemisphere_pdf, cosine_sample_hemisphere, uniform_hemisphere_pdf,
    uniform_sample_hemisphere,
};
use crate::scene::kind::{Report, Support};
use crate::scene::{ParamSpec, ParamValues};
use glam::Vec3;

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::boolean(
        "cossample",
        true,
        "sample directions by cosine (false: uniformly over the hemisphere)",
    ),
    ParamSpec::int("nsamples", 64, "directions sampled per camera ray (≥ 1)"),
    PIXEL_BOUNDS,
];

pub const KIND: IntegratorKind = IntegratorKind {
    name: "ambientocclusion",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "ambient occlusion: the cosine-weighted open fraction of the hemisphere at the first surface, from nsamples directions",
    build: |p, r| IntegratorSettings::AmbientOcclusion(AmbientOcclusionSettings::read(p, r)),
};

/// Ambient occlusion sees no media and no subsurface scattering.
pub const RENDERS_MEDIA: bool = false;
pub const SAMPLES_SUBSURFACE: bool = false;

/// `ambientocclusion`'s settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AmbientOcclusionSettings {
    pub cos_sample: bool,
    pub n_samples: u32,
}

impl Default for AmbientOcclusionSettings {
    fn default() -> Self {
        AmbientOcclusionSettings {
            cos_sample: true,
            n_samples: 64,
        }
    }
}

impl AmbientOcclusionSettings {
    /// The settings of a statement's parameters; `nsamples` below 1 is an
    /// error (pbrt-v3 would divide by zero) and 64 is used.
    pub fn read(p: &ParamValues, r: &mut dyn Report) -> Self {
        let n = p.int("nsamples");
        let n_samples = if n < 1 {
            r.error(
                Some("nsamples"),
                format!("\"nsamples\" is {n}: it must be ≥ 1"),
                "no samples",
            );
            64
        } else {
            n as u32
        };
        AmbientOcclusionSettings {
            cos_sample: p.boolean("cossample"),
            n_samples,
        }
    }

    pub fn summary(&self) -> String {
        format!(
            "nsamples {}, {} sampling",
            self.n_samples,
            if self.cos_sample { "cosine" } else { "uniform" }
        )
    }
}

/// Hemisphere directions made together before their shadow rays, which
/// are traced as one packet.
const GROUP: usize = PACKET_MAX;

/// The runtime `ambientocclusion`: its settings and the size of its
/// sampler array.
pub struct AmbientOcclusion {
    settings: AmbientOcclusionSettings,
    n: u32,
    /// Shadow rays one by one (the plain code the packets are checked
    /// against).
    scalar: bool,
}

impl AmbientOcclusion {
    pub fn new(settings: &AmbientOcclusionSettings, _scene: &RenderScene, scalar: bool) -> Self {
        AmbientOcclusion {
            settings: *settings,
            n: settings.n_samples,
            scalar,
        }
    }
}

impl Integrate for AmbientOcclusion {
    /// One 2D array of `nsamples` (rounded as the sampler wants).
    fn prepare_sampler(&mut self, _scene: &RenderScene, sampler: &mut Sampler) {
        self.n = sampler.round_count(self.settings.n_samples);
        sampler.request_2d_array(self.n);
    }

    fn li(
        &self,
        ray: Ray,
        time: f32,
        _diff: Option<RayDiff>,
        scene: &RenderScene,
        sampler: &mut Sampler,
        scratch: &mut Scratch,
    ) -> Vec3 {
        scratch.counts.closest += 1;
        let first = scene.aggregate.intersect_at(&ray, time);
        self.occlusion(ray, time, first, scene, sampler, scratch)
    }

    /// The batch's camera rays traced together (as packets, one pixel's
    /// rays being coherent), then each lane's hemisphere from its hit:
    /// lane by lane `li`'s values.
    fn li_batch(&self, b: &mut Batch, scene: &RenderScene, scratch: &mut Scratch) {
        trace_camera_rays(b, scene);
        for j in 0..b.len {
            b.l[j] = if b.weights[j] > 0.0 {
                scratch.counts.closest += 1;
                let (ray, time, first) = (b.rays[j], b.times[j], b.hits[j]);
                self.occlusion(ray, time, first, scene, &mut b.samplers[j], scratch)
            } else {
                Vec3::ZERO
            };
        }
    }
}

impl AmbientOcclusion {
    /// The occlusion seen along camera ray `ray`, whose closest hit is
    /// `first`.
    fn occlusion(
        &self,
        mut ray: Ray,
        time: f32,
        first: Option<Hit>,
        scene: &RenderScene,
        sampler: &mut Sampler,
        scratch: &mut Scratch,
    ) -> Vec3 {
        let mut crossed = 0;
        let mut next = first;
        let (hit, s) = loop {
            let Some(hit) = next else {
                return Vec3::ZERO;
            };
            let s = scene.aggregate.surface_at(&hit, time);
            if !scene.materials[s.material as usize].is_none() {
                break (hit, s);
            }
            crossed += 1;
            if crossed > MAX_PASS_THROUGH {
                return Vec3::ZERO;
            }
            ray = spawn_ray(s.point.p, s.point.p_error, s.point.n, ray.d);
            scratch.counts.closest += 1;
            next = scene.aggregate.intersect_at(&ray, time);
        };
        let n = face_forward(s.point.n, -ray.d);
        let dpdu = scene.aggregate.diff_geom(&hit, &s).dpdu;
        let sx = dpdu.normalize();
        let t = s.point.n.cross(sx);
        let Some(u) = sampler.get_2d_array(self.n) else {
            return Vec3::ZERO;
        };
        let count = self.n as f32;
        let mut l = 0.0f32;
        // A group's directions and what each adds if open are made before
        // its shadow rays are traced, so that their divisions and square
        // roots overlap, and the rays are traced together.
        let mut rays = [Ray::new(Vec3::ZERO, Vec3::Z); GROUP];
        let mut adds = [0f32; GROUP];
        for group in u.chunks(GROUP) {
            for ((&u, ray), add) in group.iter().zip(&mut rays).zip(&mut adds) {
                let (w, pdf) = if self.settings.cos_sample {
                    let w = cosine_sample_hemisphere(u);
                    (w, cosine_hemisphere_pdf(w.z.abs()))
                } else {
                    (uniform_sample_hemisphere(u), uniform_hemisphere_pdf())
                };
                let wi = Vec3::new(
                    sx.x * w.x + t.x * w.y + n.x * w.z,
                    sx.y * w.x + t.y * w.y + n.y * w.z,
                    sx.z * w.x + t.z * w.y + n.z * w.z,
                );
                *ray = spawn_ray(s.point.p, s.point.p_error, s.point.n, wi);
                *add = wi.dot(n) / (pdf * count);
            }
            // The group's rays leave one point: traced as a packet.
            let k = group.len();
            scratch.counts.shadow += k as u64;
            let mut blocked = [false; GROUP];
            if self.scalar {
                for (b, ray) in blocked.iter_mut().zip(&rays[..k]) {
                    *b = scene.aggregate.occluded_at(ray, time);
                }
            } else {
                scene
                    .aggregate
                    .occluded_packet(&rays[..k], &[time; GROUP][..k], &mut blocked[..k]);
            }
            for (&add, &b) in adds.iter().zip(&blocked).take(k) {
                if !b {
                    l += add;
                }
            }
        }
        Vec3::splat(l)
    }
}
