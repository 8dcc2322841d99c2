//! Texture handles: what a material, shape or texture parameter refers to.
//!
//! A handle is a constant (the common case, kept a plain value so that
//! reading it costs a field read and a predicted branch) or a shared,
//! immutable texture: its class, mapping and parameters as built by
//! `textures` from a `Texture` statement (pbrt-v3 semantics: a
//! texture refers to the textures defined before it, by value, so the graph
//! is a tree of `Arc`s fixed at load time). Evaluation is in
//! `textures`.

use crate::textures::Texture;
use glam::Vec3;
use std::fmt;
use std::sync::Arc;

/// A texture of values `T` (`f32` or linear RGB).
#[derive(Clone)]
pub enum Tex<T> {
    Constant(T),
    Texture(Arc<Texture<T>>),
}

/// A float-valued texture.
pub type FloatTex = Tex<f32>;
/// A spectrum-valued (linear RGB) texture.
pub type SpectrumTex = Tex<Vec3>;

impl<T: Copy> Tex<T> {
    /// The value if it does not vary over the surface.
    #[inline]
    pub fn as_constant(&self) -> Option<T> {
        match self {
            Tex::Constant(v) => Some(*v),
            Tex::Texture(_) => None,
        }
    }
}

/// Two handles are equal if they are equal constants or the same texture
/// (materials that refer to the same texture are the same material).
impl<T: PartialEq> PartialEq for Tex<T> {
    fn eq(&self, other: &Self) -> bool {
        match (self, other) {
            (Tex::Constant(a), Tex::Constant(b)) => a == b,
            (Tex::Texture(a), Tex::Texture(b)) => Arc::ptr_eq(a, b),
            _ => false,
        }
    }
}

/// A texture prints as its name and identity, not its data (MIP maps can
/// be large, and the loader keys materials by their printed description).
impl<T: fmt::Debug> fmt::Debug for Tex<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Tex::Constant(v) => write!(f, "Constant({v:?})"),
            Tex::Texture(t) => write!(f, "Texture(#{} \"{}\" {})", t.id, t.name, t.class_name()),
        }
    }
}
