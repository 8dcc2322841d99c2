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
