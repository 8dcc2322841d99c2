//! `disney`: pbrt-v3's implementation of Burley's Disney BSDF (2015): a
//! diffuse base with retro-reflection and sheen, a Trowbridge–Reitz
//! specular lobe with a metallic/dielectric Fresnel blend, a clearcoat,
//! rough specular transmission, and a thin-surface mode with diffuse
//! transmission.
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `color` | spectrum texture | 0.5 | base colour (clamped to ≥ 0) |
//! | `metallic` | float texture | 0 | blend from dielectric to metal |
//! | `eta` | float texture | 1.5 | index of refraction (specular Fresnel and transmission) |
//! | `roughness` | float texture | 0.5 | α = roughness² (≥ 0.001) |
//! | `speculartint` | float texture | 0 | tints the dielectric specular towards the colour's hue |
//! | `anisotropic` | float texture | 0 | aspect √(1 − 0.9·anisotropic): αx = α/aspect along dp/du, αy = α·aspect |
//! | `sheen` | float texture | 0 | sheen weight (lobe added when > 0) |
//! | `sheentint` | float texture | 0.5 | sheen colour from white to the colour's hue |
//! | `clearcoat` | float texture | 0 | clearcoat weight (lobe added when > 0) |
//! | `clearcoatgloss` | float texture | 1 | GTR1 α from 0.1 (0) to 0.001 (1) |
//! | `spectrans` | float texture | 0 | specular transmission weight; transmittance spectrans·√color |
//! | `scatterdistance` | spectrum texture | 0 | subsurface mean free path: not supported (warning, see below) |
//! | `thin` | bool | false | thin surface: diffuse blends with fake subsurface, diffuse transmission |
//! | `flatness` | float texture | 0 | thin only: blend of diffuse towards fake subsurface |
//! | `difftrans` | float texture | 1 | thin only: diffuse transmission, fraction difftrans/2 |
//! | `bumpmap` | float texture | | displacement for bump mapping (every material: `bump.rs`) |
//!
//! The lobes, in pbrt-v3's order (with diffuse weight (1 − metallic)(1 − spectrans)
//! and dt = difftrans/2), each added as pbrt-v3 adds it, even with a zero
//! weight, so that the lobe choice is pbrt-v3's:
//!
//! - diffuse weight > 0: thin: DisneyDiffuse ·(1 − flatness)(1 − dt) and
//!   DisneyFakeSS ·flatness·(1 − dt); else DisneyDiffuse (or, when
//!   `scatterdistance` is not black, pbrt-v3's BSDF part of the subsurface
//!   path: a SpecularTransmission of weight 1 into index `eta`); then
//!   DisneyRetro, and DisneySheen when sheen > 0;
//! - MicrofacetReflection with the Disney distribution (Trowbridge–Reitz
//!   with separable masking G1·G1) and DisneyFresnel, always;
//! - DisneyClearcoat when clearcoat > 0;
//! - spectrans > 0: MicrofacetTransmission (index 1 outside, `eta` inside),
//!   on the Disney distribution, or for thin surfaces on a plain
//!   Trowbridge–Reitz of roughness scaled by 0.65·eta − 0.35;
//! - thin: LambertianTransmission ·dt·color.
//!
//! At most 8 lobes (thin with sheen, clearcoat and spectrans), pbrt-v3's
//! `MaxBxDFs`. The BSDF's η stays 1, as pbrt-v3's (it never sets it).
//!
//! Subsurface scattering: with a non-black `scatterdistance` pbrt-v3 replaces
//! the diffuse lobe by that specular transmission and attaches a
//! `DisneyBSSRDF`, which only its path and volpath integrators sample (on a
//! transmission sample); its directlighting and whitted integrators render
//! the BSDF alone. pbrs has no BSSRDF: it renders the BSDF alone under
//! every integrator, which is pbrt-v3's directlighting and whitted image;
//! under the path tracer light refracts into the surface through the
//! transmission lobe instead of scattering beneath it. The loader warns.

use super::{Material, MaterialKind, ShadingContext, Support};
use crate::bxdf::{
    schlick_r0_from_eta, Bsdf, DisneyClearcoat, DisneyDiffuse, DisneyFakeSS, DisneyFresnel,
    DisneyMicrofacet, DisneyRetro, DisneySheen, Fresnel, LambertianTransmission,
    MicrofacetReflection, MicrofacetTransmission, SpecularTransmission, TrowbridgeReitz,
};
use crate::geometry::luminance;
use crate::scene::{FloatTex, ParamSpec, ParamValues, SpectrumTex};
use glam::Vec3;

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::spectrum("color", 0.5, "base colour"),
    ParamSpec::float_tex("metallic", 0.0, "dielectric (0) to metal (1)"),
    ParamSpec::float_tex("eta", 1.5, "index of refraction"),
    ParamSpec::nonneg_tex("roughness", 0.5, "α = roughness²"),
    ParamSpec::float_tex(
        "speculartint",
        0.0,
        "dielectric specular tinted by the colour's hue",
    ),
    ParamSpec::float_tex("anisotropic", 0.0, "anisotropy along dp/du (0..1)"),
    ParamSpec::float_tex("sheen", 0.0, "sheen weight"),
    ParamSpec::float_tex("sheentint", 0.5, "sheen from white to the colour's hue"),
    ParamSpec::float_tex("clearcoat", 0.0, "clearcoat weight"),
    ParamSpec::float_tex(
        "clearcoatgloss",
        1.0,
        "clearcoat GTR1 α 0.1 (0) to 0.001 (1)",
    ),
    ParamSpec::float_tex("spectrans", 0.0, "specular transmission weight"),
    ParamSpec::spectrum(
        "scatterdistance",
        0.0,
        "subsurface mean free path (subsurface not supported)",
    ),
    ParamSpec::boolean("thin", false, "thin surface"),
    ParamSpec::float_tex("flatness", 0.0, "thin: diffuse towards fake subsurface"),
    ParamSpec::float_tex("difftrans", 1.0, "thin: diffuse transmission ×2"),
    ParamSpec::BUMPMAP,
];

pub const KIND: MaterialKind = MaterialKind {
    name: "disney",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "Burley's Disney BSDF (pbrt-v3's): diffuse, retro, sheen, specular, clearcoat, transmission, thin surfaces",
    build: |p| Material::Disney(Disney::new(p)),
};

#[derive(Clone, Debug)]
pub struct Disney {
    pub color: SpectrumTex,
    pub metallic: FloatTex,
    pub eta: FloatTex,
    pub roughness: FloatTex,
    pub specular_tint: FloatTex,
    pub anisotropic: FloatTex,
    pub sheen: FloatTex,
    pub sheen_tint: FloatTex,
    pub clearcoat: FloatTex,
    pub clearcoat_gloss: FloatTex,
    pub spec_trans: FloatTex,
    pub scatter_distance: SpectrumTex,
    pub thin: bool,
    pub flatness: FloatTex,
    pub diff_trans: FloatTex,
}

/// pbrt-v3's `Lerp(t, a, b)`.
#[inline]
fn lerp<T>(t: f32, a: T, b: T) -> T
where
    T: std::ops::Mul<f32, Output = T> + std::ops::Add<Output = T>,
{
    a * (1.0 - t) + b * t
}

/// Microfacet α along dp/du and dp/dv for a roughness and aspect; a NaN
/// aspect (anisotropic > 1/0.9) gives 0.001 as pbrt-v3's `std::max(.001, x)`.
#[inline]
fn alphas(roughness: f32, aspect: f32) -> (f32, f32) {
    let r2 = roughness * roughness;
    ((r2 / aspect).max(0.001_f32), (r2 * aspect).max(0.001_f32))
}

/// Parameters meant to lie in [0, 1] (pbrt-v3 uses any value as given).
const UNIT_PARAMS: [&str; 7] = [
    "metallic",
    "speculartint",
    "anisotropic",
    "sheentint",
    "clearcoatgloss",
    "spectrans",
    "flatness",
];

impl Disney {
    pub fn new(p: &ParamValues) -> Disney {
        let f = |n: &str| p.float_tex(n).expect("default");
        Disney {
            color: p.spectrum_tex("color").expect("default"),
            metallic: f("metallic"),
            eta: f("eta"),
            roughness: f("roughness"),
            specular_tint: f("speculartint"),
            anisotropic: f("anisotropic"),
            sheen: f("sheen"),
            sheen_tint: f("sheentint"),
            clearcoat: f("clearcoat"),
            clearcoat_gloss: f("clearcoatgloss"),
            spec_trans: f("spectrans"),
            scatter_distance: p.spectrum_tex("scatterdistance").expect("default"),
            thin: p.boolean("thin"),
            flatness: f("flatness"),
            diff_trans: f("difftrans"),
        }
    }

    /// What the loader should warn about for these parameters: the
    /// unsupported subsurface part, and values outside the model's range.
    pub fn load_warnings(p: &ParamValues) -> Vec<String> {
        let m = Disney::new(p);
        let mut out = Vec::new();
        let constant = |t: &FloatTex| t.as_constant();
        for name in UNIT_PARAMS {
            if let Some(v) = p.float_tex(name).and_then(|t| t.as_constant()) {
                if !(0.0..=1.0).contains(&v) {
                    out.push(format!(
                        "\"{name}\" is {v}, outside the Disney model's range [0, 1]: used as given (as pbrt-v3)"
                    ));
                }
            }
        }
        if let Some(a) = constant(&m.anisotropic) {
            if 1.0 - 0.9 * a < 0.0 {
                out.push(format!(
                    "\"anisotropic\" {a} > 1/0.9 makes the aspect ratio √(1 − 0.9·anisotropic) undefined: the specular lobes get α = 0.001 (as pbrt-v3)"
                ));
            }
        }
        if let Some(g) = constant(&m.clearcoat_gloss) {
            let alpha = lerp(g, 0.1, 0.001);
            if alpha.abs() >= 1.0 && constant(&m.clearcoat).is_none_or(|c| c > 0.0) {
                out.push(format!(
                    "\"clearcoatgloss\" {g} gives a clearcoat α of {alpha}, where its GTR1 distribution is undefined: the clearcoat's values are not finite"
                ));
            }
        }
        if let Some(d) = constant(&m.diff_trans) {
            if m.thin && !(0.0..=2.0).contains(&d) {
                out.push(format!(
                    "\"difftrans\" is {d}, outside [0, 2] (it transmits difftrans/2 of the diffuse part): used as given (as pbrt-v3)"
                ));
            }
        }
        let sd_black = m.scatter_distance.as_constant() == Some(Vec3::ZERO);
        let diffuse_weight = match (constant(&m.metallic), constant(&m.spec_trans)) {
            (Some(mt), Some(st)) => Some((1.0 - mt) * (1.0 - st)),
            _ => None,
        };
        if !m.thin && !sd_black && diffuse_weight.is_none_or(|w| w > 0.0) {
            out.push(
                "\"scatterdistance\" is not black: subsurface scattering (pbrt-v3's DisneyBSSRDF) is not supported by pbrs: \
                 the diffuse part is rendered as pbrt-v3's BSDF alone has it, a smooth specular transmission into index \"eta\" \
                 in place of the diffuse lobe (pbrt-v3's directlighting and whitted image; its path tracer would scatter the \
                 transmitted light beneath the surface)"
                    .to_string(),
            );
        }
        out
    }

    fn textures(&self) -> [&FloatTex; 12] {
        [
            &self.metallic,
            &self.eta,
            &self.roughness,
            &self.specular_tint,
            &self.anisotropic,
            &self.sheen,
            &self.sheen_tint,
            &self.clearcoat,
            &self.clearcoat_gloss,
            &self.spec_trans,
            &self.flatness,
            &self.diff_trans,
        ]
    }

    pub fn needs_geom(&self) -> bool {
        self.anisotropic()
            || self.color.as_constant().is_none()
            || self.scatter_distance.as_constant().is_none()
            || self.textures().iter().any(|t| t.as_constant().is_none())
    }

    /// The most lobes it adds: thin, every lobe but one of the diffuse
    /// alternatives (8); solid, diffuse or its smooth transmission, retro,
    /// sheen, specular, clearcoat and specular transmission (6).
    pub fn max_lobes(&self) -> usize {
        if self.thin {
            8
        } else {
            6
        }
    }

    /// The specular lobes align with dp/du unless `anisotropic` is 0.
    pub fn anisotropic(&self) -> bool {
        self.anisotropic.as_constant() != Some(0.0)
    }

    #[inline]
    pub fn scatter(&self, sc: &ShadingContext, bsdf: &mut Bsdf) {
        let c = self.color.eval(sc).max(Vec3::ZERO);
        let metallic = self.metallic.eval(sc);
        let eta = self.eta.eval(sc);
        let strans = self.spec_trans.eval(sc);
        let diffuse_weight = (1.0 - metallic) * (1.0 - strans);
        let dt = 0.5 * self.diff_trans.eval(sc);
        let rough = self.roughness.eval(sc);
        // The colour's hue and saturation at unit luminance.
        let lum = luminance(c);
        let c_tint = if lum > 0.0 { c / lum } else { Vec3::ONE };

        if diffuse_weight > 0.0 {
            if self.thin {
                let flat = self.flatness.eval(sc);
                bsdf.add(DisneyDiffuse {
                    r: c * (diffuse_weight * (1.0 - flat) * (1.0 - dt)),
                });
                bsdf.add(DisneyFakeSS {
                    r: c * (diffuse_weight * flat * (1.0 - dt)),
                    roughness: rough,
                });
            } else if self.scatter_distance.eval(sc) == Vec3::ZERO {
                bsdf.add(DisneyDiffuse {
                    r: c * diffuse_weight,
                });
            } else {
                // The BSDF part of pbrt-v3's subsurface path (see above).
                bsdf.add(SpecularTransmission {
                    t: Vec3::ONE,
                    eta_a: 1.0,
                    eta_b: eta,
                });
            }
            bsdf.add(DisneyRetro {
                r: c * diffuse_weight,
                roughness: rough,
            });
            let sheen = self.sheen.eval(sc);
            if sheen > 0.0 {
                let c_sheen = lerp(self.sheen_tint.eval(sc), Vec3::ONE, c_tint);
                bsdf.add(DisneySheen {
                    r: c_sheen * (diffuse_weight * sheen),
                });
            }
        }

        let aspect = (1.0 - 0.9 * self.anisotropic.eval(sc)).sqrt();
        let (ax, ay) = alphas(rough, aspect);
        let distribution = DisneyMicrofacet::new(ax, ay);
        let spec_tint = self.specular_tint.eval(sc);
        let r0 = lerp(
            metallic,
            lerp(spec_tint, Vec3::ONE, c_tint) * schlick_r0_from_eta(eta),
            c,
        );
        bsdf.add(MicrofacetReflection {
            r: Vec3::ONE,
            distribution: distribution.into(),
            fresnel: Fresnel::Disney(DisneyFresnel { r0, metallic, eta }),
        });

        let clearcoat = self.clearcoat.eval(sc);
        if clearcoat > 0.0 {
            bsdf.add(DisneyClearcoat {
                weight: clearcoat,
                alpha: lerp(self.clearcoat_gloss.eval(sc), 0.1, 0.001),
            });
        }

        if strans > 0.0 {
            // √color, so that two refractions give the colour back.
            let t = Vec3::new(c.x.sqrt(), c.y.sqrt(), c.z.sqrt()) * strans;
            let distribution = if self.thin {
                // Thin surfaces scale roughness by the index (Burley 2015,
                // figure 15) and keep Trowbridge–Reitz's correlated G.
                let (ax, ay) = alphas((0.65 * eta - 0.35) * rough, aspect);
                TrowbridgeReitz::new(ax, ay).into()
            } else {
                distribution.into()
            };
            bsdf.add(MicrofacetTransmission {
                t,
                distribution,
                eta_a: 1.0,
                eta_b: eta,
            });
        }
        if self.thin {
            bsdf.add(LambertianTransmission { t: c * dt });
        }
    }
}
