//! Texture evaluation at a hit. Today every texture is a constant; the
//! textures issue adds the rest (with ray differentials).

use crate::render::materials::ShadingContext;
use crate::scene::{FloatTex, SpectrumTex};
use glam::Vec3;

impl FloatTex {
    #[inline]
    pub fn eval(&self, _sc: &ShadingContext) -> f32 {
        match self {
            FloatTex::Constant(v) => *v,
        }
    }
}

impl SpectrumTex {
    #[inline]
    pub fn eval(&self, _sc: &ShadingContext) -> Vec3 {
        match self {
            SpectrumTex::Constant(v) => *v,
        }
    }
}
