//! `MakeNamedMedium "name" "string type" "heterogeneous"`: pbrt-v3's
//! `GridDensityMedium` (src/media/grid.{h,cpp}): coefficients times a
//! density interpolated trilinearly in a grid over the unit cube of the
//! medium's space.
//!
//! Parameters (read by `loader::medium` through [`KIND`]'s table), besides
//! the homogeneous medium's `sigma_a`, `sigma_s`, `preset`, `scale`, `g`:
//! - `float density` nx·ny·nz values, x fastest, then y, then z (required;
//!   another length is an error, as in pbrt-v3)
//! - `integer nx`, `ny`, `nz` the grid's resolution (default 1 each)
//! - `point3 p0`, `p1` the corners of the grid's box in the space current
//!   at `MakeNamedMedium` (default 0 0 0 and 1 1 1)
//!
//! σt = σa + σs must be the same in every channel (pbrt-v3 reports an
//! error and uses the first channel's; pbrs warns and does the same).
//! Scattering is sampled by delta tracking, transmittance estimated by
//! ratio tracking with pbrt-v3's Russian roulette below 0.1, each drawing
//! from the sampler as pbrt-v3. Both step cell by cell through a majorant
//! grid ([`super::majorant`], as pbrt-v4) by each cell's largest density;
//! `"integer majorantgrid" 1` (a pbrs extension) tracks against the whole
//! grid's largest density alone, as pbrt-v3 does.

use super::majorant::Majorants;
use super::{fix, Coefficients, Density, Medium, MediumInput, MediumType, Support, COMMON};
use crate::geometry::{gamma, Ray};
use crate::samplers::Sampler;
use crate::scene::bounds::{note_cut, Cut, MAX_TRACKING_STEPS};
use crate::scene::{ParamSpec, ParamValues, Report};
use glam::{DMat4, Mat4, Vec3};
use std::sync::Arc;

/// The most voxels a density grid may have (1 GiB of f32).
pub const MAX_GRID_VOXELS: i64 = 1 << 28;

pub const KIND: MediumType = MediumType {
    name: "heterogeneous",
    aliases: &[],
    support: Support::Supported,
    params: &[
        COMMON[0],
        COMMON[1],
        COMMON[2],
        COMMON[3],
        COMMON[4],
        ParamSpec::floats("density", "nx·ny·nz densities, x fastest (required)"),
        ParamSpec::int("nx", 1, "grid resolution in x"),
        ParamSpec::int("ny", 1, "grid resolution in y"),
        ParamSpec::int("nz", 1, "grid resolution in z"),
        ParamSpec::point3("p0", [0.0; 3], "the grid box's first corner"),
        ParamSpec::point3("p1", [1.0; 3], "the grid box's opposite corner"),
        ParamSpec::int(
            "majorantgrid",
            16,
            "pbrs extension: cells per axis (at most the grid's voxels) of the grid of local largest densities that tracking steps by; 1 steps by the largest density alone, as pbrt-v3",
        ),
    ],
    doc: "a density grid scaling the coefficients, trilinearly interpolated (pbrt-v3's GridDensityMedium)",
    build,
};

/// pbrt-v3's `GridDensityMedium` checks: `density` with nx·ny·nz finite,
/// non-negative values (within the memory budget), one attenuation
/// coefficient, a box p0…p1 of some extent in the current space.
fn build(p: &ParamValues, input: &MediumInput, r: &mut dyn Report) -> Option<Medium> {
    let what = format!("MakeNamedMedium \"{}\"", input.name);
    let c = Coefficients::read(p, &what, r);
    if !p.given("density") {
        r.error(
            None,
            format!("{what}: a heterogeneous medium needs \"float density\" values (pbrt-v3: \"No density values provided\")"),
            "no \"float density\"",
        );
        return None;
    }
    let mut n = [0i64; 3];
    for (i, axis) in ["nx", "ny", "nz"].into_iter().enumerate() {
        let v = p.int(axis) as i64;
        if v < 1 {
            r.error(
                Some(axis),
                format!(
                    "{what}: \"{axis}\" is {v}: the grid needs at least one voxel along each axis"
                ),
                "must be ≥ 1",
            );
            return None;
        }
        n[i] = v;
    }
    let voxels = n[0].saturating_mul(n[1]).saturating_mul(n[2]);
    let values = p.floats("density");
    if voxels > MAX_GRID_VOXELS || values.len() as i64 != voxels {
        let why = if voxels > MAX_GRID_VOXELS {
            format!(
                "{} × {} × {} voxels is more than pbrs takes ({MAX_GRID_VOXELS})",
                n[0], n[1], n[2]
            )
        } else {
            format!(
                "\"density\" has {} values; nx·ny·nz = {} × {} × {} = {voxels} expected (pbrt-v3 reports the same error)",
                values.len(),
                n[0],
                n[1],
                n[2]
            )
        };
        r.error(
            Some("density"),
            format!("{what}: {why}"),
            "wrong number of densities",
        );
        return None;
    }
    if let Err(why) = crate::scene::memory::check_budget(
        &format!("{what}: the {} × {} × {} density grid", n[0], n[1], n[2]),
        (voxels as u64).saturating_mul(4),
    ) {
        r.error(Some("density"), why, "too large for this machine");
        return None;
    }
    let mut density: Vec<f32> = values.iter().map(|&v| v as f32).collect();
    if density.iter().any(|d| !(d.is_finite() && *d >= 0.0)) {
        r.warn(
            Some("density"),
            format!("{what}: negative or non-finite densities are set to 0"),
            "densities must be finite and ≥ 0",
        );
        for d in &mut density {
            *d = fix(*d);
        }
    }
    let sigma_t = c.sigma_a + c.sigma_s;
    if sigma_t.x != sigma_t.y || sigma_t.x != sigma_t.z {
        let at = ["sigma_a", "sigma_s", "preset"]
            .into_iter()
            .find(|n| p.given(n));
        r.warn(
            at,
            format!("{what}: sigma_a + sigma_s = {} {} {} differs by channel: a heterogeneous medium needs one attenuation coefficient (pbrt-v3 reports an error and uses the first channel's, as pbrs does)", sigma_t.x, sigma_t.y, sigma_t.z),
            "spectrally varying attenuation",
        );
    }
    let cells = p.int("majorantgrid");
    if cells < 1 {
        r.error(
            Some("majorantgrid"),
            format!("{what}: \"majorantgrid\" is {cells}: the majorant grid needs at least one cell per axis"),
            "must be ≥ 1",
        );
        return None;
    }
    let (p0, p1) = (p.point("p0"), p.point("p1"));
    let data_to_medium = DMat4::from_translation(p0) * DMat4::from_scale(p1 - p0);
    let medium_to_world = input.ctm * data_to_medium;
    if !medium_to_world.is_finite() || medium_to_world.determinant() == 0.0 {
        r.error(
            None,
            format!("{what}: the grid's box p0…p1 in the current transform is degenerate (zero extent along an axis, or a singular transform)"),
            "degenerate grid box",
        );
        return None;
    }
    let grid = Grid::new(
        c.sigma_a,
        c.sigma_s,
        [n[0] as u32, n[1] as u32, n[2] as u32],
        Arc::new(density),
        medium_to_world.inverse().as_mat4(),
        cells,
    );
    Some(Medium::new(input.name, c, Density::Grid(grid)))
}

/// How tracking along a ray ended.
enum Tracked<R> {
    /// Where the callback stopped it, with what it said.
    Stopped(R),
    /// Past the ray's end.
    Through,
    /// Past [`MAX_TRACKING_STEPS`].
    Cut,
}

#[derive(Clone, Debug)]
pub struct Grid {
    pub sigma_s: Vec3,
    /// σt of the first channel (pbrt-v3 requires all three equal).
    pub sigma_t: f32,
    pub n: [i32; 3],
    pub density: std::sync::Arc<Vec<f32>>,
    pub world_to_medium: Mat4,
    /// 1 / the largest density (∞ for an empty grid).
    pub inv_max_density: f32,
    majorants: Arc<Majorants>,
}

impl Grid {
    pub fn new(
        sigma_a: Vec3,
        sigma_s: Vec3,
        n: [u32; 3],
        density: std::sync::Arc<Vec<f32>>,
        world_to_medium: Mat4,
        majorant_cells: i32,
    ) -> Grid {
        let max = density.iter().copied().fold(0.0f32, f32::max);
        let n = n.map(|v| v as i32);
        let majorants = Arc::new(Majorants::new(n, &density, majorant_cells));
        Grid {
            majorants,
            sigma_s,
            sigma_t: sigma_a.x + sigma_s.x,
            n,
            density,
            world_to_medium,
            inv_max_density: 1.0 / max,
        }
    }

    /// The majorant grid.
    pub fn majorants(&self) -> &Majorants {
        &self.majorants
    }

    #[inline]
    fn d(&self, x: i32, y: i32, z: i32) -> f32 {
        let [nx, ny, nz] = self.n;
        if x < 0 || y < 0 || z < 0 || x >= nx || y >= ny || z >= nz {
            return 0.0;
        }
        self.density[((z * ny + y) * nx + x) as usize]
    }

    /// pbrt-v3's `Density`: trilinear between voxel centres, 0 outside.
    pub fn density_at(&self, p: Vec3) -> f32 {
        let s = Vec3::new(
            p.x * self.n[0] as f32 - 0.5,
            p.y * self.n[1] as f32 - 0.5,
            p.z * self.n[2] as f32 - 0.5,
        );
        let f = s.floor();
        let (x, y, z) = (f.x as i32, f.y as i32, f.z as i32);
        let d = s - f;
        let lerp = |t: f32, a: f32, b: f32| (1.0 - t) * a + t * b;
        let [nx, ny, nz] = self.n;
        // The eight voxels: read from one base index when they are all
        // inside the grid (the usual case), else one by one with 0 outside.
        let v = if x >= 0 && y >= 0 && z >= 0 && x + 1 < nx && y + 1 < ny && z + 1 < nz {
            let (row, slab) = (nx as usize, (nx * ny) as usize);
            let i = ((z * ny + y) * nx + x) as usize;
            let g = &self.density[i..i + slab + row + 2];
            [
                g[0],
                g[1],
                g[row],
                g[row + 1],
                g[slab],
                g[slab + 1],
                g[slab + row],
                g[slab + row + 1],
            ]
        } else {
            [
                self.d(x, y, z),
                self.d(x + 1, y, z),
                self.d(x, y + 1, z),
                self.d(x + 1, y + 1, z),
                self.d(x, y, z + 1),
                self.d(x + 1, y, z + 1),
                self.d(x, y + 1, z + 1),
                self.d(x + 1, y + 1, z + 1),
            ]
        };
        let d00 = lerp(d.x, v[0], v[1]);
        let d10 = lerp(d.x, v[2], v[3]);
        let d01 = lerp(d.x, v[4], v[5]);
        let d11 = lerp(d.x, v[6], v[7]);
        let d0 = lerp(d.y, d00, d10);
        let d1 = lerp(d.y, d01, d11);
        lerp(d.z, d0, d1)
    }

    /// The ray in medium space with a unit world direction, and the part
    /// of it inside the unit cube (`None`: it misses the grid).
    #[inline]
    fn overlap(&self, ray: &Ray) -> Option<(Vec3, Vec3, f32, f32, f32)> {
        let len = ray.d.length();
        if len.is_nan()
            || len <= 0.0
            || !self.inv_max_density.is_finite()
            || self.sigma_t.is_nan()
            || self.sigma_t <= 0.0
        {
            return None;
        }
        let o = self.world_to_medium.transform_point3(ray.o);
        let d = self.world_to_medium.transform_vector3(ray.d / len);
        let t_max = ray.t_max * len;
        // pbrt-v3's Bounds3::IntersectP against [0, 1]³.
        let (mut t0, mut t1) = (0.0f32, t_max);
        for i in 0..3 {
            let inv = 1.0 / d[i];
            let mut near = (0.0 - o[i]) * inv;
            let mut far = (1.0 - o[i]) * inv;
            if near > far {
                std::mem::swap(&mut near, &mut far);
            }
            far *= 1.0 + 2.0 * gamma(3);
            t0 = if near > t0 { near } else { t0 };
            t1 = if far < t1 { far } else { t1 };
            if t0 > t1 {
                return None;
            }
        }
        Some((o, d, t0, t1, len))
    }

    /// Delta tracking: the weight σs/σt and the world ray parameter of a
    /// scattering event, or weight 1 and none; weight 0 and none past
    /// [`MAX_TRACKING_STEPS`] steps (counted).
    pub fn sample(&self, ray: &Ray, sampler: &mut Sampler) -> (Vec3, Option<f32>) {
        let Some((o, d, t_min, t_max, len)) = self.overlap(ray) else {
            return (Vec3::ONE, None);
        };
        let tracked = self.track(o, d, t_min, t_max, sampler, |t, ratio, sampler| {
            (ratio > sampler.get_1d()).then_some(t)
        });
        match tracked {
            Tracked::Stopped(t) => (self.sigma_s / self.sigma_t, Some(t / len)),
            Tracked::Through => (Vec3::ONE, None),
            Tracked::Cut => (Vec3::ZERO, None),
        }
    }

    /// Ratio tracking with pbrt-v3's Russian roulette; 0 past
    /// [`MAX_TRACKING_STEPS`] steps (counted).
    pub fn tr(&self, ray: &Ray, sampler: &mut Sampler) -> Vec3 {
        let Some((o, d, t_min, t_max, _)) = self.overlap(ray) else {
            return Vec3::ONE;
        };
        let mut tr = 1.0f32;
        let tracked = self.track(o, d, t_min, t_max, sampler, |_, ratio, sampler| {
            tr *= 1.0 - ratio.max(0.0);
            const RR_THRESHOLD: f32 = 0.1;
            if tr < RR_THRESHOLD {
                let q = (1.0 - tr).max(0.05);
                if sampler.get_1d() < q {
                    return Some(());
                }
                tr /= 1.0 - q;
            }
            None
        });
        match tracked {
            Tracked::Through => Vec3::splat(tr),
            Tracked::Stopped(()) | Tracked::Cut => Vec3::ZERO,
        }
    }

    /// The tentative collisions of delta and ratio tracking along the ray
    /// (pbrt-v3's steps by −ln(1 − u) / (σt · majorant), cell by cell): at
    /// each, `at(t, density / majorant, sampler)` says whether tracking
    /// stops there. A step to a NaN distance ends the ray as passed through
    /// (as pbrt-v3's comparison does); more than [`MAX_TRACKING_STEPS`]
    /// steps are counted and cut.
    #[inline(always)]
    fn track<R>(
        &self,
        o: Vec3,
        d: Vec3,
        t_min: f32,
        t_max: f32,
        sampler: &mut Sampler,
        mut at: impl FnMut(f32, f32, &mut Sampler) -> Option<R>,
    ) -> Tracked<R> {
        let mut steps = 0u32;
        for (t0, t1, inv_maj) in self.segments(o, d, t_min, t_max) {
            if !inv_maj.is_finite() {
                continue;
            }
            let step = inv_maj / self.sigma_t;
            let mut t = t0;
            loop {
                steps += 1;
                if steps > MAX_TRACKING_STEPS {
                    note_cut(Cut::Tracking);
                    return Tracked::Cut;
                }
                t -= (1.0 - sampler.get_1d()).ln() * step;
                if t.is_nan() {
                    return Tracked::Through;
                }
                if t >= t1 {
                    break;
                }
                let ratio = self.density_at(o + d * t) * inv_maj;
                if let Some(r) = at(t, ratio, sampler) {
                    return Tracked::Stopped(r);
                }
            }
        }
        Tracked::Through
    }

    /// The ray's pieces `[t0, t1)` with 1 / the largest density over each
    /// (∞ where the medium is empty): for a majorant grid of one cell, one
    /// piece `[t_min, t_max)` with 1 / the grid's largest density, pbrt-v3's
    /// tracking.
    #[inline]
    fn segments(
        &self,
        o: Vec3,
        d: Vec3,
        t_min: f32,
        t_max: f32,
    ) -> impl Iterator<Item = (f32, f32, f32)> + '_ {
        self.majorants
            .walk(o, d, t_min, t_max)
            .map(|(t0, t1, maj)| (t0, t1, 1.0 / maj))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::rng::Pcg32;

    /// pbrt-v3's `Density` as written there: every voxel through `D`.
    fn density_plain(g: &Grid, p: Vec3) -> f32 {
        let s = Vec3::new(
            p.x * g.n[0] as f32 - 0.5,
            p.y * g.n[1] as f32 - 0.5,
            p.z * g.n[2] as f32 - 0.5,
        );
        let f = s.floor();
        let (x, y, z) = (f.x as i32, f.y as i32, f.z as i32);
        let d = s - f;
        let lerp = |t: f32, a: f32, b: f32| (1.0 - t) * a + t * b;
        let d00 = lerp(d.x, g.d(x, y, z), g.d(x + 1, y, z));
        let d10 = lerp(d.x, g.d(x, y + 1, z), g.d(x + 1, y + 1, z));
        let d01 = lerp(d.x, g.d(x, y, z + 1), g.d(x + 1, y, z + 1));
        let d11 = lerp(d.x, g.d(x, y + 1, z + 1), g.d(x + 1, y + 1, z + 1));
        let d0 = lerp(d.y, d00, d10);
        let d1 = lerp(d.y, d01, d11);
        lerp(d.z, d0, d1)
    }

    #[test]
    fn density_equals_the_plain_lookup() {
        let mut rng = Pcg32::with_sequence(4);
        for n in [[1u32, 1, 1], [2, 1, 3], [7, 5, 4], [16, 16, 16]] {
            let count = (n[0] * n[1] * n[2]) as usize;
            let d: Vec<f32> = (0..count).map(|_| rng.uniform_f32() * 3.0).collect();
            let g = Grid::new(Vec3::ONE, Vec3::ONE, n, Arc::new(d), Mat4::IDENTITY, 16);
            for _ in 0..20000 {
                let p = Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32()) * 1.2
                    - Vec3::splat(0.1);
                assert_eq!(
                    g.density_at(p).to_bits(),
                    density_plain(&g, p).to_bits(),
                    "{n:?} at {p}"
                );
            }
        }
    }
}
