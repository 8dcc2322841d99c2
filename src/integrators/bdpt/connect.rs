//! Connecting a light subpath's first s vertices to a camera subpath's
//! first t (pbrt-v3's `ConnectBDPT`), and the power-heuristic weight of
//! that strategy against every other that could have made the same path
//! (pbrt-v3's `MISWeight`, with its remapping of delta densities to 1).

use super::mis_shared;
use super::vertex::{push_at, remap0, Kind, Link, Mode, Vertex};
use super::Ctx;
use crate::geometry::{spawn_ray_to, Ray};
use crate::integrators::volpath::transmittance;
use crate::integrators::Scratch;
use crate::lights::{EnvSample, Light};
use crate::samplers::Sampler;
use glam::{Vec2, Vec3};

/// What one strategy gives: its weighted contribution, its MIS weight and,
/// for t = 1, where on the film it lands.
pub(crate) struct Strategy {
    pub l: Vec3,
    pub weight: f32,
    pub p_raster: Option<Vec2>,
}

/// Transmittance between two vertices (pbrt-v3's `VisibilityTester::Tr`):
/// 0 if a surface is in the way, else that of the media crossed.
fn tr(c: &Ctx, a: &Vertex, b: &Vertex, sampler: &mut Sampler, scratch: &mut Scratch) -> Vec3 {
    let ray = spawn_ray_to(a.p, a.p_error, a.n, b.p, b.p_error, b.n);
    let medium = if c.scene.media.is_empty() {
        None
    } else {
        a.medium_towards(b.p - a.p)
    };
    transmittance(c.scene, &ray, a.time, medium, sampler, scratch)
}

/// pbrt-v3's `G`: the geometry term across the link from `v0` to `v1`,
/// with their transmittance.
fn g(
    c: &Ctx,
    (v0, v1): (&Vertex, &Vertex),
    link: &Link,
    sampler: &mut Sampler,
    scratch: &mut Scratch,
) -> Vec3 {
    let mut g = link.inv;
    if v0.on_surface() {
        g *= v0.ns.dot(link.dir).abs();
    }
    if v1.on_surface() {
        g *= v1.ns.dot(link.dir).abs();
    }
    g * tr(c, v0, v1, sampler, scratch)
}

/// The sample values of an s = 1 strategy: the light chosen (with its
/// probability) and the 2D value of its sample; for an infinite light,
/// possibly its sample already taken (`EnvMap::sample`, which does not
/// depend on the vertex it is taken from).
#[derive(Clone, Copy)]
pub(crate) struct LightDraw {
    pub chosen: Option<(u32, f32)>,
    pub u: Vec2,
    pub env: Option<Option<EnvSample>>,
}

/// Draws an s = 1 strategy's values as pbrt-v3 does: the light choice,
/// then the light sample's 2D value.
pub(super) fn draw_light(c: &Ctx, sampler: &mut Sampler) -> LightDraw {
    let u = sampler.get_1d();
    let chosen = c.lights.sample(
        c.p_camera,
        Vec3::ZERO,
        u,
        &c.scene.lights,
        &c.scene.aggregate,
    );
    LightDraw {
        chosen,
        u: sampler.get_2d(),
        env: None,
    }
}

/// Strategy (s, t) over the subpaths `light` and `camera`. A strategy
/// that samples a new endpoint (t = 1: a camera vertex, s = 1: a light
/// vertex) builds it past the end of that subpath, which is as long as it
/// was again when this returns. `drawn`: an s = 1 strategy's values if
/// they were drawn ahead (`draw_ahead`); without them it draws its own.
pub(crate) fn connect<'a>(
    c: &Ctx<'a>,
    light: &mut Vec<Vertex<'a>>,
    camera: &mut Vec<Vertex<'a>>,
    (s, t): (usize, usize),
    drawn: Option<LightDraw>,
    sampler: &mut Sampler,
    scratch: &mut Scratch,
) -> Strategy {
    let (n_light, n_camera) = (light.len(), camera.len());
    debug_assert!(s <= n_light && t <= n_camera);
    let none = Strategy {
        l: Vec3::ZERO,
        weight: 0.0,
        p_raster: None,
    };
    if t > 1 && s != 0 && camera[t - 1].kind == Kind::Light {
        return none;
    }
    let e = if s == 0 {
        emitted(c, &camera[t - 1], &camera[t.saturating_sub(2)])
    } else if t == 1 {
        to_camera(c, &light[s - 1], camera, sampler, scratch)
    } else if s == 1 {
        to_light(c, &camera[t - 1], light, drawn, sampler, scratch)
    } else {
        between(c, &light[s - 1], &camera[t - 1], sampler, scratch)
    };
    let Ends {
        l,
        sampled,
        p_raster,
        dens,
        link,
    } = e;
    let weight = if l == Vec3::ZERO {
        0.0
    } else if c.plain {
        mis_weight_plain(c, light, camera, sampled, dens, s, t)
    } else {
        mis_shared::mis_weight(c, light, camera, (sampled, link), dens, s, t)
    };
    // A sampled endpoint goes again (the one early return comes before
    // anything is pushed).
    light.truncate(n_light);
    camera.truncate(n_camera);
    Strategy {
        l: l * weight,
        weight,
        p_raster,
    }
}

/// What a strategy's connection found: its unweighted contribution
/// `l`, whether a sampled endpoint was pushed (onto `camera` for t = 1,
/// else onto `light`, to take the place of the subpath's own for the MIS
/// weight), the film position of a t = 1 strategy, the densities across
/// the connection ([`Densities`]) and the segment of an s, t ≥ 2
/// connection.
#[derive(Default)]
struct Ends {
    l: Vec3,
    sampled: bool,
    p_raster: Option<Vec2>,
    dens: Densities,
    link: Option<Link>,
}

/// s = 0: the camera subpath's last vertex `pt` (reached from `prev`)
/// if it emits.
#[inline(never)]
fn emitted(c: &Ctx, pt: &Vertex, prev: &Vertex) -> Ends {
    let mut e = Ends::default();
    if pt.is_light() {
        e.l = pt.le(c, prev) * pt.beta;
    }
    e
}

/// t = 1: the light subpath's last vertex `qs` seen by a camera vertex
/// sampled from it (pushed onto `camera`).
#[inline(never)]
fn to_camera<'a>(
    c: &Ctx<'a>,
    qs: &Vertex<'a>,
    camera: &mut Vec<Vertex<'a>>,
    sampler: &mut Sampler,
    scratch: &mut Scratch,
) -> Ends {
    let mut e = Ends::default();
    if !qs.is_connectible(c) {
        return e;
    }
    let u = sampler.get_2d();
    let Some(is) = c.camera.sample_wi(qs.p, u, qs.time) else {
        return e;
    };
    e.p_raster = Some(is.p_raster);
    if is.pdf > 0.0 && is.we != Vec3::ZERO {
        push_at(
            camera,
            Kind::Camera,
            is.p_lens,
            is.n,
            is.we / is.pdf,
            (qs.time, c.camera_medium),
        );
        e.sampled = true;
        let v = &camera[camera.len() - 1];
        // `wi` is the direction `Vertex::f` would normalize towards the
        // lens point, to the bit.
        let (f, pdf) = qs.f_towards(is.wi, Mode::Importance);
        e.dens.at_qs = qs.scatters().then_some(pdf);
        // The camera's density towards qs, as `Vertex::pdf` would find it
        // (its direction, normalized, is -wi to the bit).
        e.dens.at_pt = Some(is.pdf_dir);
        let mut l = qs.beta * f * v.beta;
        if qs.on_surface() {
            l *= is.wi.dot(qs.ns).abs();
        }
        if l != Vec3::ZERO {
            l *= tr(c, qs, v, sampler, scratch);
        }
        e.l = l;
    }
    e
}

/// s = 1: the camera subpath's last vertex `pt` lit by a light vertex
/// sampled from it (pushed onto `light`), from `drawn` or drawn here.
#[inline(never)]
fn to_light<'a>(
    c: &Ctx<'a>,
    pt: &Vertex<'a>,
    light: &mut Vec<Vertex<'a>>,
    drawn: Option<LightDraw>,
    sampler: &mut Sampler,
    scratch: &mut Scratch,
) -> Ends {
    let mut e = Ends::default();
    if !pt.is_connectible(c) {
        return e;
    }
    let d = drawn.unwrap_or_else(|| draw_light(c, sampler));
    let Some((i, pmf)) = d.chosen else {
        return e;
    };
    let Some((shadow, wi)) = light_vertex(c, pt, (i, pmf), d, light) else {
        return e;
    };
    e.sampled = true;
    let v = &light[light.len() - 1];
    let (f, pdf) = pt.f(v, Mode::Radiance);
    e.dens.at_pt = pt.scatters().then_some(pdf);
    let mut l = pt.beta * f * v.beta;
    if pt.on_surface() {
        l *= wi.dot(pt.ns).abs();
    }
    if l != Vec3::ZERO {
        let medium = pt.medium_towards(wi);
        l *= transmittance(c.scene, &shadow, pt.time, medium, sampler, scratch);
    }
    e.l = l;
    e
}

/// s, t ≥ 2: the subpaths' last vertices `qs` and `pt` joined.
#[inline(always)]
fn between(
    c: &Ctx,
    qs: &Vertex,
    pt: &Vertex,
    sampler: &mut Sampler,
    scratch: &mut Scratch,
) -> Ends {
    let mut e = Ends::default();
    if !(qs.is_connectible(c) && pt.is_connectible(c)) {
        return e;
    }
    // Coincident vertices: no BSDF value (as `Vertex::f`).
    let Some(ln) = Link::new(qs, pt) else {
        return e;
    };
    let (fq, pdf_q) = qs.f_towards(ln.wi, Mode::Importance);
    let (fp, pdf_p) = pt.f_towards(-ln.wi, Mode::Radiance);
    e.dens.at_qs = qs.scatters().then_some(pdf_q);
    e.dens.at_pt = pt.scatters().then_some(pdf_p);
    let mut l = qs.beta * fq * fp * pt.beta;
    if l != Vec3::ZERO {
        l *= g(c, (qs, pt), &ln, sampler, scratch);
    }
    e.l = l;
    e.link = Some(ln);
    e
}

/// Solid-angle densities of scattering across the connection, where the
/// connection's BSDF evaluations gave them (or, for the camera vertex a
/// t = 1 strategy samples, its importance sample).
#[derive(Clone, Copy, Default)]
pub(super) struct Densities {
    /// At the light subpath's end (qs) towards the camera subpath's (pt),
    /// arriving from qs's predecessor.
    pub at_qs: Option<f32>,
    /// At pt towards qs, arriving from pt's predecessor.
    pub at_pt: Option<f32>,
}

/// The light vertex of the s = 1 strategy, pushed onto `path`: light `i`
/// (chosen with probability `pmf`) sampled from `pt` (pbrt-v3's
/// `Sample_Li`), with its density of origin; returns its shadow ray and
/// direction.
fn light_vertex<'a>(
    c: &Ctx<'a>,
    pt: &Vertex<'a>,
    (i, pmf): (u32, f32),
    d: LightDraw,
    path: &mut Vec<Vertex<'a>>,
) -> Option<(Ray, Vec3)> {
    let light = &c.scene.lights[i as usize];
    let r = crate::shapes::SurfacePoint {
        p: pt.p,
        p_error: pt.p_error,
        n: pt.n,
        ns: pt.ns,
    };
    let (ls, p, n) = match light {
        Light::Diffuse(l) => l.sample_li_at(&r, d.u, &c.scene.aggregate)?,
        _ => {
            let ls = match (light, d.env) {
                (Light::Infinite(l), Some(env)) => l.sample_li_from(&r, env)?,
                _ => light.sample_li(&r, d.u, &c.scene.aggregate)?,
            };
            let p = if ls.shadow.t_max.is_finite() {
                ls.shadow.o + ls.shadow.d
            } else {
                pt.p + ls.wi
            };
            (ls, p, Vec3::ZERO)
        }
    };
    if ls.pdf.is_nan() || ls.pdf <= 0.0 || ls.li == Vec3::ZERO {
        return None;
    }
    push_at(
        path,
        Kind::Light,
        p,
        n,
        ls.li / (ls.pdf * pmf),
        (pt.time, None),
    );
    let v = path.last_mut().expect("just pushed");
    v.light = Some(i);
    v.pdf_fwd = v.pdf_light_origin(c, pt);
    Some((ls.shadow, ls.wi))
}

/// pbrt-v3's `MISWeight` as it computes it, the plain code that
/// [`mis_shared::mis_weight`] is tested against: the subpaths' reverse
/// densities are set for this strategy (and a sampled endpoint, the last
/// vertex of `camera` for t = 1 and of `light` for s = 1, put in place),
/// the ratios of every other strategy's density to this one's summed, and
/// the subpaths restored.
#[cold]
#[inline(never)]
fn mis_weight_plain<'a>(
    c: &Ctx<'a>,
    light: &mut [Vertex<'a>],
    camera: &mut [Vertex<'a>],
    sampled: bool,
    dens: Densities,
    s: usize,
    t: usize,
) -> f32 {
    if s + t == 2 {
        return 1.0;
    }
    // The sampled endpoint replaces the subpath's.
    if sampled {
        swap_sampled_endpoint(if s == 1 { light } else { camera });
    }
    // The new reverse densities, computed before any is set.
    let (qs, pt) = (s.checked_sub(1), t - 1);
    let (qs_m, pt_m) = (s.checked_sub(2), t.checked_sub(2));
    let pt_rev = match qs {
        Some(q) => match dens.at_qs {
            Some(pdf) => light[q].convert_density(pdf, &camera[pt], c),
            None => light[q].pdf(c, qs_m.map(|i| &light[i]), &camera[pt]),
        },
        None => camera[pt].pdf_light_origin(c, &camera[pt_m.unwrap_or(0)]),
    };
    let pt_m_rev = pt_m.map(|m| match qs {
        Some(q) => camera[pt].pdf(c, Some(&light[q]), &camera[m]),
        None => camera[pt].pdf_light(c, &camera[m]),
    });
    let qs_rev = qs.map(|q| match dens.at_pt {
        Some(pdf) => camera[pt].convert_density(pdf, &light[q], c),
        None => camera[pt].pdf(c, pt_m.map(|i| &camera[i]), &light[q]),
    });
    let qs_m_rev = qs_m.map(|m| light[m + 1].pdf(c, Some(&camera[pt]), &light[m]));
    // Set them (and clear the endpoints' delta flags), keeping the old.
    let saved_pt = (camera[pt].pdf_rev, camera[pt].delta);
    camera[pt].pdf_rev = pt_rev;
    camera[pt].delta = false;
    let saved_pt_m =
        pt_m.map(|m| std::mem::replace(&mut camera[m].pdf_rev, pt_m_rev.unwrap_or(0.0)));
    let saved_qs = qs.map(|q| {
        let old = (light[q].pdf_rev, light[q].delta);
        light[q].pdf_rev = qs_rev.unwrap_or(0.0);
        light[q].delta = false;
        old
    });
    let saved_qs_m =
        qs_m.map(|m| std::mem::replace(&mut light[m].pdf_rev, qs_m_rev.unwrap_or(0.0)));

    let mut sum_ri = 0.0f32;
    let mut ri = 1.0f32;
    for i in (1..t).rev() {
        ri *= remap0(camera[i].pdf_rev) / remap0(camera[i].pdf_fwd);
        if !camera[i].delta && !camera[i - 1].delta {
            sum_ri += ri;
        }
    }
    ri = 1.0;
    for i in (0..s).rev() {
        ri *= remap0(light[i].pdf_rev) / remap0(light[i].pdf_fwd);
        let delta_light = if i > 0 {
            light[i - 1].delta
        } else {
            light[0].is_delta_light(c)
        };
        if !light[i].delta && !delta_light {
            sum_ri += ri;
        }
    }

    // Restore.
    (camera[pt].pdf_rev, camera[pt].delta) = saved_pt;
    if let (Some(m), Some(v)) = (pt_m, saved_pt_m) {
        camera[m].pdf_rev = v;
    }
    if let (Some(q), Some((r, d))) = (qs, saved_qs) {
        light[q].pdf_rev = r;
        light[q].delta = d;
    }
    if let (Some(m), Some(v)) = (qs_m, saved_qs_m) {
        light[m].pdf_rev = v;
    }
    if sampled {
        swap_sampled_endpoint(if s == 1 { light } else { camera });
    }
    1.0 / (1.0 + sum_ri)
}

/// Exchanges a subpath's first vertex with the sampled endpoint at its end.
fn swap_sampled_endpoint(path: &mut [Vertex]) {
    let (first, rest) = path.split_at_mut(1);
    let last = rest.last_mut().expect("a sampled endpoint past the first");
    first[0].swap_endpoint(last);
}
