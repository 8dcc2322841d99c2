//! Subsurface scattering: pbrt-v3's tabulated BSSRDF (core/bssrdf.{h,cpp}).
//!
//! - [`table`]: the photon-beam-diffusion profile table (`BSSRDFTable`,
//!   `ComputeBeamDiffusionBSSRDF`) and `SubsurfaceFromDiffuse`.
//! - [`tabulated`]: `TabulatedBSSRDF`'s Sr, Sample_Sr, Pdf_Sr and the
//!   separable BSSRDF's Sw.
//!
//! - [`probe`]: the geometry of probe-ray sampling (Sample_Sp's axis,
//!   channel and segment; Pdf_Sp).
//!
//! The Sw adapter lobe is `bxdf::SwAdapter`. Still to come (see the
//! branch's WIP notes): the probe intersection loop and the integrator
//! hooks.

pub mod probe;
pub mod table;
pub mod tabulated;

pub use table::{subsurface_from_diffuse, BssrdfTable};
pub use tabulated::TabulatedBssrdf;
