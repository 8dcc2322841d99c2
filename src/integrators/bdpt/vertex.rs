//! The vertices of bdpt's subpaths (pbrt-v3's `Vertex`, bdpt.h): camera,
//! light, surface and medium vertices with their forward and reverse
//! densities (by area, or by solid angle at a light at infinity), the
//! conversions between measures, the lights' densities of origin and
//! direction, and the random walk that makes a subpath (pbrt-v3's
//! `RandomWalk`), with media sampled along its segments.

use super::mis_shared::Back;
use super::Ctx;
use crate::geometry::{spawn_ray, Ray, RayDiff};
use crate::integrators::common::{escaped, shade};
use crate::integrators::sppm::importance as eta_importance;
use crate::integrators::volpath::medium_after;
use crate::integrators::{Scratch, SurfaceMedia, MAX_PASS_THROUGH};
use crate::materials::{Bsdf, BxdfFlags};
use crate::media::HenyeyGreenstein;
use crate::samplers::Sampler;
use glam::Vec3;

/// Appends a vertex of `kind` at `p` (geometric and shading normal `n`)
/// with throughput `beta`, time and medium, nothing else set, to `path`,
/// written field by field into the vector's next slot: a vertex holds its
/// BSDF's storage, which a vertex built on the stack and pushed would copy
/// whole, and a copy of one assembled from narrow stores stalls on store
/// forwarding.
pub(crate) fn push_at<'a>(
    path: &mut Vec<Vertex<'a>>,
    kind: Kind,
    p: Vec3,
    n: Vec3,
    beta: Vec3,
    (time, medium): (f32, Option<u32>),
) {
    use std::ptr::addr_of_mut;
    path.reserve(1);
    let len = path.len();
    let v = path.spare_capacity_mut()[0].as_mut_ptr();
    // Every field, named, so that a new one must be written here too.
    let _fields = |v: &Vertex| {
        let Vertex {
            kind: _,
            beta: _,
            p: _,
            p_error: _,
            n: _,
            ns: _,
            wo: _,
            time: _,
            medium: _,
            media: _,
            light: _,
            bsdf: _,
            phase: _,
            delta: _,
            pdf_fwd: _,
            pdf_rev: _,
            ratio: _,
            back: _,
        } = v;
    };
    // SAFETY: `reserve` made slot `len` exist; every field of the vertex
    // is written below before the length covers it.
    unsafe {
        addr_of_mut!((*v).kind).write(kind);
        addr_of_mut!((*v).beta).write(beta);
        addr_of_mut!((*v).p).write(p);
        addr_of_mut!((*v).p_error).write(Vec3::ZERO);
        addr_of_mut!((*v).n).write(n);
        addr_of_mut!((*v).ns).write(n);
        addr_of_mut!((*v).wo).write(Vec3::ZERO);
        addr_of_mut!((*v).time).write(time);
        addr_of_mut!((*v).medium).write(medium);
        addr_of_mut!((*v).media).write(None);
        addr_of_mut!((*v).light).write(None);
        Bsdf::write_empty(addr_of_mut!((*v).bsdf));
        addr_of_mut!((*v).phase).write(HenyeyGreenstein { g: 0.0 });
        addr_of_mut!((*v).delta).write(false);
        addr_of_mut!((*v).pdf_fwd).write(0.0);
        addr_of_mut!((*v).pdf_rev).write(0.0);
        addr_of_mut!((*v).ratio).write(0.0);
        addr_of_mut!((*v).back).write(None);
        path.set_len(len + 1);
    }
}

/// What a vertex is (pbrt-v3's `VertexType`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Kind {
    Camera,
    Light,
    Surface,
    Medium,
}

/// Which way light flows along a subpath (pbrt-v3's `TransportMode`):
/// camera subpaths carry radiance, light subpaths importance.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Mode {
    Radiance,
    Importance,
}

/// One vertex of a subpath.
#[derive(Clone, Debug)]
pub(crate) struct Vertex<'a> {
    pub kind: Kind,
    /// The subpath's throughput up to the vertex.
    pub beta: Vec3,
    pub p: Vec3,
    pub p_error: Vec3,
    /// The geometric normal; zero off surfaces (pbrt-v3's `IsOnSurface`).
    pub n: Vec3,
    /// The shading normal of a surface (else `n`).
    pub ns: Vec3,
    /// Towards the previous vertex (surfaces and media).
    pub wo: Vec3,
    pub time: f32,
    /// The medium the vertex is in (for a surface, the one its ray came
    /// through).
    pub medium: Option<u32>,
    /// A surface's media when it is a transition.
    pub media: Option<SurfaceMedia>,
    /// A light vertex's light (`None`: an escaped ray, pbrt-v3's light at
    /// infinity with no light), or a surface's area light.
    pub light: Option<u32>,
    pub bsdf: Bsdf<'a>,
    pub phase: HenyeyGreenstein,
    /// Reached by a specular bounce.
    pub delta: bool,
    pub pdf_fwd: f32,
    pub pdf_rev: f32,
    /// The MIS weight's ratio of the vertex's reverse density to its
    /// forward one, each 0 taken as 1 (pbrt-v3's `remap0`), set by
    /// [`finish_subpath`](super::mis_shared::finish_subpath) once the
    /// subpath is complete.
    pub ratio: f32,
    /// The way back to the previous vertex of the subpath (`None`: none,
    /// or coincident), set by
    /// [`finish_subpath`](super::mis_shared::finish_subpath).
    pub back: Option<Back>,
}

/// pbrt-v3's `remap0`: a density of 0 (a delta bounce) counts as 1 in
/// the MIS weight.
#[inline]
pub(crate) fn remap0(f: f32) -> f32 {
    if f != 0.0 {
        f
    } else {
        1.0
    }
}

impl<'a> Vertex<'a> {
    /// Exchanges everything but the BSDF and phase function with `other`:
    /// how a strategy's sampled camera or light vertex takes the place of
    /// the subpath's endpoint (neither scatters, so they have neither)
    /// without moving a BSDF's worth of bytes.
    pub fn swap_endpoint(&mut self, other: &mut Vertex<'a>) {
        use std::mem::swap;
        // Written out in full, so that a new field must be placed here.
        let Vertex {
            kind,
            beta,
            p,
            p_error,
            n,
            ns,
            wo,
            time,
            medium,
            media,
            light,
            bsdf: _,
            phase: _,
            delta,
            pdf_fwd,
            pdf_rev,
            ratio,
            back,
        } = self;
        swap(kind, &mut other.kind);
        swap(beta, &mut other.beta);
        swap(p, &mut other.p);
        swap(p_error, &mut other.p_error);
        swap(n, &mut other.n);
        swap(ns, &mut other.ns);
        swap(wo, &mut other.wo);
        swap(time, &mut other.time);
        swap(medium, &mut other.medium);
        swap(media, &mut other.media);
        swap(light, &mut other.light);
        swap(delta, &mut other.delta);
        swap(pdf_fwd, &mut other.pdf_fwd);
        swap(pdf_rev, &mut other.pdf_rev);
        swap(ratio, &mut other.ratio);
        swap(back, &mut other.back);
    }

    #[inline]
    pub fn on_surface(&self) -> bool {
        self.n != Vec3::ZERO
    }

    /// The medium a ray leaving the vertex towards `w` is in (pbrt-v3's
    /// `GetMedium(w)`).
    #[inline]
    pub fn medium_towards(&self, w: Vec3) -> Option<u32> {
        match self.media {
            Some(m) if w.dot(self.n) > 0.0 => m.outside,
            Some(m) => m.inside,
            None => self.medium,
        }
    }

    /// pbrt-v3's `IsLight`.
    #[inline]
    pub fn is_light(&self) -> bool {
        self.kind == Kind::Light || (self.kind == Kind::Surface && self.light.is_some())
    }

    /// pbrt-v3's `IsDeltaLight`.
    #[inline]
    pub fn is_delta_light(&self, c: &Ctx) -> bool {
        self.kind == Kind::Light
            && self
                .light
                .is_some_and(|i| c.scene.lights[i as usize].is_delta())
    }

    /// pbrt-v3's `IsInfiniteLight`: an escaped ray, an infinite light or
    /// a distant one.
    #[inline]
    pub fn is_infinite_light(&self, c: &Ctx) -> bool {
        self.kind == Kind::Light
            && self
                .light
                .is_none_or(|i| c.scene.lights[i as usize].at_infinity())
    }

    /// pbrt-v3's `IsConnectible`.
    #[inline]
    pub fn is_connectible(&self, c: &Ctx) -> bool {
        match self.kind {
            Kind::Medium | Kind::Camera => true,
            Kind::Light => self.light.is_none_or(|i| {
                let l = &c.scene.lights[i as usize];
                !(l.is_delta() && l.at_infinity())
            }),
            Kind::Surface => {
                self.bsdf.has_component(BxdfFlags(
                    BxdfFlags::DIFFUSE.0
                        | BxdfFlags::GLOSSY.0
                        | BxdfFlags::REFLECTION.0
                        | BxdfFlags::TRANSMISSION.0,
                ))
            }
        }
    }

    /// Scattering from `wo` towards `next` (pbrt-v3's `Vertex::f`), with
    /// the adjoint BSDF's corrections for importance: the shading normal's
    /// (pbrt-v3's `CorrectShadingNormal`) and, through a dielectric
    /// boundary, the (η_t/η_i)² that radiance's BTDFs divide by.
    ///
    /// Also returns the solid-angle density of sampling `next` from here
    /// having arrived along `wo` (what [`Vertex::pdf`] gives before its
    /// conversion to area, up to rounding in `wo`), which the MIS weight
    /// of the strategy connecting here needs; 0 off surfaces and media.
    pub fn f(&self, next: &Vertex, mode: Mode) -> (Vec3, f32) {
        let wi = next.p - self.p;
        if wi.length_squared() == 0.0 {
            return (Vec3::ZERO, 0.0);
        }
        self.f_towards(wi.normalize(), mode)
    }

    /// [`Vertex::f`] towards the unit direction `wi` (the next vertex's,
    /// normalized as `f` normalizes it).
    #[inline]
    pub fn f_towards(&self, wi: Vec3, mode: Mode) -> (Vec3, f32) {
        match self.kind {
            Kind::Surface => {
                let (f, pdf) = self.bsdf.f_pdf(self.wo, wi, BxdfFlags::ALL);
                let f = match mode {
                    Mode::Radiance => f,
                    Mode::Importance => {
                        let f = f + self.transmission_excess(wi);
                        f * correct_shading_normal(self, self.wo, wi)
                    }
                };
                (f, pdf)
            }
            Kind::Medium => {
                let p = self.phase.p(self.wo, wi);
                (Vec3::splat(p), p)
            }
            _ => (Vec3::ZERO, 0.0),
        }
    }

    /// Whether [`Vertex::pdf`] is a density of scattering (a surface or a
    /// medium), which [`Vertex::f`] gives with its value.
    #[inline]
    pub fn scatters(&self) -> bool {
        matches!(self.kind, Kind::Surface | Kind::Medium)
    }

    /// What importance's BTDF adds to radiance's for the pair (wo, wi)
    /// through a dielectric boundary: (s − 1)·f of the glossy transmission
    /// lobes, s = η² or 1/η² by the side of `wo` (as `sppm`'s photons).
    fn transmission_excess(&self, wi: Vec3) -> Vec3 {
        let eta = self.bsdf.eta;
        if eta == 1.0 || self.wo.dot(self.bsdf.ng) * wi.dot(self.bsdf.ng) >= 0.0 {
            return Vec3::ZERO;
        }
        let s = if self.wo.dot(self.bsdf.frame.n) > 0.0 {
            eta * eta
        } else {
            1.0 / (eta * eta)
        };
        let flags = BxdfFlags(BxdfFlags::TRANSMISSION.0 | BxdfFlags::GLOSSY.0);
        self.bsdf.f(self.wo, wi, flags) * (s - 1.0)
    }

    /// pbrt-v3's `ConvertDensity`: a solid-angle density at this vertex
    /// towards `next` as a density by area at `next` (unchanged towards a
    /// light at infinity).
    #[inline]
    pub fn convert_density(&self, pdf: f32, next: &Vertex, c: &Ctx) -> f32 {
        if next.is_infinite_light(c) {
            return pdf;
        }
        let w = next.p - self.p;
        let d2 = w.length_squared();
        if d2 == 0.0 {
            return 0.0;
        }
        let inv = 1.0 / d2;
        let mut pdf = pdf;
        if next.on_surface() {
            pdf *= next.n.dot(w * inv.sqrt()).abs();
        }
        pdf * inv
    }

    /// [`Vertex::convert_density`] across a [`Link`] from this vertex to
    /// `next` (or from `next` to this one: the terms are the same).
    #[inline]
    pub fn convert_density_across(&self, pdf: f32, next: &Vertex, link: &Link, c: &Ctx) -> f32 {
        if next.is_infinite_light(c) {
            return pdf;
        }
        let mut pdf = pdf;
        if next.on_surface() {
            pdf *= next.n.dot(link.dir).abs();
        }
        pdf * link.inv
    }

    /// pbrt-v3's `Vertex::Pdf`: the density of sampling `next` from this
    /// vertex, arrived at from `prev` (none for the camera), by area.
    pub fn pdf(&self, c: &Ctx, prev: Option<&Vertex>, next: &Vertex) -> f32 {
        if self.kind == Kind::Light {
            return self.pdf_light(c, next);
        }
        let wn = next.p - self.p;
        if wn.length_squared() == 0.0 {
            return 0.0;
        }
        let wn = wn.normalize();
        let wp = match prev {
            Some(v) => {
                let wp = v.p - self.p;
                if wp.length_squared() == 0.0 {
                    return 0.0;
                }
                wp.normalize()
            }
            None => Vec3::ZERO,
        };
        self.convert_density(self.pdf_dirs(c, wp, wn), next, c)
    }

    /// [`Vertex::pdf`] by solid angle, from the unit directions towards
    /// the previous vertex and the next.
    #[inline]
    pub fn pdf_dirs(&self, c: &Ctx, wp: Vec3, wn: Vec3) -> f32 {
        match self.kind {
            Kind::Camera => c.camera.pdf_we(self.p, wn, self.time).1,
            Kind::Surface => self.bsdf.pdf(wp, wn, BxdfFlags::ALL),
            Kind::Medium => self.phase.p(wp, wn),
            Kind::Light => 0.0,
        }
    }

    /// The light of a light vertex or an emitting surface.
    #[inline]
    fn light_index(&self) -> Option<u32> {
        self.light
    }

    /// pbrt-v3's `PdfLight`: the density of a light (this vertex) emitting
    /// towards `v`, by area at `v`.
    pub fn pdf_light(&self, c: &Ctx, v: &Vertex) -> f32 {
        let w = v.p - self.p;
        let inv = 1.0 / w.length_squared();
        let w = w * inv.sqrt();
        let mut pdf = if self.is_infinite_light(c) {
            let r = c.scene_radius;
            1.0 / (std::f32::consts::PI * r * r)
        } else {
            let Some(i) = self.light_index() else {
                return 0.0;
            };
            c.scene.lights[i as usize].pdf_le(w, self.n).1 * inv
        };
        if v.on_surface() {
            pdf *= v.n.dot(w).abs();
        }
        pdf
    }

    /// pbrt-v3's `PdfLightOrigin`: the density of choosing this light and
    /// the vertex on it, as the light subpath does.
    pub fn pdf_light_origin(&self, c: &Ctx, v: &Vertex) -> f32 {
        let w = v.p - self.p;
        if w.length_squared() == 0.0 {
            return 0.0;
        }
        let w = w.normalize();
        if self.is_infinite_light(c) {
            return c.infinite_light_density(w);
        }
        let Some(i) = self.light_index() else {
            return 0.0;
        };
        let pdf_pos = c.scene.lights[i as usize].pdf_le(w, self.n).0;
        pdf_pos * c.light_pmf(i)
    }

    /// pbrt-v3's `Vertex::Le`: the radiance this vertex (a light) emits
    /// towards `v`.
    pub fn le(&self, c: &Ctx, v: &Vertex) -> Vec3 {
        if !self.is_light() {
            return Vec3::ZERO;
        }
        let w = v.p - self.p;
        if w.length_squared() == 0.0 {
            return Vec3::ZERO;
        }
        let w = w.normalize();
        if self.is_infinite_light(c) {
            return escaped(c.scene, -w);
        }
        match self.light {
            Some(i) => c.scene.lights[i as usize].emitted(self.n, w),
            None => Vec3::ZERO,
        }
    }
}

/// The segment between a light subpath's vertex qs and a camera
/// subpath's pt that a strategy connects, with what its BSDF values,
/// geometry term and densities share: computed once, with the bits each
/// of them would compute on its own.
pub(crate) struct Link {
    /// From qs towards pt, normalized as [`Vertex::f`] normalizes it.
    pub wi: Vec3,
    /// 1 / squared distance.
    pub inv: f32,
    /// From qs towards pt as `G` and `ConvertDensity` normalize it.
    pub dir: Vec3,
}

impl Link {
    /// The link from `qs` to `pt` (or from any vertex to another); `None`
    /// if they are the same point.
    #[inline]
    pub fn new(qs: &Vertex, pt: &Vertex) -> Option<Link> {
        let w = pt.p - qs.p;
        let d2 = w.length_squared();
        if d2 == 0.0 {
            return None;
        }
        let inv = 1.0 / d2;
        Some(Link {
            wi: w.normalize(),
            inv,
            dir: w * inv.sqrt(),
        })
    }
}

/// pbrt-v3's `CorrectShadingNormal` for importance: |wo·ns||wi·ng| /
/// (|wo·ng||wi·ns|).
#[inline]
fn correct_shading_normal(v: &Vertex, wo: Vec3, wi: Vec3) -> f32 {
    if v.ns == v.n {
        // Numerator and denominator are the same product: 1, or 0 where it
        // is 0 (and NaN where it is not finite), without the division.
        let d = wo.dot(v.n).abs() * wi.dot(v.n).abs();
        return if d == 0.0 {
            0.0
        } else if d.is_finite() {
            1.0
        } else {
            f32::NAN
        };
    }
    let num = wo.dot(v.ns).abs() * wi.dot(v.n).abs();
    let denom = wo.dot(v.n).abs() * wi.dot(v.ns).abs();
    if denom == 0.0 {
        0.0
    } else {
        num / denom
    }
}

/// The state a random walk starts from.
pub(crate) struct Walk {
    pub ray: Ray,
    /// The first ray's differentials (camera subpaths), for the first
    /// hit's textures.
    pub diff: Option<RayDiff>,
    pub beta: Vec3,
    /// Solid-angle density of the first ray's direction.
    pub pdf: f32,
    pub medium: Option<u32>,
    pub time: f32,
    pub mode: Mode,
}

/// pbrt-v3's `RandomWalk`: extends `path` (which holds the subpath's
/// first vertex) by up to `max_depth` vertices. Returns the number added.
pub(crate) fn random_walk<'a>(
    c: &Ctx<'a>,
    w: Walk,
    max_depth: u32,
    path: &mut Vec<Vertex<'a>>,
    sampler: &mut Sampler,
    scratch: &mut Scratch,
) -> u32 {
    if max_depth == 0 {
        return 0;
    }
    let scene = c.scene;
    let Walk {
        mut ray,
        mut diff,
        mut beta,
        medium,
        time,
        mode,
        ..
    } = w;
    let mut medium = if scene.media.is_empty() { None } else { medium };
    let (mut bounces, mut crossed) = (0u32, 0u32);
    let mut pdf_fwd = w.pdf;
    let mut pdf_rev: f32;
    loop {
        scratch.counts.closest += 1;
        let hit = scene.aggregate.intersect_at(&ray, time);
        let mut scattered = None;
        if let Some(m) = medium {
            let med = &scene.media[m as usize];
            let segment = Ray {
                t_max: hit.as_ref().map_or(f32::INFINITY, |h| h.t),
                ..ray
            };
            let (wt, t) = med.sample(&segment, sampler);
            beta *= wt;
            scattered = t.map(|t| (t, med.phase));
        }
        if beta == Vec3::ZERO {
            break;
        }
        let prev = path.len() - 1;
        if let Some((t, phase)) = scattered {
            let p = ray.at(t);
            push_at(path, Kind::Medium, p, Vec3::ZERO, beta, (time, medium));
            let (before, new) = path.split_at_mut(prev + 1);
            let v = &mut new[0];
            v.wo = -ray.d.normalize();
            v.phase = phase;
            v.pdf_fwd = before[prev].convert_density(pdf_fwd, v, c);
            bounces += 1;
            if bounces >= max_depth {
                break;
            }
            let v = &path[prev + 1];
            let (wi, p_phase) = phase.sample(v.wo, sampler.get_2d());
            pdf_fwd = p_phase;
            pdf_rev = p_phase;
            ray = Ray::new(p, wi);
            diff = None;
        } else {
            let Some(h) = hit.as_ref() else {
                if mode == Mode::Radiance {
                    c.prefetch_sky(ray.d);
                    push_at(path, Kind::Light, ray.o + ray.d, -ray.d, beta, (time, medium));
                    path[prev + 1].pdf_fwd = pdf_fwd;
                    bounces += 1;
                }
                break;
            };
            let mut s = scene.aggregate.surface_at(h, time);
            let material = &scene.materials[s.material as usize];
            if material.is_none() {
                crossed += 1;
                if crossed > MAX_PASS_THROUGH {
                    break;
                }
                medium = medium_after(scene, &s, ray.d, medium);
                ray = spawn_ray(s.point.p, s.point.p_error, s.point.n, ray.d);
                continue;
            }
            push_at(path, Kind::Surface, s.point.p, s.point.n, beta, (time, medium));
            let (before, new) = path.split_at_mut(prev + 1);
            let v = &mut new[0];
            shade(
                scene,
                h,
                &mut s,
                material,
                true,
                diff.as_ref(),
                &mut v.bsdf,
            );
            diff = None;
            v.p_error = s.point.p_error;
            v.ns = s.point.ns;
            v.wo = -ray.d.normalize();
            v.light = s.light;
            v.media = scene
                .surface_media
                .get(s.material as usize)
                .copied()
                .flatten();
            v.pdf_fwd = before[prev].convert_density(pdf_fwd, v, c);
            bounces += 1;
            if bounces >= max_depth {
                break;
            }
            let v = &mut path[prev + 1];
            let wo = v.wo;
            let Some(bs) = v.bsdf.sample(wo, sampler.get_2d(), BxdfFlags::ALL) else {
                break;
            };
            if bs.f == Vec3::ZERO || bs.pdf == 0.0 {
                break;
            }
            pdf_fwd = bs.pdf;
            beta *= bs.f * bs.wi.dot(v.ns).abs() / bs.pdf;
            pdf_rev = v.bsdf.pdf(bs.wi, wo, BxdfFlags::ALL);
            if bs.is_specular() {
                v.delta = true;
                pdf_rev = 0.0;
                pdf_fwd = 0.0;
            }
            if mode == Mode::Importance {
                beta *= correct_shading_normal(v, wo, bs.wi) * eta_importance(&v.bsdf, &bs, wo);
            }
            medium = v.medium_towards(bs.wi);
            ray = spawn_ray(v.p, v.p_error, v.n, bs.wi);
        }
        let (a, b) = path.split_at_mut(prev + 1);
        a[prev].pdf_rev = b[0].convert_density(pdf_rev, &a[prev], c);
    }
    bounces
}
