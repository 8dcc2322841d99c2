//! Geometry: rays, bounds, frames, transforms and robust ray origins.

mod bounds;
pub use bounds::Bounds2i;
