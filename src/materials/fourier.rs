//! `fourier`: a measured or precomputed BSDF tabulated in pbrt-v3's Fourier
//! basis (a `.bsdf` file, e.g. a layered material made with layerlab).
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `bsdffile` | string | (none: warning, black) | the `.bsdf` file, relative to the top-level scene file's directory (pbrt-v3's search directory, also for an `Include`d file's materials); read once per scene |
//! | `bumpmap` | float texture | | displacement for bump mapping (every material: `bump.rs`) |
//!
//! One [`FourierBsdf`] lobe (reflection and transmission, glossy); the
//! BSDF's η stays 1 as in pbrt-v3. Without a readable file (not given, or
//! the loader warned about it) the material has no lobe and renders black,
//! as pbrt-v3's when its table failed to load. The table is isotropic, so
//! any shading frame around the normal will do, and it reads no texture.

use super::{Material, MaterialKind, ShadingContext, Support};
use crate::bxdf::{Bsdf, FourierBsdf};
use crate::scene::{FourierTable, ParamSpec, ParamValues};
use std::sync::Arc;

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::fourier_file(
        "bsdffile",
        "tabulated BSDF (pbrt-v3's `.bsdf` format), relative to the top-level scene file's directory; read once per scene; missing or malformed: warning, black",
    ),
    ParamSpec::BUMPMAP,
];

pub const KIND: MaterialKind = MaterialKind {
    name: "fourier",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "a BSDF tabulated in a Fourier basis (`.bsdf` file)",
    build: |p| Material::Fourier(Fourier::new(p)),
};

#[derive(Clone, Debug)]
pub struct Fourier {
    /// `None`: no readable file (the loader warned).
    pub table: Option<Arc<FourierTable>>,
}

impl Fourier {
    pub fn new(p: &ParamValues) -> Fourier {
        Fourier {
            table: p.fourier("bsdffile"),
        }
    }

    pub fn needs_geom(&self) -> bool {
        false
    }

    pub fn max_lobes(&self) -> usize {
        1
    }

    #[inline]
    pub fn scatter<'a>(&'a self, _sc: &ShadingContext, bsdf: &mut Bsdf<'a>) {
        if let Some(t) = &self.table {
            bsdf.add(FourierBsdf::new(t));
        }
    }
}
