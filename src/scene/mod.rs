//! The plain scene description: what the scene language and scene building hand
//! to the render core. Nothing here knows about text, spans or graphics state,
//! and nothing here knows about rendering: it is data, with pbrt-v3's defaults
//! already applied and every colour already reduced to linear RGB.
//!
//! Transforms are `f64` so that long chains of scene-file transforms do not lose
//! precision before the render core converts geometry to `f32` world space.

pub mod bounds;
mod fourier;
pub mod image;
pub mod kind;
pub mod memory;
pub mod motion;
mod params;
mod textures;

pub use fourier::{FourierTable, FourierTableData, MAX_FOURIER_ORDER};
pub use image::{srgb_to_linear, Decode, RgbImage, SampleDepth, MAX_IMAGE_PIXELS};
pub use kind::{Collected, Kind, Report, Support};
pub use motion::AnimatedTransform;
pub use params::{Elem, ParamKind, ParamSpec, ParamValue, ParamValues, Range, SpectrumDefault};
pub use textures::{FloatTex, SpectrumTex, Tex};

pub use crate::lights::{DiffuseEmission, Light};
use glam::{DMat4, Vec2, Vec3};
use std::path::PathBuf;
use std::sync::Arc;

/// A whole scene, ready to be compiled for rendering.
#[derive(Clone, Debug)]
pub struct SceneDescription {
    pub camera: CameraDesc,
    pub film: FilmDesc,
    pub filter: crate::filters::Filter,
    pub sampler: SamplerDesc,
    pub integrator: IntegratorSettings,
    /// Materials referenced by shapes (by index). Only referenced ones are built.
    pub materials: Vec<MaterialDesc>,
    /// Shapes in world space (their `object_to_world` maps to world).
    pub shapes: Vec<ShapeDesc>,
    /// Lights other than area lights (area lights live on their shapes),
    /// as their kinds built them (what depends on the whole scene is set
    /// when it is built: `Light::preprocess`).
    pub lights: Vec<Light>,
    /// Per entry of `lights`: the medium its emitted rays start in. pbrt-v3
    /// gives point, spot, goniometric and projection lights the outside
    /// medium of the graphics state at their `LightSource`; distant and
    /// infinite lights emit from no medium. Only bdpt's and mlt's light
    /// subpaths start from lights.
    pub light_media: Vec<Option<MediumId>>,
    /// Object definitions that are instanced at least once.
    pub objects: Vec<ObjectDesc>,
    /// Placements of objects.
    pub instances: Vec<InstanceDesc>,
    /// Participating media referenced by the camera or by a shape's
    /// interface (by index: [`MediumId`]).
    pub media: Vec<crate::media::Medium>,
    /// The camera's medium (pbrt-v3: the outside medium of the graphics
    /// state when the camera is made, at WorldEnd).
    pub camera_medium: Option<MediumId>,
    /// Human-readable notes on what was left out and why (unreferenced named
    /// materials, objects never instanced, ...), for `--check` and `--stats`.
    pub skipped: Vec<String>,
}

/// Index into [`SceneDescription::media`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct MediumId(pub u32);

/// pbrt-v3's `MediumInterface` of a shape: the media on the side its
/// normal points away from (`inside`) and towards (`outside`); `None` is
/// vacuum. A shape whose two media are the same is no transition: rays
/// keep the medium they are in when they cross it (as pbrt-v3's
/// `GeometricPrimitive::Intersect`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct MediumInterfaceDesc {
    pub inside: Option<MediumId>,
    pub outside: Option<MediumId>,
}

impl MediumInterfaceDesc {
    pub fn is_transition(&self) -> bool {
        self.inside != self.outside
    }
}

/// Index into [`SceneDescription::materials`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct MaterialId(pub u32);

#[derive(Clone, Debug)]
pub struct CameraDesc {
    /// Camera-to-world transform: inverse of the CTM at the `Camera` directive.
    /// Camera space is pbrt's left-handed one: +z looks forward, +y up, +x right
    /// as seen in the image before any handedness flip in the CTM.
    pub camera_to_world: DMat4,
    /// Camera-to-world over the shutter when the `Camera` directive saw two
    /// different CTMs (`camera_to_world` is then its start transform).
    pub motion: Option<Arc<AnimatedTransform>>,
    /// The camera kind with its settings, as its builder checked them; its
    /// mapping is derived from the film when the scene is compiled.
    pub projection: crate::cameras::Projection,
    pub shutter_open: f32,
    pub shutter_close: f32,
}

impl Default for CameraDesc {
    /// pbrt-v3's camera when the scene has no `Camera`.
    fn default() -> CameraDesc {
        CameraDesc {
            camera_to_world: DMat4::IDENTITY,
            motion: None,
            projection: Default::default(),
            shutter_open: 0.0,
            shutter_close: 1.0,
        }
    }
}

#[derive(Clone, Debug)]
pub struct FilmDesc {
    pub xresolution: u32,
    pub yresolution: u32,
    /// [x0, x1, y0, y1] in NDC, already clamped to [0,1] and ordered.
    pub cropwindow: [f32; 4],
    /// Output file name as written in the scene (relative to the working
    /// directory, as pbrt-v3 does); the command line may override it.
    pub filename: PathBuf,
    pub scale: f32,
    pub max_sample_luminance: f32,
    /// Physical film diagonal in millimetres (`diagonal`; the realistic
    /// camera's sensor size).
    pub diagonal: f32,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SamplerKind {
    Halton,
    Random,
    Sobol,
    /// Stratified with jitter; `pixelsamples` is xsamples*ysamples.
    Stratified {
        jitter: bool,
        xsamples: u32,
        ysamples: u32,
    },
    /// `dimensions`: how many 1D and 2D dimensions take the pattern.
    ZeroTwoSequence {
        dimensions: u32,
    },
    MaxMinDist {
        dimensions: u32,
    },
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SamplerDesc {
    pub kind: SamplerKind,
    pub pixel_samples: u32,
    /// Halton's `samplepixelcenter`.
    pub sample_pixel_center: bool,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightSampleStrategy {
    Uniform,
    Power,
    Spatial,
    /// A light BVH (a pbrs extension: pbrt-v4's BVHLightSampler).
    Bvh,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DirectStrategy {
    All,
    One,
}

/// The integrator: a kind's settings, built by its row of
/// `integrators::INTEGRATORS`.
pub use crate::integrators::{
    DirectLightingSettings, IntegratorSettings, PathSettings, VolPathSettings, WhittedSettings,
};

/// A material: its kind (a name in `materials::MATERIALS`) and the
/// values of the parameters that kind declares, defaults applied.
/// `Material "none"` / `""` is the kind "none" (no BSDF: the surface only
/// delimits media).
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialDesc {
    pub kind: &'static str,
    pub params: ParamValues,
}

impl MaterialDesc {
    /// A spectrum parameter's value if it is a constant.
    pub fn constant_spectrum(&self, name: &str) -> Option<Vec3> {
        self.params.spectrum_tex(name)?.as_constant()
    }
    /// A float-texture parameter's value if it is a constant.
    pub fn constant_float(&self, name: &str) -> Option<f32> {
        self.params.float_tex(name)?.as_constant()
    }
}

#[derive(Clone, Debug)]
pub struct ShapeDesc {
    pub surface: Surface,
    pub object_to_world: DMat4,
    /// Object-to-world over time when the shape's start and end CTMs differ
    /// (`object_to_world` is then the start transform). `None` for every
    /// static shape.
    pub motion: Option<Arc<AnimatedTransform>>,
    pub reverse_orientation: bool,
    pub material: MaterialId,
    /// What the `AreaLightSource` in scope says (each of the shape's
    /// triangles, or the shape, becomes a `DiffuseLight` when the scene is
    /// built).
    pub area_light: Option<DiffuseEmission>,
    /// pbrt-v3's `alpha` mask (triangle meshes): hits where it is 0 are
    /// ignored by every ray. `None`: no test.
    pub alpha: Option<FloatTex>,
    /// pbrt-v3's `shadowalpha`: hits where it is 0 are ignored by shadow
    /// rays.
    pub shadow_alpha: Option<FloatTex>,
    /// The media on either side (the `MediumInterface` current at the
    /// shape).
    pub medium_interface: MediumInterfaceDesc,
}

/// A shape as its kind built it (`shapes::SHAPES`), in its object
/// space; the render core places it (once per instance for shapes inside
/// `ObjectBegin`).
#[derive(Clone, Debug)]
pub enum Surface {
    /// Vertices in object space (`trianglemesh`, the mesh files and the
    /// refined shapes).
    TriangleMesh(Arc<MeshData>),
    /// pbrt-v3's `curve`, as cubic Bézier segments (bspline and degree-2
    /// input already converted); placed as 2^splitdepth pieces per segment.
    Curve(Arc<CurveData>),
    /// A sphere, disk, cylinder, cone, paraboloid or hyperboloid: the
    /// render core's own analytic shape, built at the origin (identity
    /// transform) and placed with `AnalyticShape::placed`.
    Analytic(crate::shapes::AnalyticShape),
}

/// pbrt-v3's curve types.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CurveKind {
    Flat,
    Ribbon,
    Cylinder,
}

/// One cubic Bézier segment of a curve (object space).
#[derive(Clone, Debug)]
pub struct CurveSegment {
    pub cp: [glam::Vec3; 4],
    /// Widths at the segment's ends (> 0).
    pub width: [f32; 2],
    /// Ribbon normals at the segment's ends (ribbons only).
    pub normals: Option<[glam::Vec3; 2]>,
}

/// A `curve` shape: its segments, each split into 2^`split_depth` pieces.
#[derive(Clone, Debug)]
pub struct CurveData {
    pub kind: CurveKind,
    pub segments: Vec<CurveSegment>,
    pub split_depth: u32,
}

/// Triangle mesh data in object space, shared between shapes and instances.
#[derive(Clone, Debug, Default)]
pub struct MeshData {
    /// Shared with the render's world-space mesh (positions too when the
    /// shape's transform is the identity), so a big mesh is held once.
    pub positions: std::sync::Arc<Vec<Vec3>>,
    /// Three per triangle, every index < positions.len().
    pub indices: std::sync::Arc<Vec<u32>>,
    /// Per-vertex normals (same length as positions) if given.
    pub normals: Option<Vec<Vec3>>,
    /// Per-vertex uv (same length as positions) if given.
    pub uvs: Option<Vec<Vec2>>,
    /// Per-triangle Ptex face ids (`faceIndices`; one per triangle) if given.
    pub face_indices: Option<Vec<i32>>,
}

impl MeshData {
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }
}

#[derive(Clone, Debug)]
pub struct ObjectDesc {
    pub name: String,
    /// Shapes with transforms relative to the object's space. As pbrt-v3 records
    /// them, a shape's `object_to_world` is the CTM at its `Shape` statement inside
    /// `ObjectBegin` (the CTM is not reset by `ObjectBegin`); its world transform is
    /// `instance.instance_to_world * shape.object_to_world`. Area lights are never
    /// set here (pbrt-v3 ignores them inside object definitions).
    pub shapes: Vec<ShapeDesc>,
}

#[derive(Clone, Debug)]
pub struct InstanceDesc {
    /// Index into [`SceneDescription::objects`].
    pub object: usize,
    pub instance_to_world: DMat4,
    /// Instance-to-world over time when the start and end CTMs differ
    /// (`instance_to_world` is then the start transform).
    pub motion: Option<Arc<AnimatedTransform>>,
}
