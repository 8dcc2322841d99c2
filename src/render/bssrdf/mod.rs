//! Subsurface scattering: pbrt-v3's tabulated BSSRDF (core/bssrdf.{h,cpp}).
//!
//! - [`table`]: the photon-beam-diffusion profile table (`BSSRDFTable`,
//!   `ComputeBeamDiffusionBSSRDF`) and `SubsurfaceFromDiffuse`.
//!
//! Still to come (see the branch's WIP notes): `TabulatedBSSRDF` (Sr,
//! Sample_Sr, Pdf_Sr), probe-ray sampling of the exit point (Sample_Sp,
//! Pdf_Sp), the Sw adapter BxDF and the integrator hooks.

pub mod table;

pub use table::{subsurface_from_diffuse, BssrdfTable};
