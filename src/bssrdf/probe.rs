//! Probe-ray sampling of a BSSRDF's exit point, pbrt-v3's
//! `SeparableBSSRDF::Sample_Sp` / `Pdf_Sp` (core/bssrdf.cpp), the geometric
//! part: choosing a projection axis and a channel from one uniform number,
//! the probe segment through the sampled disk point, and the combined
//! density of a found exit point over the three axes and three channels.
//!
//! The axes are the entry point's shading frame: the normal (probability
//! ½) and the two tangents (¼ each). A radius `r` is sampled from the
//! channel's profile and an angle φ uniformly; the probe is the chord of the
//! sphere of radius `r_max` (the channel's profile at u = 0.999) through
//! the disk point, along the axis: from `p + r(x cosφ + y sinφ) − (l/2) z`
//! to `+ (l/2) z`, `l = 2√(r_max² − r²)`.
//!
//! [`find_exit`] traces the probe (pbrt-v3's intersection chain) with the
//! error-bounded spawn functions, keeping hits of the entry point's
//! material, and picks one uniformly. pbrt-v3 stores the chain in its
//! arena; to allocate nothing, pbrs traces the probe twice: once to count
//! the admissible hits, once to stop at the chosen one (same choice, same
//! hit, twice the probe rays).

use super::tabulated::TabulatedBssrdf;
use crate::accel::{Aggregate, SurfaceHit};
use crate::geometry::{spawn_ray_to_point, Frame, Ray, SHADOW_EPSILON};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// The probability of projecting along the normal, the tangent `s` and the
/// tangent `t` (pbrt-v3's `axisProb` is listed in the order s, t, n).
const AXIS_PROB: [f32; 3] = [0.25, 0.25, 0.5];

/// A probe segment for one exit-point sample, and what the choice of the
/// intersection along it needs.
#[derive(Clone, Copy, Debug)]
pub struct ProbeSegment {
    /// Start and end of the chord (trace from `start` towards `end`).
    pub start: Vec3,
    pub end: Vec3,
    /// What is left of the uniform number after choosing the axis and the
    /// channel: choose the `floor(u_choice · found)`-th admissible hit.
    pub u_choice: f32,
    pub channel: usize,
}

/// pbrt-v3's choice of axis, channel, radius and angle: the probe segment
/// at entry point `po` with shading frame `frame`, or `None` when the
/// profile has no sample there (σt 0) or the radius falls outside r_max.
pub fn probe_segment(
    bssrdf: &TabulatedBssrdf,
    po: Vec3,
    frame: &Frame,
    u1: f32,
    u2: Vec2,
) -> Option<ProbeSegment> {
    let (vx, vy, vz, mut u1) = if u1 < 0.5 {
        (frame.s, frame.t, frame.n, u1 * 2.0)
    } else if u1 < 0.75 {
        (frame.t, frame.n, frame.s, (u1 - 0.5) * 4.0)
    } else {
        (frame.n, frame.s, frame.t, (u1 - 0.75) * 4.0)
    };
    let ch = ((u1 * 3.0) as i32).clamp(0, 2) as usize;
    u1 = u1 * 3.0 - ch as f32;
    let r = bssrdf.sample_sr(ch, u2.x)?;
    if r < 0.0 {
        return None;
    }
    let phi = 2.0 * PI * u2.y;
    let r_max = bssrdf.sample_sr(ch, 0.999)?;
    if r >= r_max {
        return None;
    }
    let l = 2.0 * (r_max * r_max - r * r).sqrt();
    let start = po + r * (vx * phi.cos() + vy * phi.sin()) - l * vz * 0.5;
    Some(ProbeSegment {
        start,
        end: start + l * vz,
        u_choice: u1,
        channel: ch,
    })
}

/// Hits along one probe beyond which the walk stops (pbrt-v3 has no bound;
/// a closed surface crosses a chord a handful of times).
const MAX_PROBE_HITS: u32 = 64;

/// Walks the probe from `seg.start` to `seg.end` at `time`, calling
/// `visit(k, hit)` with the running count `k` of admissible hits (of
/// `material`) for each; stops when `visit` returns true. Returns the
/// number of admissible hits seen.
fn walk(
    geometry: &Aggregate,
    seg: &ProbeSegment,
    material: u32,
    time: f32,
    rays: &mut u64,
    mut visit: impl FnMut(u32, &SurfaceHit) -> bool,
) -> u32 {
    // The first ray leaves a point in space (pbrt-v3's bare Interaction:
    // no error bounds, no offset).
    let mut ray = Ray {
        o: seg.start,
        d: seg.end - seg.start,
        t_max: 1.0 - SHADOW_EPSILON,
    };
    let mut found = 0;
    for _ in 0..MAX_PROBE_HITS {
        if ray.d == Vec3::ZERO {
            break;
        }
        *rays += 1;
        let Some(hit) = geometry.intersect_at(&ray, time) else {
            break;
        };
        let s = geometry.surface_at(&hit, time);
        if s.material == material {
            if visit(found, &s) {
                return found + 1;
            }
            found += 1;
        }
        ray = spawn_ray_to_point(s.point.p, s.point.p_error, s.point.n, seg.end);
    }
    found
}

/// pbrt-v3's choice of one exit point along the probe: the admissible hits
/// (same `material` as the entry point) and the chosen one, or `None` if
/// the probe finds none. The caller divides [`pdf_sp`] by the count.
/// `rays` counts the probe rays traced.
pub fn find_exit(
    geometry: &Aggregate,
    seg: &ProbeSegment,
    material: u32,
    time: f32,
    rays: &mut u64,
) -> Option<(SurfaceHit, u32)> {
    let n = walk(geometry, seg, material, time, rays, |_, _| false);
    if n == 0 {
        return None;
    }
    let selected = ((seg.u_choice * n as f32) as u32).min(n - 1);
    let mut chosen = None;
    walk(geometry, seg, material, time, rays, |k, s| {
        if k == selected {
            chosen = Some(*s);
            true
        } else {
            false
        }
    });
    chosen.map(|s| (s, n))
}

/// pbrt-v3's `Pdf_Sp`: the density (per unit area) of having sampled exit
/// point `pi` with geometric normal `ni` from entry point `po` with shading
/// frame `frame`, summed over the three axes and channels (before dividing
/// by the number of admissible hits along the probe).
pub fn pdf_sp(bssrdf: &TabulatedBssrdf, po: Vec3, frame: &Frame, pi: Vec3, ni: Vec3) -> f32 {
    let d = po - pi;
    let dl = Vec3::new(frame.s.dot(d), frame.t.dot(d), frame.n.dot(d));
    let nl = Vec3::new(frame.s.dot(ni), frame.t.dot(ni), frame.n.dot(ni));
    let r_proj = [
        (dl.y * dl.y + dl.z * dl.z).sqrt(),
        (dl.z * dl.z + dl.x * dl.x).sqrt(),
        (dl.x * dl.x + dl.y * dl.y).sqrt(),
    ];
    let mut pdf = 0.0;
    for axis in 0..3 {
        for ch in 0..3 {
            pdf += bssrdf.pdf_sr(ch, r_proj[axis]) * nl[axis].abs() * AXIS_PROB[axis] / 3.0;
        }
    }
    pdf
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bssrdf::BssrdfTable;
    use crate::sampling::Pcg32;

    #[test]
    fn on_a_plane_the_probes_along_the_normal_hit_where_pdf_sp_says() {
        // Entry point on the plane z = 0, frame = the plane's. A probe along
        // the normal crosses the plane at its disk point; integrating
        // pdf_sp over the plane gives the probability that the sample is a
        // normal-axis probe whose point lies on the plane within r_max:
        // the tangent axes' probes lie in the plane and never cross it
        // transversally (their |n_local| factor is 0 there).
        let table = BssrdfTable::beam_diffusion(0.0, 1.33);
        let b = TabulatedBssrdf::new(&table, Vec3::splat(0.1), Vec3::splat(1.0), 1.33);
        let frame = Frame {
            s: Vec3::X,
            t: Vec3::Y,
            n: Vec3::Z,
        };
        // Monte Carlo of ∫ pdf_sp dA over the plane, by polar sampling.
        let r_max = b.sample_sr(0, 0.999).unwrap();
        let mut rng = Pcg32::with_sequence(7);
        let n = 200_000;
        let mut sum = 0.0f64;
        for _ in 0..n {
            let r = r_max * 3.0 * rng.uniform_f32();
            let phi = 2.0 * PI * rng.uniform_f32();
            let pi = Vec3::new(r * phi.cos(), r * phi.sin(), 0.0);
            let area = (2.0 * PI * r * r_max * 3.0) as f64;
            sum += pdf_sp(&b, Vec3::ZERO, &frame, pi, Vec3::Z) as f64 * area;
        }
        let total = sum / n as f64;
        // The normal axis (½) times the profile's mass inside r_max (0.999).
        assert!((total - 0.5).abs() < 0.01, "{total}");

        // And every normal-axis probe crosses the plane at distance r.
        for k in 0..100 {
            let u1 = (k as f32 + 0.5) / 200.0; // < ½: the normal axis
            let u2 = Vec2::new(
                ((k * 37) % 100) as f32 / 100.0,
                ((k * 61) % 100) as f32 / 100.0,
            );
            if let Some(seg) = probe_segment(&b, Vec3::ZERO, &frame, u1, u2) {
                assert!(seg.start.z < 0.0 && seg.end.z > 0.0);
                assert!((seg.start.x - seg.end.x).abs() < 1e-6);
                assert!(seg.channel < 3 && (0.0..1.0).contains(&seg.u_choice));
                assert!(seg.start.truncate().length() < r_max);
            }
        }
    }
}
