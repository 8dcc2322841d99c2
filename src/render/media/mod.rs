//! Participating media, as pbrt-v3 has them: one file per medium type, each
//! opening with its parameters, and one table, [`MEDIA`], that the loader
//! (parsing and "did you mean"), `--check`, `grammar/REFERENCE.md` and the
//! tests read. [`hg`] is the Henyey–Greenstein phase function both use;
//! [`presets`] pbrt-v3's measured media.
//!
//! A medium answers two questions about a ray segment `[0, ray.t_max]`
//! (pbrt-v3's `Medium::Tr` and `Medium::Sample`): its transmittance, and
//! where (if anywhere) a path going along it scatters, with the weight
//! the path's throughput is multiplied by. Both may draw from the
//! sampler; neither allocates.

pub mod grid;
pub mod hg;
pub mod homogeneous;
pub mod presets;

pub use grid::Grid;
pub use hg::{phase_hg, HenyeyGreenstein};
pub use homogeneous::Homogeneous;

use crate::render::geometry::Ray;
use crate::render::samplers::Sampler;
use crate::scene::{MediumDesc, MediumKind, ParamSpec};
use glam::Vec3;

/// One medium type: its pbrt-v3 name, its parameters, what it is.
pub type MediumType = crate::scene::Kind<()>;

pub use crate::scene::Support;

/// The parameters every medium type reads (pbrt-v3's `MakeMedium`).
pub const COMMON: [ParamSpec; 5] = [
    ParamSpec::spectrum_value(
        "sigma_a",
        [0.0011, 0.0024, 0.014],
        "absorption coefficient per unit length (pbrt-v3's default: whole milk in mm⁻¹)",
    ),
    ParamSpec::spectrum_value(
        "sigma_s",
        [2.55, 3.21, 3.77],
        "scattering coefficient per unit length",
    ),
    ParamSpec::string(
        "preset",
        "",
        "a measured medium of pbrt-v3's table giving sigma_a and sigma_s (which the parameters override)",
    ),
    ParamSpec::float("scale", 1.0, "multiplies sigma_a and sigma_s"),
    ParamSpec::float(
        "g",
        0.0,
        "Henyey–Greenstein asymmetry in (-1, 1): > 0 forward, < 0 backward scattering",
    ),
];

/// Every medium type pbrt-v3's `MakeMedium` knows.
pub static MEDIA: &[MediumType] = &[homogeneous::KIND, grid::KIND];

/// The table entry of a medium type.
pub fn kind(name: &str) -> Option<&'static MediumType> {
    crate::scene::kind::find(MEDIA, name)
}

/// A medium ready to render.
#[derive(Clone, Debug)]
pub struct Medium {
    pub phase: HenyeyGreenstein,
    pub kind: Kind,
}

#[derive(Clone, Debug)]
pub enum Kind {
    Homogeneous(Homogeneous),
    Grid(Grid),
}

impl Medium {
    pub fn new(desc: &MediumDesc) -> Medium {
        let kind = match &desc.kind {
            MediumKind::Homogeneous => {
                Kind::Homogeneous(Homogeneous::new(desc.sigma_a, desc.sigma_s))
            }
            MediumKind::Grid {
                nx,
                ny,
                nz,
                density,
                medium_to_world,
            } => Kind::Grid(Grid::new(
                desc.sigma_a,
                desc.sigma_s,
                [*nx, *ny, *nz],
                density.clone(),
                medium_to_world.inverse().as_mat4(),
            )),
        };
        Medium {
            phase: HenyeyGreenstein { g: desc.g },
            kind,
        }
    }

    /// Transmittance along `ray` from 0 to `ray.t_max` (pbrt-v3's `Tr`).
    #[inline]
    pub fn tr(&self, ray: &Ray, sampler: &mut Sampler) -> Vec3 {
        match &self.kind {
            Kind::Homogeneous(m) => m.tr(ray),
            Kind::Grid(m) => m.tr(ray, sampler),
        }
    }

    /// pbrt-v3's `Sample` over `[0, ray.t_max]`: the throughput weight and
    /// the ray parameter of the scattering point, if the path scatters.
    #[inline]
    pub fn sample(&self, ray: &Ray, sampler: &mut Sampler) -> (Vec3, Option<f32>) {
        match &self.kind {
            Kind::Homogeneous(m) => m.sample(ray, sampler),
            Kind::Grid(m) => m.sample(ray, sampler),
        }
    }
}
