//! The render core: geometry, shapes, acceleration, materials, lights,
//! samplers, integrators and film. It consumes a [`crate::scene::SceneDescription`].

pub mod accel;
pub mod bssrdf;
pub mod bxdf;
pub mod camera;
pub mod driver;
pub mod film;
pub mod filters;
pub mod geometry;
pub mod integrators;
pub mod lights;
pub mod materials;
pub mod media;
pub mod samplers;
pub mod sampling;
pub mod scene;
pub mod shapes;
pub mod textures;
