//! Speed only: pbrt-v3's MIS weight (`MISWeight`) from what the
//! strategies through a subpath share, bit for bit the plain
//! [`mis_weight_plain`](super::connect) (tests/integrators_bdpt.rs renders
//! with both). pbrt-v3 writes each strategy's four new reverse densities
//! into the subpaths, sums the ratios of every other strategy's density to
//! this one's from scratch and restores them; here the subpaths are only
//! read, each vertex's ratio of reverse to forward density is divided once
//! per subpath ([`Vertex::ratio`]), and so is its way back to its
//! predecessor ([`Back`]), which the two densities back along the subpaths
//! need: a strategy divides only at the four vertices it changes and
//! evaluates one density each for those two.

use super::connect::Densities;
use super::vertex::{remap0, Link, Vertex};
use super::Ctx;
use glam::Vec3;

/// What the density of scattering from a vertex back to its predecessor
/// on the subpath needs that does not depend on where the vertex was
/// arrived at from (pbrt-v3 recomputes it in each strategy's MIS weight):
/// the direction, normalized as [`Vertex::pdf`] normalizes it, and
/// [`Vertex::convert_density`]'s factors.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Back {
    pub wn: Vec3,
    /// |cos| at the predecessor (1 off surfaces and at infinity).
    pub cos: f32,
    /// 1 / squared distance (1 to a light at infinity).
    pub inv: f32,
}

impl Back {
    /// The link from `v` back to `prev`, with `ConvertDensity`'s factors
    /// at `prev`.
    fn new(c: &Ctx, v: &Vertex, prev: &Vertex) -> Option<Back> {
        let link = Link::new(v, prev)?;
        if prev.is_infinite_light(c) {
            return Some(Back {
                wn: link.wi,
                cos: 1.0,
                inv: 1.0,
            });
        }
        let cos = if prev.on_surface() {
            prev.n.dot(link.dir).abs()
        } else {
            1.0
        };
        Some(Back {
            wn: link.wi,
            cos,
            inv: link.inv,
        })
    }
}

/// Sets what the MIS weights of the strategies through a complete
/// subpath's vertices share, once: each one's [`Vertex::ratio`], and
/// [`Vertex::back`] for those from `first_end` on, the ones that end a
/// connection (every vertex for bdpt, the last for one mlt strategy).
pub(crate) fn finish_subpath(c: &Ctx, path: &mut [Vertex], first_end: usize) {
    for i in 0..path.len() {
        let (before, rest) = path.split_at_mut(i);
        let v = &mut rest[0];
        v.ratio = remap0(v.pdf_rev) / remap0(v.pdf_fwd);
        v.back = if i >= first_end {
            before.last().and_then(|prev| Back::new(c, v, prev))
        } else {
            None
        };
    }
}

impl Vertex<'_> {
    /// [`Vertex::pdf`] of scattering back to the subpath's previous vertex
    /// (by [`Vertex::back`]), arrived at from the unit direction `wp`.
    #[inline]
    pub fn pdf_back(&self, c: &Ctx, wp: Vec3) -> f32 {
        let Some(b) = self.back else {
            return 0.0;
        };
        self.pdf_dirs(c, wp, b.wn) * b.cos * b.inv
    }
}

/// The unit direction from `v` to `to` as [`Vertex::pdf`] normalizes it;
/// `None` if they coincide.
#[inline]
fn towards(v: &Vertex, to: &Vertex) -> Option<Vec3> {
    let w = to.p - v.p;
    (w.length_squared() != 0.0).then(|| w.normalize())
}

/// pbrt-v3's `MISWeight`: the ratios of every other strategy's density
/// to this one's summed, with the reverse densities this strategy sets at
/// the two ends of each subpath (and their delta flags cleared) taken in
/// place of the stored ones, and a sampled endpoint (the last vertex of
/// `camera` for t = 1, of `light` for s = 1) in place of the subpath's
/// first. pbrt-v3 writes these into the subpaths and restores them; the
/// subpaths are only read here, in the same order of arithmetic. `link`:
/// the segment of an s, t ≥ 2 connection.
pub(super) fn mis_weight<'a>(
    c: &Ctx<'a>,
    light: &[Vertex<'a>],
    camera: &[Vertex<'a>],
    (sampled, link): (bool, Option<Link>),
    dens: Densities,
    s: usize,
    t: usize,
) -> f32 {
    if s + t == 2 {
        return 1.0;
    }
    // The vertices as this strategy sees them.
    let first_cam = if sampled && s != 1 {
        camera.len() - 1
    } else {
        0
    };
    let first_light = if sampled && s == 1 { light.len() - 1 } else { 0 };
    let cam = |i: usize| &camera[if i == 0 { first_cam } else { i }];
    let lig = |i: usize| &light[if i == 0 { first_light } else { i }];
    // The new reverse densities.
    let (qs, pt) = (s.checked_sub(1), t - 1);
    let (qs_m, pt_m) = (s.checked_sub(2), t.checked_sub(2));
    let (pt_rev, pt_m_rev, qs_rev, qs_m_rev) = match (link, dens, qs, pt_m, qs_m) {
        // s, t ≥ 2 with both ends scattering: the link gives the
        // directions between them.
        (
            Some(ln),
            Densities {
                at_qs: Some(pdf_q),
                at_pt: Some(pdf_p),
            },
            Some(q),
            Some(_),
            Some(_),
        ) => {
            let (pq, pp) = (lig(q), cam(pt));
            (
                pq.convert_density_across(pdf_q, pp, &ln, c),
                pp.pdf_back(c, -ln.wi),
                pp.convert_density_across(pdf_p, pq, &ln, c),
                pq.pdf_back(c, ln.wi),
            )
        }
        _ => (
            match qs {
                Some(q) => match dens.at_qs {
                    Some(pdf) => lig(q).convert_density(pdf, cam(pt), c),
                    None => lig(q).pdf(c, qs_m.map(lig), cam(pt)),
                },
                None => cam(pt).pdf_light_origin(c, cam(pt_m.unwrap_or(0))),
            },
            pt_m.map_or(0.0, |m| match qs {
                Some(q) => towards(cam(pt), lig(q)).map_or(0.0, |wp| cam(pt).pdf_back(c, wp)),
                None => cam(pt).pdf_light(c, cam(m)),
            }),
            qs.map_or(0.0, |q| match dens.at_pt {
                Some(pdf) => cam(pt).convert_density(pdf, lig(q), c),
                None => cam(pt).pdf(c, pt_m.map(cam), lig(q)),
            }),
            qs_m.map_or(0.0, |m| {
                towards(lig(m + 1), cam(pt)).map_or(0.0, |wp| lig(m + 1).pdf_back(c, wp))
            }),
        ),
    };

    // Each subpath's ratios from its connecting end back: the two
    // vertices whose reverse densities this strategy sets, then the
    // stored ratios.
    let mut sum_ri = 0.0f32;
    let mut ri = remap0(pt_rev) / remap0(cam(pt).pdf_fwd);
    if pt >= 1 {
        // t ≥ 2: the camera subpath as it is (only t = 1 samples its first
        // vertex anew), read without `cam`'s choice.
        let cv = &camera[..t];
        // pt's delta flag is cleared.
        if !cv[pt - 1].delta {
            sum_ri += ri;
        }
        if let Some(m) = pt_m.filter(|&m| m >= 1) {
            let v = &cv[m];
            ri *= remap0(pt_m_rev) / remap0(v.pdf_fwd);
            if !v.delta && !cv[m - 1].delta {
                sum_ri += ri;
            }
            // Vertex i with its predecessor, for i = m − 1 down to 1.
            for w in cv[..m].windows(2).rev() {
                ri *= w[1].ratio;
                if !w[1].delta && !w[0].delta {
                    sum_ri += ri;
                }
            }
        }
    }
    if let Some(q) = qs {
        let delta_before = |i: usize| {
            if i > 0 {
                lig(i - 1).delta
            } else {
                lig(0).is_delta_light(c)
            }
        };
        // qs's delta flag is cleared.
        ri = remap0(qs_rev) / remap0(lig(q).pdf_fwd);
        if !delta_before(q) {
            sum_ri += ri;
        }
        if let Some(m) = qs_m {
            // s ≥ 2: the light subpath as it is (only s = 1 samples its
            // first vertex anew).
            let lv = &light[..s];
            let v = &lv[m];
            ri *= remap0(qs_m_rev) / remap0(v.pdf_fwd);
            if !v.delta && !delta_before(m) {
                sum_ri += ri;
            }
            // Vertex i with its predecessor, for i = m − 1 down to 1, then
            // the light's own vertex.
            for w in lv[..m].windows(2).rev() {
                ri *= w[1].ratio;
                if !w[1].delta && !w[0].delta {
                    sum_ri += ri;
                }
            }
            if m >= 1 {
                ri *= lv[0].ratio;
                if !lv[0].delta && !delta_before(0) {
                    sum_ri += ri;
                }
            }
        }
    }
    1.0 / (1.0 + sum_ri)
}
