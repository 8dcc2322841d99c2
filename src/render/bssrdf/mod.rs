//! Subsurface scattering: pbrt-v3's tabulated BSSRDF (core/bssrdf.{h,cpp}).
//!
//! - [`table`]: the photon-beam-diffusion profile table (`BSSRDFTable`,
//!   `ComputeBeamDiffusionBSSRDF`) and `SubsurfaceFromDiffuse`.
//! - [`tabulated`]: `TabulatedBSSRDF`'s Sr, Sample_Sr, Pdf_Sr and the
//!   separable BSSRDF's Sw.
//!
//! Still to come (see the branch's WIP notes): probe-ray sampling of the
//! exit point (Sample_Sp, Pdf_Sp), the Sw adapter BxDF and the integrator
//! hooks.

pub mod table;
pub mod tabulated;

pub use table::{subsurface_from_diffuse, BssrdfTable};
pub use tabulated::TabulatedBssrdf;
