//! Texture handles: what a material parameter refers to. Today a constant;
//! the textures issue adds image, procedural and mixing textures here (as
//! data; their evaluation is in `render::textures`).

use glam::Vec3;

/// A float-valued texture.
#[derive(Clone, Debug, PartialEq)]
pub enum FloatTex {
    Constant(f32),
}

/// A spectrum-valued (linear RGB) texture.
#[derive(Clone, Debug, PartialEq)]
pub enum SpectrumTex {
    Constant(Vec3),
}

impl FloatTex {
    /// The value if it does not vary over the surface.
    pub fn as_constant(&self) -> Option<f32> {
        match self {
            FloatTex::Constant(v) => Some(*v),
        }
    }
}

impl SpectrumTex {
    pub fn as_constant(&self) -> Option<Vec3> {
        match self {
            SpectrumTex::Constant(v) => Some(*v),
        }
    }
}
