//! The render-ready scene: world-space geometry with its BVH, the materials,
//! lights, media and camera, as the integrators trace them.
//! `crate::render::compile` makes it from the scene description
//! ([`RenderScene::new`]); only what the scene references is built.

use crate::accel::Aggregate;
use crate::cameras::Camera;
use crate::lights::Light;
use crate::materials::Material;
use crate::media::Medium;

pub struct RenderScene {
    pub aggregate: Aggregate,
    pub materials: Vec<Material>,
    /// `materials[i].needs_geom()`, computed once: the answer walks the
    /// material's textures (and a mix's materials), too much for every hit.
    pub material_needs_geom: Vec<bool>,
    pub lights: Vec<Light>,
    /// Indices of infinite lights (seen by rays that escape).
    pub infinite_lights: Vec<u32>,
    pub camera: Camera,
    /// Camera rays carry differentials (some material reads the
    /// differential geometry, so textures can filter and bump maps step).
    pub differentials: bool,
    /// What was built and what was skipped, for `--stats`.
    pub notes: Vec<String>,
    /// The scene's media (indices are the description's `MediumId`s).
    pub media: Vec<Medium>,
    /// The medium the camera is in.
    pub camera_medium: Option<u32>,
    /// One per entry of `lights`: the medium its emitted rays start in
    /// (bdpt's and mlt's light subpaths; `Some` only in a scene with media).
    pub light_media: Vec<Option<u32>>,
    /// By material slot: the media on either side of the surfaces that
    /// use it, for shapes that are medium transitions (`None`: rays keep
    /// their medium). A shape that is a transition gets a slot of its own
    /// per (material, interface), a copy of its material, so that hits
    /// find their interface from the material index they carry anyway:
    /// nothing is added to hits or primitives, and scenes without media
    /// never look at this table.
    pub surface_media: Vec<Option<SurfaceMedia>>,
    /// Some material is `none` (rays pass through it).
    pub has_pass_through: bool,
}

/// The media on the two sides of a surface (pbrt-v3's `MediumInterface`
/// of a transition); `None` is vacuum.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SurfaceMedia {
    pub inside: Option<u32>,
    pub outside: Option<u32>,
}
