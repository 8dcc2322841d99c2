//! What makes the image: compiling the scene description into the render-ready
//! scene ([`compile`]), the render loop over tiles and threads ([`driver`]) and
//! the film with its image files ([`film`]). The families it drives (shapes,
//! lights, cameras, materials, integrators, ...) are modules of their own.

pub mod compile;
pub mod driver;
pub mod film;
