//! The summary `pbrs --check` prints: options and counts by type.

use crate::materials::{self, Support};
use crate::scene::*;
use std::collections::BTreeMap;
use std::fmt;

/// Counts of what a scene holds, for `--check` and tests.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Summary {
    pub camera: String,
    pub film: String,
    pub filter: String,
    pub sampler: String,
    pub integrator: String,
    /// Shapes placed directly in the world.
    pub shapes: usize,
    /// Shapes by kind (`trianglemesh`, `sphere`), world shapes only.
    pub shapes_by_type: BTreeMap<&'static str, usize>,
    /// Triangles of world shapes.
    pub triangles: usize,
    /// Shapes that emit (area lights), world shapes only.
    pub area_lights: usize,
    /// Lights other than area lights, by type.
    pub lights_by_type: BTreeMap<&'static str, usize>,
    /// Materials built (distinct), by the type declared for them, a name in
    /// `materials::MATERIALS` (an unsupported type counts under its
    /// own name, though it is rendered as a matte).
    pub materials_by_type: BTreeMap<&'static str, usize>,
    /// Materials of types pbrs does not know (read as mattes), by type.
    pub unknown_materials: BTreeMap<String, usize>,
    /// Textures defined (`Texture` statements that made one), by class.
    pub textures_by_class: BTreeMap<&'static str, usize>,
    /// World shapes with an `alpha` or `shadowalpha` mask.
    pub alpha_shapes: usize,
    pub objects: usize,
    pub object_shapes: usize,
    pub object_triangles: usize,
    pub instances: usize,
    /// Animated world shapes, animated instances, and whether the camera
    /// moves: the motion structures the render builds (none if all are 0).
    pub moving_shapes: usize,
    pub moving_instances: usize,
    pub moving_camera: bool,
    pub shutter: (f32, f32),
    pub warnings: usize,
    /// Media built, one line each: name, type, coefficients.
    pub media: Vec<String>,
    /// The camera's medium, if any.
    pub camera_medium: Option<String>,
    /// World shapes that are medium transitions (different media inside and out).
    pub medium_boundaries: usize,
}

impl Summary {
    pub fn of(
        scene: &SceneDescription,
        material_kinds: &[DeclaredKind],
        warnings: usize,
    ) -> Summary {
        let mut s = Summary {
            warnings,
            ..Default::default()
        };
        s.camera = scene.camera.projection.describe();
        let f = &scene.film;
        s.film = format!(
            "{}×{}, \"{}\"",
            f.xresolution,
            f.yresolution,
            f.filename.display()
        );
        if f.cropwindow != [0.0, 1.0, 0.0, 1.0] {
            s.film += &format!(", crop {:?}", f.cropwindow);
        }
        s.filter = scene.filter.describe();
        let kind = match scene.sampler.kind {
            SamplerKind::Halton => "halton".to_string(),
            SamplerKind::Random => "random".into(),
            SamplerKind::Sobol => "sobol".into(),
            SamplerKind::Stratified {
                jitter,
                xsamples,
                ysamples,
            } => format!(
                "stratified {xsamples}×{ysamples}{}",
                if jitter { ", jittered" } else { "" }
            ),
            SamplerKind::ZeroTwoSequence { .. } => "02sequence".into(),
            SamplerKind::MaxMinDist { .. } => "maxmindist".into(),
        };
        s.sampler = format!("{kind}, {} samples per pixel", scene.sampler.pixel_samples);
        s.integrator = scene.integrator.summary();
        s.media = scene.media.iter().map(|m| m.describe()).collect();
        s.camera_medium = scene
            .camera_medium
            .and_then(|id| scene.media.get(id.0 as usize))
            .map(|m| m.name.clone());
        s.medium_boundaries = scene
            .shapes
            .iter()
            .filter(|sh| sh.medium_interface.is_transition())
            .count();
        for sh in &scene.shapes {
            s.shapes += 1;
            *s.shapes_by_type
                .entry(crate::shapes::kind_name(&sh.surface))
                .or_default() += 1;
            s.triangles += triangles(&sh.surface);
            s.area_lights += usize::from(sh.area_light.is_some());
            s.alpha_shapes += usize::from(sh.alpha.is_some() || sh.shadow_alpha.is_some());
        }
        for l in &scene.lights {
            *s.lights_by_type.entry(l.name()).or_default() += 1;
        }
        for k in material_kinds {
            match k {
                DeclaredKind::Table(k) => *s.materials_by_type.entry(k).or_default() += 1,
                DeclaredKind::Unknown(k) => *s.unknown_materials.entry(k.clone()).or_default() += 1,
            }
        }
        s.objects = scene.objects.len();
        for o in &scene.objects {
            s.object_shapes += o.shapes.len();
            s.object_triangles += o
                .shapes
                .iter()
                .map(|sh| triangles(&sh.surface))
                .sum::<usize>();
        }
        s.instances = scene.instances.len();
        s.moving_shapes = scene.shapes.iter().filter(|x| x.motion.is_some()).count();
        s.moving_instances = scene
            .instances
            .iter()
            .filter(|x| x.motion.is_some())
            .count();
        s.moving_camera = scene.camera.motion.is_some();
        s.shutter = (scene.camera.shutter_open, scene.camera.shutter_close);
        s
    }
}

/// The type a built material was declared with.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum DeclaredKind {
    /// A kind of `materials::MATERIALS`.
    Table(&'static str),
    /// A type pbrs does not know (built as a matte).
    Unknown(String),
}

fn triangles(g: &Surface) -> usize {
    match g {
        Surface::TriangleMesh(m) => m.triangle_count(),
        _ => 0,
    }
}

fn by_type(m: &BTreeMap<&'static str, usize>) -> String {
    if m.is_empty() {
        return "none".into();
    }
    m.iter()
        .map(|(k, v)| format!("{v} {k}"))
        .collect::<Vec<_>>()
        .join(", ")
}

impl fmt::Display for Summary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "camera:     {}", self.camera)?;
        writeln!(f, "film:       {}", self.film)?;
        writeln!(f, "filter:     {}", self.filter)?;
        writeln!(f, "sampler:    {}", self.sampler)?;
        writeln!(f, "integrator: {}", self.integrator)?;
        writeln!(
            f,
            "shapes:     {} ({})",
            self.shapes,
            by_type(&self.shapes_by_type)
        )?;
        writeln!(f, "triangles:  {}", self.triangles)?;
        let lights: usize = self.lights_by_type.values().sum();
        writeln!(
            f,
            "lights:     {} ({} area-light shapes; {})",
            lights + self.area_lights,
            self.area_lights,
            by_type(&self.lights_by_type)
        )?;
        let mut kinds: Vec<String> = self
            .materials_by_type
            .iter()
            .map(|(k, v)| format!("{v} {k}"))
            .collect();
        kinds.extend(
            self.unknown_materials
                .iter()
                .map(|(k, v)| format!("{v} \"{k}\" (unknown)")),
        );
        let total = self.materials_by_type.values().sum::<usize>()
            + self.unknown_materials.values().sum::<usize>();
        let kinds = if kinds.is_empty() {
            "none".to_string()
        } else {
            kinds.join(", ")
        };
        writeln!(f, "materials:  {total} ({kinds})")?;
        for k in self.materials_by_type.keys() {
            if let Some(Support::Unsupported(why)) = materials::kind(k).map(|m| m.support) {
                writeln!(
                    f,
                    "            {k}: not supported by pbrs ({why}), rendered as matte"
                )?;
            }
        }
        if !self.unknown_materials.is_empty() {
            let names: Vec<String> = self
                .unknown_materials
                .keys()
                .map(|k| format!("\"{k}\""))
                .collect();
            writeln!(
                f,
                "            {}: unknown material type{}, read as matte (as pbrt-v3)",
                names.join(", "),
                if names.len() == 1 { "" } else { "s" }
            )?;
        }
        if !self.textures_by_class.is_empty() {
            writeln!(
                f,
                "textures:   {} ({})",
                self.textures_by_class.values().sum::<usize>(),
                by_type(&self.textures_by_class)
            )?;
        }
        if self.alpha_shapes > 0 {
            writeln!(
                f,
                "alpha:      {} shapes with alpha masks",
                self.alpha_shapes
            )?;
        }
        if self.objects > 0 || self.instances > 0 {
            writeln!(
                f,
                "objects:    {} ({} shapes, {} triangles), {} instances",
                self.objects, self.object_shapes, self.object_triangles, self.instances
            )?;
        }
        if !self.media.is_empty() {
            writeln!(
                f,
                "media:      {} (camera in {}; {} shapes are medium boundaries)",
                self.media.len(),
                self.camera_medium
                    .as_ref()
                    .map_or("none".to_string(), |n| format!("\"{n}\"")),
                self.medium_boundaries
            )?;
            for m in &self.media {
                writeln!(f, "            {m}")?;
            }
        }
        if self.moving_shapes + self.moving_instances > 0 || self.moving_camera {
            writeln!(
                f,
                "motion:     {} animated shapes, {} animated instances, {} camera, shutter {}..{} (motion structures built)",
                self.moving_shapes,
                self.moving_instances,
                if self.moving_camera { "moving" } else { "still" },
                self.shutter.0,
                self.shutter.1
            )?;
        } else {
            writeln!(f, "motion:     none (no motion structures built)")?;
        }
        write!(f, "warnings:   {}", self.warnings)
    }
}
