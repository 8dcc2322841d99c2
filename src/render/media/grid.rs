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
//! Scattering is sampled by delta tracking against the grid's largest
//! density, transmittance estimated by ratio tracking with pbrt-v3's
//! Russian roulette below 0.1, each drawing from the sampler as pbrt-v3.

use super::{MediumType, Support, COMMON};
use crate::render::geometry::{gamma, Ray};
use crate::render::samplers::Sampler;
use crate::scene::ParamSpec;
use glam::{Mat4, Vec3};

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
    ],
    doc: "a density grid scaling the coefficients, trilinearly interpolated (pbrt-v3's GridDensityMedium)",
    build: (),
};

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
}

impl Grid {
    pub fn new(
        sigma_a: Vec3,
        sigma_s: Vec3,
        n: [u32; 3],
        density: std::sync::Arc<Vec<f32>>,
        world_to_medium: Mat4,
    ) -> Grid {
        let max = density.iter().copied().fold(0.0f32, f32::max);
        Grid {
            sigma_s,
            sigma_t: sigma_a.x + sigma_s.x,
            n: n.map(|v| v as i32),
            density,
            world_to_medium,
            inv_max_density: 1.0 / max,
        }
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
        let d00 = lerp(d.x, self.d(x, y, z), self.d(x + 1, y, z));
        let d10 = lerp(d.x, self.d(x, y + 1, z), self.d(x + 1, y + 1, z));
        let d01 = lerp(d.x, self.d(x, y, z + 1), self.d(x + 1, y, z + 1));
        let d11 = lerp(d.x, self.d(x, y + 1, z + 1), self.d(x + 1, y + 1, z + 1));
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
    /// scattering event, or weight 1 and none.
    pub fn sample(&self, ray: &Ray, sampler: &mut Sampler) -> (Vec3, Option<f32>) {
        let Some((o, d, t_min, t_max, len)) = self.overlap(ray) else {
            return (Vec3::ONE, None);
        };
        let step = self.inv_max_density / self.sigma_t;
        let mut t = t_min;
        loop {
            t -= (1.0 - sampler.get_1d()).ln() * step;
            if t.is_nan() || t >= t_max {
                return (Vec3::ONE, None);
            }
            if self.density_at(o + d * t) * self.inv_max_density > sampler.get_1d() {
                return (self.sigma_s / self.sigma_t, Some(t / len));
            }
        }
    }

    /// Ratio tracking with pbrt-v3's Russian roulette.
    pub fn tr(&self, ray: &Ray, sampler: &mut Sampler) -> Vec3 {
        let Some((o, d, t_min, t_max, _)) = self.overlap(ray) else {
            return Vec3::ONE;
        };
        let step = self.inv_max_density / self.sigma_t;
        let (mut tr, mut t) = (1.0f32, t_min);
        loop {
            t -= (1.0 - sampler.get_1d()).ln() * step;
            if t.is_nan() || t >= t_max {
                return Vec3::splat(tr);
            }
            let density = self.density_at(o + d * t);
            tr *= 1.0 - (density * self.inv_max_density).max(0.0);
            const RR_THRESHOLD: f32 = 0.1;
            if tr < RR_THRESHOLD {
                let q = (1.0 - tr).max(0.05);
                if sampler.get_1d() < q {
                    return Vec3::ZERO;
                }
                tr /= 1.0 - q;
            }
        }
    }
}
