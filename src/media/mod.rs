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
pub mod majorant;
pub mod presets;

pub use grid::Grid;
pub use hg::{phase_hg, HenyeyGreenstein};
pub use homogeneous::Homogeneous;

use crate::geometry::Ray;
use crate::samplers::Sampler;
use crate::scene::kind::closest_name;
use crate::scene::{ParamSpec, ParamValues, Report};
use glam::{DMat4, Vec3};

/// What a medium's builder gets besides its parameters.
pub struct MediumInput<'a> {
    /// The name given to `MakeNamedMedium`.
    pub name: &'a str,
    /// The CTM at `MakeNamedMedium` (the grid's box is in its space).
    pub ctm: DMat4,
}

/// What a medium type builds: the medium, or `None` after an error or a
/// warning that says it is not defined (pbrt-v3 then leaves the name
/// undefined).
pub type MediumBuild = fn(&ParamValues, &MediumInput, &mut dyn Report) -> Option<Medium>;

/// One medium type: its pbrt-v3 name, its parameters, its builder.
pub type MediumType = crate::scene::Kind<MediumBuild>;

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

/// The coefficients every medium type has, as pbrt-v3's `MakeMedium`
/// reads them: a `preset` from the measured table, else the defaults; then
/// `sigma_a` and `sigma_s` if given; both times `scale`. Negative or
/// non-finite channels become 0 and `g` is clamped into (-1, 1), with
/// warnings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coefficients {
    pub sigma_a: Vec3,
    pub sigma_s: Vec3,
    pub g: f32,
}

impl Coefficients {
    pub fn read(p: &ParamValues, what: &str, r: &mut dyn Report) -> Coefficients {
        let default = |n: &str| match COMMON.iter().find(|s| s.name == n).map(|s| s.kind) {
            Some(crate::scene::ParamKind::Spectrum(d)) => Vec3::from_array(d),
            _ => Vec3::ZERO,
        };
        let (mut sigma_a, mut sigma_s) = (default("sigma_a"), default("sigma_s"));
        let preset = p.string("preset");
        match presets::measured(preset) {
            Some(m) => {
                sigma_a = Vec3::from_array(m.sigma_a);
                sigma_s = Vec3::from_array(m.sigma_prime_s);
            }
            None if preset.is_empty() => {}
            None => {
                let names: Vec<&str> = presets::MEASURED.iter().map(|m| m.name).collect();
                let help = closest_name(preset, &names)
                    .map(|c| format!("; did you mean \"{c}\"?"))
                    .unwrap_or_default();
                r.warn(
                    Some("preset"),
                    format!("{what}: unknown preset \"{preset}\": pbrt-v3's default coefficients are used (as pbrt-v3){help}"),
                    "not a measured medium",
                );
            }
        }
        let scale = p.float("scale");
        let mut g = p.float("g");
        let given = |n: &str, v: Vec3| if p.given(n) { p.spectrum(n) } else { v };
        let sigma_a = nonneg(p, r, what, "sigma_a", given("sigma_a", sigma_a) * scale);
        let sigma_s = nonneg(p, r, what, "sigma_s", given("sigma_s", sigma_s) * scale);
        if g.is_nan() || g.abs() >= 1.0 {
            let clamped = if g.is_nan() {
                0.0
            } else {
                g.clamp(-0.999, 0.999)
            };
            r.warn(
                Some("g"),
                format!("{what}: \"g\" is {g}: the Henyey–Greenstein asymmetry must be in (-1, 1); {clamped} is used"),
                "out of range",
            );
            g = clamped;
        }
        Coefficients {
            sigma_a,
            sigma_s,
            g,
        }
    }
}

/// A coefficient with negative channels set to 0 (and a warning there).
fn nonneg(p: &ParamValues, r: &mut dyn Report, what: &str, n: &str, v: Vec3) -> Vec3 {
    if v.cmpge(Vec3::ZERO).all() && v.is_finite() {
        return v;
    }
    let fixed = Vec3::new(fix(v.x), fix(v.y), fix(v.z));
    let at = [n, "scale"].into_iter().find(|a| p.given(a));
    if let Some(at) = at {
        r.warn(
            Some(at),
            format!("{what}: \"{n}\" is {} {} {}: coefficients must be finite and ≥ 0; {} {} {} is used", v.x, v.y, v.z, fixed.x, fixed.y, fixed.z),
            "negative or non-finite coefficient",
        );
    }
    fixed
}

/// A value made finite and non-negative (0 otherwise).
pub fn fix(c: f32) -> f32 {
    if c.is_finite() {
        c.max(0.0)
    } else {
        0.0
    }
}

/// A medium ready to render.
#[derive(Clone, Debug)]
pub struct Medium {
    /// The name given to `MakeNamedMedium` (for messages and `--check`).
    pub name: String,
    /// The coefficients as read (`scale` applied), for `--check`.
    pub coefficients: Coefficients,
    pub phase: HenyeyGreenstein,
    pub density: Density,
}

/// How the coefficients vary over space; each variant is one file of this
/// module.
#[derive(Clone, Debug)]
pub enum Density {
    Homogeneous(Homogeneous),
    Grid(Grid),
}

impl Medium {
    pub fn new(name: &str, coefficients: Coefficients, density: Density) -> Medium {
        Medium {
            name: name.to_string(),
            coefficients,
            phase: HenyeyGreenstein { g: coefficients.g },
            density,
        }
    }

    /// The type and its settings, for `--check`.
    pub fn describe(&self) -> String {
        let v = |c: Vec3| format!("{} {} {}", c.x, c.y, c.z);
        let kind = match &self.density {
            Density::Homogeneous(_) => "homogeneous".to_string(),
            Density::Grid(g) => format!("heterogeneous {}×{}×{}", g.n[0], g.n[1], g.n[2]),
        };
        format!(
            "\"{}\": {kind}, sigma_a {}, sigma_s {}, g {}",
            self.name,
            v(self.coefficients.sigma_a),
            v(self.coefficients.sigma_s),
            self.coefficients.g
        )
    }

    /// Whether `tr` draws sample values (ratio tracking through a grid).
    pub fn tr_draws(&self) -> bool {
        matches!(self.density, Density::Grid(_))
    }

    /// Transmittance along `ray` from 0 to `ray.t_max` (pbrt-v3's `Tr`).
    #[inline]
    pub fn tr(&self, ray: &Ray, sampler: &mut Sampler) -> Vec3 {
        match &self.density {
            Density::Homogeneous(m) => m.tr(ray),
            Density::Grid(m) => m.tr(ray, sampler),
        }
    }

    /// pbrt-v3's `Sample` over `[0, ray.t_max]`: the throughput weight and
    /// the ray parameter of the scattering point, if the path scatters.
    #[inline]
    pub fn sample(&self, ray: &Ray, sampler: &mut Sampler) -> (Vec3, Option<f32>) {
        match &self.density {
            Density::Homogeneous(m) => m.sample(ray, sampler),
            Density::Grid(m) => m.sample(ray, sampler),
        }
    }
}
