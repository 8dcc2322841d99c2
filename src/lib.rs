//! pbrs: a physically based renderer for scenes in the pbrt-v3 file format.
//!
//! Data flows one way:
//! scene text → [`lang`] (tokens, directives, diagnostics)
//! → [`loader`] (graphics state → [`scene::SceneDescription`])
//! → [`render`] (render-ready scene, integrators, film) → image.
//! The command line ([`cli`]) sits on top.

pub mod cli;
pub mod lang;
pub mod loader;
pub mod render;
pub mod scene;

// The render core's primitives and pluggable families: the scene description
// holds what their kinds build, and `render` drives them.
pub mod accel;
pub mod bssrdf;
pub mod bxdf;
pub mod cameras;
pub mod filters;
pub mod geometry;
pub mod image;
pub mod integrators;
pub mod lights;
pub mod materials;
pub mod media;
pub mod samplers;
pub mod sampling;
pub mod shapes;
pub mod textures;
