//! `marble` (spectrum only): bands of a colour spline along y, perturbed by
//! FBm (pbrt-v3's `MarbleTexture`).
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `octaves` | integer | 8 | most FBm octaves |
//! | `roughness` | float | 0.5 | FBm amplitude factor per octave (ω) |
//! | `scale` | float | 1 | scale of the 3D-mapped point |
//! | `variation` | float | 0.2 | amplitude of the perturbation |
//!
//! t = ½ + ½·sin(p.y + variation·FBm(p)) selects a cubic Bézier segment of
//! pbrt-v3's nine colours; as in pbrt-v3 only the first two segments are
//! used (its segment index is min(1, ⌊6t⌋)), and the value is ×1.5.
//! pbrt-v3 makes no float `marble` texture (the name stays undefined).

use super::noise::fbm;
use super::{Class, Mapping3D, MappingUse, Support, TexBuild, TexBuilder, Texture, TextureClass};
use crate::materials::ShadingContext;
use crate::scene::{ParamSpec, Tex};
use glam::Vec3;

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::int("octaves", 8, "most octaves"),
    ParamSpec::float("roughness", 0.5, "amplitude factor per octave"),
    ParamSpec::float("scale", 1.0, "scale of the point"),
    ParamSpec::float("variation", 0.2, "amplitude of the FBm perturbation"),
];

pub const CLASS: TextureClass = TextureClass {
    name: "marble",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "marble veins: a colour spline of sin(y + variation·FBm)",
    build: TexBuild {
        mapping: MappingUse::ThreeD,
        float: None,
        spectrum: Some(build),
    },
};

/// pbrt-v3's marble colours (textures/marble.h).
pub const COLORS: [[f32; 3]; 9] = [
    [0.58, 0.58, 0.6],
    [0.58, 0.58, 0.6],
    [0.58, 0.58, 0.6],
    [0.5, 0.5, 0.5],
    [0.6, 0.59, 0.58],
    [0.58, 0.58, 0.6],
    [0.58, 0.58, 0.6],
    [0.2, 0.2, 0.33],
    [0.58, 0.58, 0.6],
];

pub struct Marble {
    pub mapping: Mapping3D,
    pub octaves: i32,
    pub omega: f32,
    pub scale: f32,
    pub variation: f32,
}

fn build(b: &mut TexBuilder) -> Result<Tex<Vec3>, String> {
    Ok(Texture::new_handle(
        b.name,
        Class::Marble(Marble {
            mapping: b.mapping3d,
            octaves: b.params.int("octaves").min(super::noise::MAX_OCTAVES),
            omega: b.params.float("roughness"),
            scale: b.params.float("scale"),
            variation: b.params.float("variation"),
        }),
    ))
}

impl Marble {
    pub fn eval(&self, sc: &ShadingContext) -> Vec3 {
        let (p, dpdx, dpdy) = self.mapping.map(sc);
        let p = p * self.scale;
        let m = p.y
            + self.variation
                * fbm(
                    p,
                    self.scale * dpdx,
                    self.scale * dpdy,
                    self.omega,
                    self.octaves,
                );
        spline(0.5 + 0.5 * m.sin())
    }
}

/// pbrt-v3's spline of [`COLORS`] at `t` (de Casteljau), ×1.5.
pub fn spline(t: f32) -> Vec3 {
    const NSEG: f32 = (COLORS.len() - 3) as f32;
    let first = ((t * NSEG).floor() as i32).min(1);
    let t = t * NSEG - first as f32;
    // (first is 0 or 1 for t ≥ 0; a NaN t gives 0.)
    let first = first.max(0) as usize;
    let c = |i: usize| Vec3::from_array(COLORS[first + i]);
    let (c0, c1, c2, c3) = (c(0), c(1), c(2), c(3));
    let s0 = (1.0 - t) * c0 + t * c1;
    let s1 = (1.0 - t) * c1 + t * c2;
    let s2 = (1.0 - t) * c2 + t * c3;
    let s0 = (1.0 - t) * s0 + t * s1;
    let s1 = (1.0 - t) * s1 + t * s2;
    1.5 * ((1.0 - t) * s0 + t * s1)
}
