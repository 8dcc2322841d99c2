//! `mix`: a blend of two named materials (pbrt-v3's `MixMaterial`): the
//! lobes of `namedmaterial1` weighted by `amount` and those of
//! `namedmaterial2` weighted by 1 − `amount`, both clamped ≥ 0. The shading
//! frame and η are material 1's, bumped by material 1's `bumpmap` if it has
//! one (material 2's bump map is ignored, as in pbrt-v3, where material 2's
//! lobes join material 1's BSDF). `mix` itself has no `bumpmap` (pbrt-v3's
//! `MixMaterial` does not bump). Mixes nest.
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `amount` | spectrum texture | 0.5 | weight of material 1 |
//! | `namedmaterial1` | string | | first material (undefined: a matte, with a warning) |
//! | `namedmaterial2` | string | | second material (undefined: a matte, with a warning) |
//!
//! The loader resolves the names into material indices that precede the
//! mix's own, so references cannot loop. A BSDF holds at most `MAX_BXDFS`
//! lobes: pbrt-v3 aborts beyond, pbrs warns at load time when a mix could
//! exceed it ([`Mix::max_lobes`]) and drops the extra lobes.

use super::{BsdfContext, Material, MaterialKind, ShadingContext, Support};
use crate::bxdf::Bsdf;
use crate::scene::{FloatTex, MaterialId, ParamSpec, ParamValues, SpectrumTex};
use glam::Vec3;

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::spectrum("amount", 0.5, "weight of material 1"),
    ParamSpec::named_material("namedmaterial1", "first material"),
    ParamSpec::named_material("namedmaterial2", "second material"),
];

pub const KIND: MaterialKind = MaterialKind {
    name: "mix",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "a blend of two named materials",
    build: |p| Material::Mix(Mix::new(p)),
};

#[derive(Clone, Debug)]
pub struct Mix {
    pub amount: SpectrumTex,
    /// Indices into the scene's materials (`None`: nothing, never from
    /// the loader).
    pub m1: Option<MaterialId>,
    pub m2: Option<MaterialId>,
    /// Whether either material is anisotropic or needs differential
    /// geometry, known once the materials are [`super::link_materials`]ed.
    pub anisotropic: bool,
    pub needs_geom: bool,
    /// Material 1's bump map (through nested mixes), which bumps the hit
    /// before either material's lobes are built.
    pub leading_bump: Option<FloatTex>,
}

impl Mix {
    pub fn new(p: &ParamValues) -> Mix {
        let amount = p.spectrum_tex("amount").expect("default");
        Mix {
            needs_geom: amount.as_constant().is_none(),
            amount,
            m1: p.material("namedmaterial1"),
            m2: p.material("namedmaterial2"),
            anisotropic: false,
            leading_bump: None,
        }
    }

    /// Takes the two materials' needs; `before` are the materials preceding
    /// this one (references elsewhere are dropped: they could loop).
    pub fn link(&mut self, before: &[Material]) {
        let valid = |m: Option<MaterialId>| m.filter(|id| (id.0 as usize) < before.len());
        self.m1 = valid(self.m1);
        self.m2 = valid(self.m2);
        for m in [self.m1, self.m2].into_iter().flatten() {
            let m = &before[m.0 as usize];
            self.anisotropic |= m.anisotropic();
            self.needs_geom |= m.needs_geom();
        }
        self.needs_geom |= self.anisotropic;
        self.leading_bump = self
            .m1
            .and_then(|m| before[m.0 as usize].leading_bump().cloned());
    }

    /// The most lobes the mix can add, given the same count for the
    /// materials it refers to.
    pub fn max_lobes(&self, lobes_of: &dyn Fn(MaterialId) -> usize) -> usize {
        [self.m1, self.m2].into_iter().flatten().map(lobes_of).sum()
    }

    #[inline]
    pub fn scatter<'a>(&self, sc: &ShadingContext, ctx: &BsdfContext<'a>, bsdf: &mut Bsdf<'a>) {
        let s1 = self.amount.eval(sc).max(Vec3::ZERO);
        let s2 = (Vec3::ONE - s1).max(Vec3::ZERO);
        let material = |m: Option<MaterialId>| m.and_then(|id| ctx.materials.get(id.0 as usize));
        let first = bsdf.lobes().len();
        bsdf.eta = 1.0;
        if let Some(m) = material(self.m1) {
            m.scatter(sc, ctx, bsdf);
        }
        let eta = bsdf.eta;
        bsdf.scale_from(first, s1);
        let second = bsdf.lobes().len();
        if let Some(m) = material(self.m2) {
            m.scatter(sc, ctx, bsdf);
        }
        bsdf.scale_from(second, s2);
        bsdf.eta = eta;
    }
}
