//! The photon-beam-diffusion (PBD) profile table of pbrt-v3's tabulated
//! BSSRDF (`BSSRDFTable`, `BeamDiffusionSS`, `BeamDiffusionMS`,
//! `ComputeBeamDiffusionBSSRDF`, `SubsurfaceFromDiffuse` in
//! core/bssrdf.cpp, after Habel, Christensen and Jarosz, "Photon Beam
//! Diffusion", 2013).
//!
//! The table holds the radial scattering profile `Sr` of a semi-infinite
//! medium in *optical* units (σt = 1), as a function of the single-
//! scattering albedo ρ = σs/σt and the optical radius r·σt; a material
//! scales it to its σt at lookup. Parameters, fixed per material:
//!
//! - `g`: the Henyey–Greenstein asymmetry of the medium (pbrt-v3's
//!   `subsurface` "g", default 0; `kdsubsurface` has none and uses 0).
//! - `eta`: the index of refraction of the boundary (medium over outside;
//!   `"eta"`, default 1.33).
//!
//! Discretisation, as pbrt-v3's materials build it (`BSSRDFTable(100, 64)`):
//!
//! - 100 albedos `ρ_i = (1 − e^{−8i/99}) / (1 − e^{−8})`, dense near 1,
//!   where the profile changes fastest;
//! - 64 optical radii: 0, 2.5·10⁻³, then each 1.2 times the last (the
//!   last is about 204 mean free paths).
//!
//! Each row stores `2π r · (S_ss(r) + S_ms(r))` (the profile times the
//! polar-coordinates Jacobian, so that it is directly a density in `r`), its
//! Catmull-Rom running integral (`profile_cdf`, for sampling a radius) and
//! the full integral `rho_eff`, the row's effective (total diffuse) albedo.
//!
//! Like pbrt-v3, the integrands are estimated with 100 stratified samples
//! of the source depth in f32.

use crate::bxdf::fr_dielectric;
use crate::media::phase_hg;
use crate::sampling::interpolation::{integrate_catmull_rom, invert_catmull_rom};
use glam::Vec3;
use rayon::prelude::*;
use std::collections::HashMap;
use std::f32::consts::PI;
use std::sync::{Arc, Mutex, Weak};

const INV_4PI: f32 = 1.0 / (4.0 * PI);

/// Number of albedo samples pbrt-v3's materials tabulate.
pub const RHO_SAMPLES: usize = 100;
/// Number of optical-radius samples pbrt-v3's materials tabulate.
pub const RADIUS_SAMPLES: usize = 64;
/// Depth samples of the beam integrals (pbrt-v3's `nSamples`).
const DEPTH_SAMPLES: usize = 100;

/// pbrt-v3's `FresnelMoment1`: the polynomial fit of the first moment
/// `∫₀¹ F_r(η, μ) μ dμ · 2` of the dielectric Fresnel reflectance.
pub fn fresnel_moment1(eta: f32) -> f32 {
    let (eta2, eta3) = (eta * eta, eta * eta * eta);
    let (eta4, eta5) = (eta3 * eta, eta3 * eta * eta);
    if eta < 1.0 {
        0.45966 - 1.73965 * eta + 3.37668 * eta2 - 3.904945 * eta3 + 2.49277 * eta4 - 0.68441 * eta5
    } else {
        -4.61686 + 11.1136 * eta - 10.4646 * eta2 + 5.11455 * eta3 - 1.27198 * eta4 + 0.12746 * eta5
    }
}

/// pbrt-v3's `FresnelMoment2`: the fit of the second moment.
pub fn fresnel_moment2(eta: f32) -> f32 {
    let (eta2, eta3) = (eta * eta, eta * eta * eta);
    let (eta4, eta5) = (eta3 * eta, eta3 * eta * eta);
    if eta < 1.0 {
        0.27614 - 0.87350 * eta + 1.12077 * eta2 - 0.65095 * eta3 + 0.07883 * eta4 + 0.04860 * eta5
    } else {
        let r = 1.0 / eta;
        let (r2, r3) = (r * r, r * r * r);
        -547.033 + 45.3087 * r3 - 218.725 * r2 + 458.843 * r + 404.557 * eta - 189.519 * eta2
            + 54.9327 * eta3
            - 9.00603 * eta4
            + 0.63942 * eta5
    }
}

/// The constants of the dipole for one medium (pbrt-v3's precomputation in
/// `BeamDiffusionMS`, book equations 15.24–15.32).
#[derive(Clone, Copy, Debug)]
pub struct Dipole {
    /// Reduced extinction σ′t = σa + σs(1 − g).
    pub sigmap_t: f32,
    /// Reduced albedo ρ′ = σ′s / σ′t.
    pub rhop: f32,
    /// Grosjean's non-classical diffusion coefficient D_G.
    pub d_g: f32,
    /// Effective transport coefficient σtr = √(σa / D_G).
    pub sigma_tr: f32,
    /// Linear extrapolation distance z_e (negative: above the surface).
    pub ze: f32,
    /// Exitance weights of fluence and vector irradiance.
    pub c_phi: f32,
    pub c_e: f32,
}

impl Dipole {
    pub fn new(sigma_s: f32, sigma_a: f32, g: f32, eta: f32) -> Self {
        let sigmap_s = sigma_s * (1.0 - g);
        let sigmap_t = sigma_a + sigmap_s;
        let rhop = sigmap_s / sigmap_t;
        let d_g = (2.0 * sigma_a + sigmap_s) / (3.0 * sigmap_t * sigmap_t);
        let sigma_tr = (sigma_a / d_g).sqrt();
        let (fm1, fm2) = (fresnel_moment1(eta), fresnel_moment2(eta));
        let ze = -2.0 * d_g * (1.0 + 3.0 * fm2) / (1.0 - 2.0 * fm1);
        Dipole {
            sigmap_t,
            rhop,
            d_g,
            sigma_tr,
            ze,
            c_phi: 0.25 * (1.0 - 2.0 * fm1),
            c_e: 0.5 * (1.0 - 3.0 * fm2),
        }
    }

    /// Radiant exitance at radius `r` of a unit point source at depth `zr`
    /// and its mirror source (equation 15.27 weighted by 15.31/15.32),
    /// without PBD's κ and ρ′² factors.
    pub fn exitance(&self, zr: f32, r: f32) -> f32 {
        let zv = -zr + 2.0 * self.ze;
        let dr = (r * r + zr * zr).sqrt();
        let dv = (r * r + zv * zv).sqrt();
        let (er, ev) = ((-self.sigma_tr * dr).exp(), (-self.sigma_tr * dv).exp());
        let phi_d = INV_4PI / self.d_g * (er / dr - ev / dv);
        let e_dn = INV_4PI
            * (zr * (1.0 + self.sigma_tr * dr) * er / (dr * dr * dr)
                - zv * (1.0 + self.sigma_tr * dv) * ev / (dv * dv * dv));
        phi_d * self.c_phi + e_dn * self.c_e
    }
}

/// `ln(1 − (i + ½)/n)` for the beam integrals' depth samples `i` (the
/// same for every albedo and radius, so made once per table).
fn depth_logs() -> [f32; DEPTH_SAMPLES] {
    std::array::from_fn(|i| (1.0 - (i as f32 + 0.5) / DEPTH_SAMPLES as f32).ln())
}

/// pbrt-v3's `BeamDiffusionMS`: the multiple-scattering profile at radius
/// `r` of a medium with `sigma_s`, `sigma_a`, HG `g` and boundary `eta`,
/// integrating dipoles along the refracted beam (sources at depths
/// sampled by the reduced extinction).
pub fn beam_diffusion_ms(sigma_s: f32, sigma_a: f32, g: f32, eta: f32, r: f32) -> f32 {
    ms_with(&Dipole::new(sigma_s, sigma_a, g, eta), &depth_logs(), r)
}

/// [`beam_diffusion_ms`] from the medium's dipole and [`depth_logs`].
fn ms_with(dip: &Dipole, logs: &[f32; DEPTH_SAMPLES], r: f32) -> f32 {
    let mut ed = 0.0f32;
    for &log in logs {
        let zr = -log / dip.sigmap_t;
        let dr = (r * r + zr * zr).sqrt();
        let kappa = 1.0 - (-2.0 * dip.sigmap_t * (dr + zr)).exp();
        ed += kappa * dip.rhop * dip.rhop * dip.exitance(zr, r);
    }
    ed / DEPTH_SAMPLES as f32
}

/// pbrt-v3's `BeamDiffusionSS`: the single-scattering profile at radius `r`
/// (scattering once along the refracted beam below the critical angle and
/// leaving through the Fresnel boundary).
pub fn beam_diffusion_ss(sigma_s: f32, sigma_a: f32, g: f32, eta: f32, r: f32) -> f32 {
    ss_with(sigma_s, sigma_a, g, eta, &depth_logs(), r)
}

/// [`beam_diffusion_ss`] with [`depth_logs`].
fn ss_with(
    sigma_s: f32,
    sigma_a: f32,
    g: f32,
    eta: f32,
    logs: &[f32; DEPTH_SAMPLES],
    r: f32,
) -> f32 {
    let sigma_t = sigma_a + sigma_s;
    let rho = sigma_s / sigma_t;
    let t_crit = r * (eta * eta - 1.0).max(0.0).sqrt();
    let mut ess = 0.0f32;
    for &log in logs {
        let ti = t_crit - log / sigma_t;
        let d = (r * r + ti * ti).sqrt();
        let cos_o = ti / d;
        ess += rho * (-sigma_t * (d + t_crit)).exp() / (d * d)
            * phase_hg(cos_o, g)
            * (1.0 - fr_dielectric(-cos_o, 1.0, eta))
            * cos_o.abs();
    }
    ess / DEPTH_SAMPLES as f32
}

/// The tables materials hold, by the bits of their `g` and `eta`.
type LiveTables = HashMap<(u32, u32), Weak<BssrdfTable>>;

/// pbrt-v3's `BSSRDFTable`, filled by `ComputeBeamDiffusionBSSRDF`.
#[derive(Clone, Debug)]
pub struct BssrdfTable {
    pub rho_samples: Vec<f32>,
    pub radius_samples: Vec<f32>,
    /// `2π r S(ρ_i, r_j)`, row `i` (albedo) major.
    pub profile: Vec<f32>,
    /// Running Catmull-Rom integrals of each row of `profile`.
    pub profile_cdf: Vec<f32>,
    /// Each row's full integral: the effective albedo.
    pub rho_eff: Vec<f32>,
}

impl BssrdfTable {
    /// The table pbrt-v3's `subsurface` and `kdsubsurface` build for HG
    /// asymmetry `g` and boundary index `eta` (100 albedos × 64 radii).
    pub fn beam_diffusion(g: f32, eta: f32) -> Self {
        let (n_rho, n_r) = (RHO_SAMPLES, RADIUS_SAMPLES);
        let mut radius_samples = vec![0.0f32; n_r];
        radius_samples[1] = 2.5e-3;
        for i in 2..n_r {
            radius_samples[i] = radius_samples[i - 1] * 1.2;
        }
        let rho_samples: Vec<f32> = (0..n_rho)
            .map(|i| (1.0 - (-8.0 * i as f32 / (n_rho - 1) as f32).exp()) / (1.0 - (-8.0f32).exp()))
            .collect();
        let mut profile = vec![0.0f32; n_rho * n_r];
        let mut profile_cdf = vec![0.0f32; n_rho * n_r];
        let mut rho_eff = vec![0.0f32; n_rho];
        // The rows (albedos) are independent: filled side by side, each
        // with pbrt-v3's operations, its dipole made once for its radii.
        let logs = depth_logs();
        profile
            .par_chunks_mut(n_r)
            .zip(profile_cdf.par_chunks_mut(n_r))
            .zip(rho_eff.par_iter_mut())
            .zip(rho_samples.par_iter())
            .for_each(|(((row, cdf), eff), &rho)| {
                let dip = Dipole::new(rho, 1.0 - rho, g, eta);
                for (p, &r) in row.iter_mut().zip(&radius_samples) {
                    *p = 2.0
                        * PI
                        * r
                        * (ss_with(rho, 1.0 - rho, g, eta, &logs, r) + ms_with(&dip, &logs, r));
                }
                *eff = integrate_catmull_rom(&radius_samples, row, cdf);
            });
        BssrdfTable {
            rho_samples,
            radius_samples,
            profile,
            profile_cdf,
            rho_eff,
        }
    }

    /// [`BssrdfTable::beam_diffusion`]`(g, eta)`, shared with every other
    /// live material of the same `g` and `eta` (bit for bit), so that a
    /// scene's materials of one medium kind compute it once.
    pub fn shared(g: f32, eta: f32) -> Arc<BssrdfTable> {
        static LIVE: Mutex<Option<LiveTables>> = Mutex::new(None);
        let key = (g.to_bits(), eta.to_bits());
        let lock = || LIVE.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(table) = lock().as_ref().and_then(|live| live.get(&key)?.upgrade()) {
            return table;
        }
        // Computed without the lock held (its rows run on the thread pool);
        // a table another thread made meanwhile is taken instead.
        let table = Arc::new(BssrdfTable::beam_diffusion(g, eta));
        let mut live = lock();
        let live = live.get_or_insert_with(HashMap::new);
        if let Some(other) = live.get(&key).and_then(Weak::upgrade) {
            return other;
        }
        // Only the tables some material still holds are remembered.
        live.retain(|_, t| t.strong_count() > 0);
        live.insert(key, Arc::downgrade(&table));
        table
    }

    /// The tabulated `2π r S` at albedo index `rho_index`, radius index
    /// `radius_index` (pbrt-v3's `EvalProfile`).
    #[inline]
    pub fn eval_profile(&self, rho_index: usize, radius_index: usize) -> f32 {
        self.profile[rho_index * self.radius_samples.len() + radius_index]
    }
}

/// pbrt-v3's `SubsurfaceFromDiffuse`: per channel, the single-scattering
/// albedo whose tabulated effective albedo is `rho_eff` (clamped to the
/// table's range), and with mean free path `mfp`: σs = ρ/mfp and
/// σa = (1 − ρ)/mfp. Returns `(sigma_a, sigma_s)`.
pub fn subsurface_from_diffuse(table: &BssrdfTable, rho_eff: Vec3, mfp: Vec3) -> (Vec3, Vec3) {
    let mut sigma_a = Vec3::ZERO;
    let mut sigma_s = Vec3::ZERO;
    for c in 0..3 {
        let rho = invert_catmull_rom(&table.rho_samples, &table.rho_eff, rho_eff[c]);
        sigma_s[c] = rho / mfp[c];
        sigma_a[c] = (1.0 - rho) / mfp[c];
    }
    (sigma_a, sigma_s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::interpolation::catmull_rom_weights;
    use std::sync::OnceLock;

    fn table() -> &'static BssrdfTable {
        static T: OnceLock<BssrdfTable> = OnceLock::new();
        T.get_or_init(|| BssrdfTable::beam_diffusion(0.0, 1.33))
    }

    /// The rows filled side by side (each with its dipole and the depth
    /// samples' logarithms made once) hold, entry by entry, pbrt-v3's
    /// `2π r (BeamDiffusionSS + BeamDiffusionMS)` at their albedo and
    /// radius, and their integrals, bit for bit.
    #[test]
    fn parallel_rows_are_the_entries_one_by_one() {
        for (g, eta) in [(0.0, 1.33), (0.7, 1.5), (-0.3, 1.0)] {
            let t = BssrdfTable::beam_diffusion(g, eta);
            let n_r = t.radius_samples.len();
            for (i, &rho) in t.rho_samples.iter().enumerate() {
                let row: Vec<f32> = t
                    .radius_samples
                    .iter()
                    .map(|&r| {
                        2.0 * PI
                            * r
                            * (beam_diffusion_ss(rho, 1.0 - rho, g, eta, r)
                                + beam_diffusion_ms(rho, 1.0 - rho, g, eta, r))
                    })
                    .collect();
                let mut cdf = vec![0.0; n_r];
                let eff = integrate_catmull_rom(&t.radius_samples, &row, &mut cdf);
                let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(
                    bits(&t.profile[i * n_r..(i + 1) * n_r]),
                    bits(&row),
                    "g {g} row {i}"
                );
                assert_eq!(bits(&t.profile_cdf[i * n_r..(i + 1) * n_r]), bits(&cdf));
                assert_eq!(t.rho_eff[i].to_bits(), eff.to_bits());
            }
        }
    }

    /// Materials of one medium kind (`g`, `eta`) share one table; another
    /// kind gets its own; a table no material holds any more is not kept.
    #[test]
    fn shared_tables_one_per_medium_while_held() {
        let (g, eta) = (0.25, 1.41);
        let a = BssrdfTable::shared(g, eta);
        let b = BssrdfTable::shared(g, eta);
        assert!(Arc::ptr_eq(&a, &b));
        let c = BssrdfTable::shared(g, 1.4);
        assert!(!Arc::ptr_eq(&a, &c));
        assert_eq!(a.profile, BssrdfTable::beam_diffusion(g, eta).profile);
        let weak = Arc::downgrade(&a);
        drop((a, b));
        assert!(weak.upgrade().is_none());
    }

    /// Numerical integral of `f` over r in [0, r_max] on a geometric grid.
    fn integrate_radially(f: impl Fn(f32) -> f64, r_max: f64) -> f64 {
        // Simpson on u = ln(1 + r / s), dense near 0.
        let s = 1e-3f64;
        let u_max = (1.0 + r_max / s).ln();
        let n = 20_000;
        let h = u_max / n as f64;
        let mut sum = 0.0;
        for k in 0..=n {
            let u = k as f64 * h;
            let r = s * (u.exp() - 1.0);
            let jac = s * u.exp();
            let w = if k == 0 || k == n {
                1.0
            } else if k % 2 == 1 {
                4.0
            } else {
                2.0
            };
            sum += w * f(r as f32) * jac;
        }
        sum * h / 3.0
    }

    #[test]
    fn fresnel_moments_match_their_definition() {
        // pbrt-v3's fits of ∫₀¹ F_r(η, μ) μ^i dμ (i = 1, 2), F_r seen from
        // inside (index η, total internal reflection included) a boundary
        // with index 1 outside.
        for &eta in &[1.1f32, 1.33, 1.5, 2.0] {
            let n = 100_000;
            let (mut m1, mut m2) = (0.0f64, 0.0f64);
            for k in 0..n {
                let mu = (k as f64 + 0.5) / n as f64;
                let f = fr_dielectric(mu as f32, eta, 1.0) as f64;
                m1 += f * mu / n as f64;
                m2 += f * mu * mu / n as f64;
            }
            let (f1, f2) = (fresnel_moment1(eta) as f64, fresnel_moment2(eta) as f64);
            assert!((f1 - m1).abs() < 0.01, "{eta}: {f1} vs {m1}");
            assert!((f2 - m2).abs() < 0.01, "{eta}: {f2} vs {m2}");
        }
    }

    #[test]
    fn one_dipole_integrates_to_its_closed_form() {
        // ∫ 2πr E(r) dr over the plane of one source pair has the closed
        // form (c_φ/(2 D σtr)) (e^{−σtr zr} − e^{−σtr|zv|})
        //       + (c_E/2)(e^{−σtr zr} + e^{−σtr|zv|}).
        for &(ss, sa, g, eta) in &[
            (0.9f32, 0.1f32, 0.0f32, 1.33f32),
            (0.5, 0.5, 0.3, 1.5),
            (0.99, 0.01, 0.0, 1.0),
        ] {
            let dip = Dipole::new(ss, sa, g, eta);
            for &zr in &[0.05f32, 0.5, 2.0] {
                let zv = -zr + 2.0 * dip.ze;
                assert!(zv < 0.0);
                let (er, ev) = (
                    (-(dip.sigma_tr * zr) as f64).exp(),
                    (-(dip.sigma_tr * zv.abs()) as f64).exp(),
                );
                let exact = dip.c_phi as f64 / (2.0 * dip.d_g as f64 * dip.sigma_tr as f64)
                    * (er - ev)
                    + dip.c_e as f64 / 2.0 * (er + ev);
                let numeric = integrate_radially(
                    |r| 2.0 * std::f64::consts::PI * r as f64 * dip.exitance(zr, r) as f64,
                    400.0 / dip.sigma_tr as f64,
                );
                assert!(
                    (numeric - exact).abs() < 2e-3 * exact.abs().max(1e-3),
                    "{ss} {sa} {g} {eta} zr {zr}: {numeric} vs {exact}"
                );
            }
        }
    }

    #[test]
    fn multiple_scattering_integrates_to_the_beam_of_dipoles() {
        // Without κ (which only matters near the entry point), the MS
        // profile integrated over the plane is the average over the beam's
        // depth samples of ρ′² × the closed form above.
        let (ss, sa, g, eta) = (0.8f32, 0.2f32, 0.0f32, 1.33f32);
        let dip = Dipole::new(ss, sa, g, eta);
        let numeric = integrate_radially(
            |r| 2.0 * std::f64::consts::PI * r as f64 * beam_diffusion_ms(ss, sa, g, eta, r) as f64,
            300.0,
        );
        let mut exact = 0.0f64;
        let mut no_kappa_upper = 0.0f64;
        for i in 0..DEPTH_SAMPLES {
            let zr = -(1.0 - (i as f32 + 0.5) / DEPTH_SAMPLES as f32).ln() / dip.sigmap_t;
            let zv = -zr + 2.0 * dip.ze;
            let (er, ev) = (
                (-(dip.sigma_tr * zr) as f64).exp(),
                (-(dip.sigma_tr * zv.abs()) as f64).exp(),
            );
            let e = dip.c_phi as f64 / (2.0 * dip.d_g as f64 * dip.sigma_tr as f64) * (er - ev)
                + dip.c_e as f64 / 2.0 * (er + ev);
            no_kappa_upper += (dip.rhop * dip.rhop) as f64 * e;
            // κ ≥ 1 − e^{−4σ′t zr} at every radius (dr ≥ zr).
            exact += (dip.rhop * dip.rhop) as f64
                * e
                * (1.0 - (-4.0 * (dip.sigmap_t * zr) as f64).exp());
        }
        let (lower, upper) = (
            exact / DEPTH_SAMPLES as f64,
            no_kappa_upper / DEPTH_SAMPLES as f64,
        );
        assert!(
            numeric <= upper * 1.002 && numeric >= lower * 0.998,
            "{lower} <= {numeric} <= {upper}"
        );
    }

    #[test]
    fn table_rows_integrate_to_rho_eff_and_rho_eff_is_monotonic() {
        let t = table();
        assert_eq!(t.rho_samples.len(), RHO_SAMPLES);
        assert_eq!(t.radius_samples.len(), RADIUS_SAMPLES);
        assert_eq!(t.rho_samples[0], 0.0);
        assert!((t.rho_samples[RHO_SAMPLES - 1] - 1.0).abs() < 1e-6);
        assert!((t.radius_samples[63] - 2.5e-3 * 1.2f32.powi(62)).abs() < 1.0);
        assert_eq!(t.rho_eff[0], 0.0);
        for i in 1..RHO_SAMPLES {
            assert!(
                t.rho_eff[i] > t.rho_eff[i - 1],
                "{i}: {} {}",
                t.rho_eff[i - 1],
                t.rho_eff[i]
            );
            let last_cdf = t.profile_cdf[i * RADIUS_SAMPLES + RADIUS_SAMPLES - 1];
            assert_eq!(last_cdf, t.rho_eff[i]);
            // The CDF never decreases by more than rounding.
            for j in 1..RADIUS_SAMPLES {
                let (a, b) = (
                    t.profile_cdf[i * RADIUS_SAMPLES + j - 1],
                    t.profile_cdf[i * RADIUS_SAMPLES + j],
                );
                assert!(b >= a - 1e-6 * t.rho_eff[i], "{i} {j}");
            }
        }
        // A white medium reflects about all the light (PBD's approximations
        // put pbrt-v3's value for ρ = 1, η = 1.33 slightly above 1), a grey
        // one much less.
        let white = t.rho_eff[RHO_SAMPLES - 1];
        assert!(white > 0.9 && white < 1.05, "{white}");
        assert!(
            (t.rho_samples[8] - 0.4763).abs() < 1e-3,
            "{}",
            t.rho_samples[8]
        );
        assert!(t.rho_eff[8] < 0.2, "{}", t.rho_eff[8]);
        // The profile is finite and non-negative everywhere.
        assert!(t.profile.iter().all(|p| p.is_finite() && *p >= 0.0));
    }

    #[test]
    fn subsurface_from_diffuse_round_trips_through_the_table() {
        let t = table();
        let mfp = Vec3::new(1.0, 0.5, 2.0);
        for &kd in &[0.05f32, 0.2, 0.5, 0.7] {
            let (sa, ss) = subsurface_from_diffuse(t, Vec3::splat(kd), mfp);
            for c in 0..3 {
                // σt = 1/mfp, and the spline of rho_eff at ρ gives back kd.
                assert!(((sa[c] + ss[c]) * mfp[c] - 1.0).abs() < 1e-5);
                let rho = ss[c] * mfp[c];
                let (off, w) = catmull_rom_weights(&t.rho_samples, rho).unwrap();
                let mut back = 0.0;
                for (k, wk) in w.iter().enumerate() {
                    if *wk != 0.0 {
                        back += wk * t.rho_eff[(off + k as isize) as usize];
                    }
                }
                assert!((back - kd).abs() < 1e-4, "{kd}: rho {rho} -> {back}");
            }
        }
        // Out of range: clamped to the table's ends, never NaN.
        let (sa, ss) = subsurface_from_diffuse(t, Vec3::new(-1.0, 2.0, f32::NAN), Vec3::ONE);
        assert_eq!(ss, Vec3::new(0.0, 1.0, 0.0));
        assert_eq!(sa, Vec3::new(1.0, 0.0, 1.0));
    }
}
