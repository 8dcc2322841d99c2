//! The walk over statements with pbrt-v3's graphics state (api.cpp): CTM, attribute
//! and transform stacks, current and named materials, textures, area light,
//! ReverseOrientation, object definitions, and the option directives. A
//! `Shape` statement with the state current at it (transforms and motion,
//! media, area light, material) is built in `state/shape.rs`.

use super::material::{self, MaterialSpec};
use super::params::Lookup;
use super::params::Textures;
use super::texture::{self as texture, Defined, TextureState};
use super::Ctx;
use super::{lights, options};
use crate::bxdf::MAX_BXDFS;
use crate::lang::parser::{ActiveKind, DirKind, Directive, Name, Stmt};
use crate::lang::Loc;
use crate::materials::Material;
use crate::scene::motion;
use crate::scene::*;
use glam::{DMat3, DMat4, DVec3, DVec4};
use std::collections::{HashMap, HashSet};
use std::rc::Rc;
use std::sync::Arc;

mod shape;

#[derive(Clone)]
struct Graphics {
    material: Rc<MaterialSpec>,
    named: Rc<HashMap<String, Rc<MaterialSpec>>>,
    textures: Rc<Textures>,
    area_light: Option<(usize, Loc)>,
    reverse: bool,
    /// pbrt-v3's `currentInsideMedium`/`currentOutsideMedium` (names, ""
    /// for none) and the `MediumInterface` statement that set them.
    media: Rc<(String, String, Loc)>,
}

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum FrameKind {
    Attribute,
    Transform,
    Object,
}

impl FrameKind {
    fn begin(self) -> &'static str {
        match self {
            FrameKind::Attribute => "AttributeBegin",
            FrameKind::Transform => "TransformBegin",
            FrameKind::Object => "ObjectBegin",
        }
    }
}

struct Frame {
    kind: FrameKind,
    loc: Loc,
    ctm: [DMat4; 2],
    active: [bool; 2],
    graphics: Option<Graphics>,
}

/// A shape recorded inside ObjectBegin, built when the object is first instanced.
struct PendingShape {
    stmt: usize,
    ctm: [DMat4; 2],
    graphics: Graphics,
    /// Resolved at the `Shape` statement, as pbrt-v3 does.
    media: MediumInterfaceDesc,
}

struct ObjectDef {
    loc: Loc,
    shapes: Vec<PendingShape>,
    built: Option<usize>,
}

#[derive(PartialEq, Eq, Clone, Copy)]
enum Phase {
    Options,
    World,
    After,
}

/// Walks the statements and fills a [`SceneDescription`].
pub struct Builder<'s, 'c> {
    stmts: &'s [Stmt],
    pub ctx: &'c mut Ctx,
    phase: Phase,
    ctm: [DMat4; 2],
    active: [bool; 2],
    named_coords: HashMap<String, [DMat4; 2]>,
    graphics: Graphics,
    stack: Vec<Frame>,
    // Options: the statement and the CTMs (start, end) it saw.
    camera: Option<(usize, [DMat4; 2])>,
    /// `TransformTimes` (pbrt-v3's default 0, 1): the times of the start and
    /// end CTMs.
    transform_times: (f64, f64),
    pub(super) film: Option<usize>,
    filter: Option<usize>,
    sampler: Option<usize>,
    integrator: Option<usize>,
    accelerator: Option<usize>,
    // World.
    current_object: Option<(String, ObjectDef)>,
    objects: HashMap<String, ObjectDef>,
    object_order: Vec<String>,
    /// Built materials by their statement (`None`: the initial matte).
    material_ids: HashMap<Option<usize>, MaterialId>,
    material_keys: HashMap<String, MaterialId>,
    reported_materials: HashSet<Option<usize>>,
    area_lights: HashMap<usize, Option<DiffuseEmission>>,
    named_material_defs: Vec<(String, Rc<MaterialSpec>)>,
    pub meshes: HashMap<std::path::PathBuf, Option<Arc<MeshData>>>,
    /// Triangles of the mesh shapes so far, and the bytes the render will
    /// add for them (world-space copies and the BVH): checked against the
    /// machine's memory at each mesh.
    scene_triangles: u64,
    render_bytes: u64,
    /// When the machine's memory is next read for them.
    budget: crate::scene::memory::BudgetWatch,
    /// A mesh was refused for the scene's size (reported once; the later
    /// ones are refused without another error).
    too_big: bool,
    /// Shared MIP maps and texture counts.
    pub texture_state: TextureState,
    after_warned: bool,
    world_seen: bool,
    world_ended: bool,
    pub scene_materials: Vec<MaterialDesc>,
    pub material_kinds: Vec<super::DeclaredKind>,
    /// The most lobes each scene material can add to a BSDF.
    material_lobes: Vec<usize>,
    pub shapes: Vec<ShapeDesc>,
    pub lights: Vec<Light>,
    /// Per entry of `lights`, the medium its rays start in.
    pub light_media: Vec<Option<MediumId>>,
    pub scene_objects: Vec<ObjectDesc>,
    pub instances: Vec<InstanceDesc>,
    pub skipped: Vec<String>,
    pub unsupported_shapes: usize,
    /// Every medium `MakeNamedMedium` made, with its statement's location
    /// and its index in `scene_media` once something refers to it.
    medium_defs: Vec<(crate::media::Medium, Loc, Option<MediumId>)>,
    /// The definition each name refers to now (a redefinition replaces it
    /// for later statements, as pbrt-v3's `namedMedia[name] = medium`).
    medium_names: HashMap<String, usize>,
    /// Undefined medium names already reported, by the interface statement.
    reported_media: HashSet<(String, u32, u32, u32)>,
    pub scene_media: Vec<crate::media::Medium>,
    pub camera_medium: Option<MediumId>,
    /// The first `MediumInterface` statement (pbrt-v3's `haveScatteringMedia`).
    pub first_medium_interface: Option<Loc>,
    /// The first `subsurface`/`kdsubsurface` material a shape uses.
    first_subsurface: Option<Loc>,
    /// The outside medium named when the `Camera` statement was read.
    camera_outside: Option<(String, Loc)>,
}

impl<'s, 'c> Builder<'s, 'c> {
    pub fn new(stmts: &'s [Stmt], ctx: &'c mut Ctx) -> Self {
        let default_material = Rc::new(MaterialSpec::default_matte());
        Builder {
            stmts,
            ctx,
            phase: Phase::Options,
            ctm: [DMat4::IDENTITY; 2],
            active: [true, true],
            named_coords: HashMap::new(),
            graphics: Graphics {
                material: default_material,
                named: Rc::new(HashMap::new()),
                textures: Rc::new(Textures::default()),
                area_light: None,
                reverse: false,
                media: Rc::new((String::new(), String::new(), Loc::default())),
            },
            stack: Vec::new(),
            camera: None,
            transform_times: (0.0, 1.0),
            film: None,
            filter: None,
            sampler: None,
            integrator: None,
            accelerator: None,
            current_object: None,
            objects: HashMap::new(),
            object_order: Vec::new(),
            material_ids: HashMap::new(),
            material_keys: HashMap::new(),
            reported_materials: HashSet::new(),
            area_lights: HashMap::new(),
            named_material_defs: Vec::new(),
            meshes: HashMap::new(),
            scene_triangles: 0,
            render_bytes: 0,
            budget: Default::default(),
            too_big: false,
            texture_state: TextureState::default(),
            after_warned: false,
            world_seen: false,
            world_ended: false,
            scene_materials: Vec::new(),
            material_kinds: Vec::new(),
            material_lobes: Vec::new(),
            shapes: Vec::new(),
            lights: Vec::new(),
            light_media: Vec::new(),
            scene_objects: Vec::new(),
            instances: Vec::new(),
            skipped: Vec::new(),
            unsupported_shapes: 0,
            medium_defs: Vec::new(),
            medium_names: HashMap::new(),
            reported_media: HashSet::new(),
            scene_media: Vec::new(),
            camera_medium: None,
            first_medium_interface: None,
            first_subsurface: None,
            camera_outside: None,
        }
    }

    fn apply(&mut self, f: impl Fn(DMat4) -> DMat4) {
        for i in 0..2 {
            if self.active[i] {
                self.ctm[i] = f(self.ctm[i]);
            }
        }
    }

    /// [`Self::apply`] for a transform statement at `loc`: a result that
    /// is not finite as an f32 (the render core's precision; numbers whose
    /// product overflows) is a located error
    /// and the transform is left as it was.
    fn apply_at(&mut self, loc: Loc, f: impl Fn(DMat4) -> DMat4) {
        let next = self.ctm.map(&f);
        let fits = |m: &DMat4| {
            m.to_cols_array()
                .iter()
                .all(|v| v.is_finite() && v.abs() <= f32::MAX as f64)
        };
        if (0..2).any(|i| self.active[i] && !fits(&next[i])) {
            self.ctx.error(loc, "the transform is not finite in single precision (its numbers overflow a 32-bit float, alone or combined with the current transform)", "this transform", None);
            return;
        }
        self.apply(f);
    }

    fn world_only(kind: DirKind) -> bool {
        use DirKind as K;
        matches!(
            kind,
            K::AttributeBegin
                | K::AttributeEnd
                | K::TransformBegin
                | K::TransformEnd
                | K::Shape
                | K::Material
                | K::MakeNamedMaterial
                | K::NamedMaterial
                | K::LightSource
                | K::AreaLightSource
                | K::Texture
                | K::ReverseOrientation
                | K::ObjectBegin
                | K::ObjectEnd
                | K::ObjectInstance
        )
    }

    fn options_only(kind: DirKind) -> bool {
        use DirKind as K;
        matches!(
            kind,
            K::Camera
                | K::Sampler
                | K::Film
                | K::PixelFilter
                | K::Integrator
                | K::Accelerator
                | K::TransformTimes
        )
    }

    /// Walks every statement.
    pub fn run(&mut self) {
        let stmts = self.stmts;
        for (i, s) in stmts.iter().enumerate() {
            if self.phase == Phase::After {
                if !self.after_warned {
                    self.after_warned = true;
                    self.ctx.warn(s.loc, format!("`{}` after WorldEnd: pbrs renders the first world block and ignores everything after it", s.kind.name()), "ignored from here on");
                    self.skipped.push(
                        "statements after the first WorldEnd (pbrs renders one world block)".into(),
                    );
                }
                continue;
            }
            if self.phase == Phase::Options && Self::world_only(s.kind) {
                self.ctx.warn(
                    s.loc,
                    format!(
                        "`{}` before WorldBegin is ignored (pbrt-v3 reports it and ignores it)",
                        s.kind.name()
                    ),
                    "only allowed inside WorldBegin … WorldEnd",
                );
                if let Some(p) = s.params() {
                    p.mark_all_used();
                }
                continue;
            }
            if self.phase == Phase::World && Self::options_only(s.kind) {
                self.ctx.warn(s.loc, format!("`{}` inside the world block is ignored (pbrt-v3 reports it and ignores it)", s.kind.name()), "only allowed before WorldBegin");
                if let Some(p) = s.params() {
                    p.mark_all_used();
                }
                continue;
            }
            self.statement(i, s);
        }
        if self.phase == Phase::World {
            let loc = stmts.last().map(|s| s.loc).unwrap_or_default();
            self.ctx.warn(
                loc,
                "the file ends without WorldEnd: the scene is loaded anyway",
                "last statement",
            );
            self.end_world();
        }
        if !self.world_seen {
            let loc = stmts.last().map(|s| s.loc).unwrap_or_default();
            if !self.ctx.sources.files.is_empty() {
                self.ctx.warn(
                    loc,
                    "the scene has no WorldBegin: it has no shapes or lights",
                    "last statement",
                );
            }
        }
    }

    fn statement(&mut self, i: usize, s: &'s Stmt) {
        use DirKind as K;
        let nums = match &s.dir {
            Directive::Numbers(v) => v.as_slice(),
            _ => &[],
        };
        match s.kind {
            K::Identity => self.apply(|_| DMat4::IDENTITY),
            K::Translate => {
                let t = DMat4::from_translation(DVec3::new(nums[0], nums[1], nums[2]));
                self.apply_at(s.loc, |m| m * t);
            }
            K::Scale => {
                let t = DMat4::from_scale(DVec3::new(nums[0], nums[1], nums[2]));
                self.apply_at(s.loc, |m| m * t);
            }
            K::Rotate => {
                let axis = DVec3::new(nums[1], nums[2], nums[3]);
                if axis.length_squared() == 0.0 || !axis.length_squared().is_finite() {
                    self.ctx.error(s.loc, "Rotate about a zero-length axis", "the axis (x y z) must not be 0 0 0", None);
                    return;
                }
                let t = DMat4::from_axis_angle(axis.normalize(), nums[0].to_radians());
                self.apply_at(s.loc, |m| m * t);
            }
            K::LookAt => match look_at(nums) {
                Some(t) => self.apply_at(s.loc, |m| m * t),
                None => self.ctx.warn(s.loc, "degenerate LookAt (eye equals look, or up is parallel to the view direction): ignored, as pbrt-v3 does", "this LookAt"),
            },
            K::Transform | K::ConcatTransform => {
                let mut a = [0.0; 16];
                a.copy_from_slice(nums);
                let t = DMat4::from_cols_array(&a);
                if s.kind == K::Transform {
                    self.apply_at(s.loc, |_| t);
                } else {
                    self.apply_at(s.loc, |m| m * t);
                }
            }
            K::CoordinateSystem => {
                if let Directive::Named(n) = &s.dir {
                    self.named_coords.insert(n.value.clone(), self.ctm);
                }
            }
            K::CoordSysTransform => {
                if let Directive::Named(n) = &s.dir {
                    match self.named_coords.get(&n.value) {
                        Some(&m) => self.ctm = m,
                        None => self.ctx.warn(n.loc, format!("unknown coordinate system \"{}\": CoordSysTransform ignored (as pbrt-v3)", n.value), "not defined by CoordinateSystem or Camera"),
                    }
                }
            }
            K::ActiveTransform => {
                if let Directive::ActiveTransform(k) = s.dir {
                    self.active = match k {
                        ActiveKind::All => [true, true],
                        ActiveKind::StartTime => [true, false],
                        ActiveKind::EndTime => [false, true],
                    };
                }
            }
            // pbrt-v3 takes the two times as given (no ordering check):
            // interpolation clamps to the start transform up to the start
            // time and to the end one from the end time on. Non-finite
            // times would interpolate to NaN: refused.
            K::TransformTimes => {
                let (t0, t1) = (nums[0], nums[1]);
                if !(t0.is_finite() && t1.is_finite()) {
                    self.ctx.error(s.loc, "TransformTimes: the times must be finite numbers", "ignored", None);
                } else {
                    if t1 < t0 {
                        self.ctx.warn(s.loc, format!("TransformTimes: the end time {t1} is before the start time {t0}; as pbrt-v3, times up to {t0} see the start transform and later ones the end transform (no motion in between)"), "this TransformTimes");
                    }
                    self.transform_times = (t0, t1);
                }
            }
            K::Camera => {
                self.camera = Some((i, self.ctm));
                self.camera_outside = Some((self.graphics.media.1.clone(), s.loc));
                let inv = self.ctm[0].inverse();
                self.named_coords.insert("camera".into(), [inv, self.ctm[1].inverse()]);
            }
            K::Film => self.film = Some(i),
            K::PixelFilter => self.filter = Some(i),
            K::Sampler => self.sampler = Some(i),
            K::Integrator => self.integrator = Some(i),
            K::Accelerator => self.accelerator = Some(i),
            K::WorldBegin => {
                if self.phase == Phase::World {
                    self.ctx.warn(s.loc, "WorldBegin inside the world block is ignored", "already inside WorldBegin");
                    return;
                }
                self.phase = Phase::World;
                self.world_seen = true;
                self.ctm = [DMat4::IDENTITY; 2];
                self.active = [true, true];
                self.named_coords.insert("world".into(), self.ctm);
            }
            K::WorldEnd => {
                if self.phase != Phase::World {
                    self.ctx.warn(s.loc, "WorldEnd without WorldBegin is ignored", "no world block is open");
                    return;
                }
                self.end_world();
            }
            K::AttributeBegin | K::TransformBegin => {
                let kind = if s.kind == K::AttributeBegin { FrameKind::Attribute } else { FrameKind::Transform };
                self.push(kind, s.loc);
            }
            K::AttributeEnd | K::TransformEnd => {
                let kind = if s.kind == K::AttributeEnd { FrameKind::Attribute } else { FrameKind::Transform };
                self.pop(kind, s);
            }
            K::ObjectBegin => {
                let Directive::Named(n) = &s.dir else { return };
                if let Some((outer, _)) = &self.current_object {
                    let outer = outer.clone();
                    self.ctx.error(s.loc, format!("ObjectBegin \"{}\" inside the definition of object \"{outer}\": object definitions cannot be nested", n.value), "nested ObjectBegin", None);
                    return;
                }
                self.push(FrameKind::Object, s.loc);
                self.current_object = Some((n.value.clone(), ObjectDef { loc: n.loc, shapes: Vec::new(), built: None }));
            }
            K::ObjectEnd => {
                if self.current_object.is_none() {
                    self.ctx.error(s.loc, "ObjectEnd without ObjectBegin", "no object definition is open", None);
                    return;
                }
                if self.pop(FrameKind::Object, s) {
                    let (name, def) = self.current_object.take().expect("checked");
                    if let Some(old) = self.objects.get(&name) {
                        let at = self.ctx.sources.position(old.loc);
                        self.ctx.warn(def.loc, format!("object \"{name}\" redefined (first defined at {at}); the new definition is used"), "redefinition");
                    } else {
                        self.object_order.push(name.clone());
                    }
                    self.objects.insert(name, def);
                }
            }
            K::ObjectInstance => {
                let Directive::Named(n) = &s.dir else { return };
                self.instance(n);
            }
            K::ReverseOrientation => self.graphics.reverse = !self.graphics.reverse,
            K::Material => {
                let Directive::Entity { name, .. } = &s.dir else { return };
                self.graphics.material = Rc::new(MaterialSpec::new(name.value.clone(), Some(i), name.loc, self.graphics.textures.clone(), None, self.graphics.named.clone()));
            }
            K::MakeNamedMaterial => {
                let Directive::Entity { name, params } = &s.dir else { return };
                let ty = params.find("type", |t| t == crate::lang::params::ParamType::String).and_then(|p| p.strs().first().cloned());
                let Some(ty) = ty else {
                    self.ctx.error(name.loc, format!("MakeNamedMaterial \"{}\" has no \"string type\" parameter", name.value), "needs \"string type\" [ \"matte\" ] or similar", None);
                    return;
                };
                if let Some(old) = self.graphics.named.get(&name.value) {
                    let at = self.ctx.sources.position(old.loc);
                    self.ctx.warn(name.loc, format!("named material \"{}\" redefined (first defined at {at})", name.value), "redefinition");
                }
                let spec = Rc::new(MaterialSpec::new(ty, Some(i), name.loc, self.graphics.textures.clone(), Some(name.value.clone()), self.graphics.named.clone()));
                self.named_material_defs.push((name.value.clone(), spec.clone()));
                Rc::make_mut(&mut self.graphics.named).insert(name.value.clone(), spec);
            }
            K::NamedMaterial => {
                let Directive::Named(n) = &s.dir else { return };
                match self.graphics.named.get(&n.value) {
                    Some(spec) => self.graphics.material = spec.clone(),
                    None => {
                        let names: Vec<&str> = self.graphics.named.keys().map(String::as_str).collect();
                        let help = closest_name(&n.value, &names).map(|c| format!("did you mean \"{c}\"?")).or_else(|| {
                            Some(if names.is_empty() { "no named material is defined here (MakeNamedMaterial binds names in order, scoped by AttributeBegin/End)".into() } else { format!("defined here: {}", names.join(", ")) })
                        });
                        let help = help.map(|h| format!(" ({h})")).unwrap_or_default();
                        self.ctx.warn(n.loc, format!("unknown named material \"{}\"{help}: the current material is kept (as pbrt-v3, which renders on)", n.value), "not defined by MakeNamedMaterial before this line");
                    }
                }
            }
            K::Texture => {
                let Directive::Texture { name, kind, class, params } = &s.dir else { return };
                if self.ctm[0] != self.ctm[1] {
                    self.ctx.warn(s.loc, "animated texture transform: the start transform is used", "this Texture");
                }
                let defined = texture::texture(self.ctx, name, kind, class, params, &self.graphics.textures, self.ctm[0], &mut self.texture_state);
                let redefined = |ctx: &mut Ctx, old: Option<Loc>| {
                    if let Some(old) = old {
                        let at = ctx.sources.position(old);
                        ctx.warn(name.loc, format!("texture \"{}\" redefined (first defined at {at})", name.value), "redefinition");
                    }
                };
                match defined {
                    Some(Defined::Float(e)) => {
                        let old = self.graphics.textures.float.get(&name.value).map(|o| o.loc);
                        redefined(self.ctx, old);
                        Rc::make_mut(&mut self.graphics.textures).float.insert(name.value.clone(), e);
                    }
                    Some(Defined::Spectrum(e)) => {
                        let old = self.graphics.textures.spectrum.get(&name.value).map(|o| o.loc);
                        redefined(self.ctx, old);
                        Rc::make_mut(&mut self.graphics.textures).spectrum.insert(name.value.clone(), e);
                    }
                    None => {}
                }
            }
            K::LightSource => {
                let Directive::Entity { name, params } = &s.dir else { return };
                if self.ctm[0] != self.ctm[1] {
                    self.ctx.warn(s.loc, "animated light transform: the start transform is used", "this LightSource");
                }
                if !self.ctm[0].is_finite() {
                    self.ctx.error(s.loc, "the light's transform has non-finite entries (overflow in the transform statements)", "this LightSource", None);
                    self.ctx.report_unused(params, &format!("LightSource \"{}\"", name.value));
                } else if let Some(l) = lights::light(self.ctx, name, params, self.ctm[0]) {
                    // pbrt-v3 resolves the interface for every light:
                    // undefined names are errors. A light at a point emits
                    // into the outside medium (pbrt-v3's `MakeLight`), which
                    // bdpt's light subpaths start in.
                    let media = self.graphics.media.clone();
                    for n in [&media.0, &media.1] {
                        if !n.is_empty() && !self.medium_names.contains_key(n.as_str()) {
                            self.medium_id(n, media.2);
                        }
                    }
                    let medium = if l.at_infinity() {
                        None
                    } else {
                        self.medium_id(&media.1, media.2)
                    };
                    self.lights.push(l);
                    self.light_media.push(medium);
                }
            }
            K::AreaLightSource => {
                let Directive::Entity { name, params } = &s.dir else { return };
                self.graphics.area_light = lights::area_light_known(self.ctx, name, params).then_some((i, name.loc));
            }
            K::Shape => self.shape(i, s),
            K::MakeNamedMedium => {
                let Directive::Entity { name, params } = &s.dir else { return };
                if self.ctm[0] != self.ctm[1] {
                    self.ctx.warn(s.loc, "animated medium transform: the start transform is used (as pbrt-v3)", "this MakeNamedMedium");
                }
                if let Some(m) = super::medium::medium(self.ctx, name, params, self.ctm[0]) {
                    if let Some(&old) = self.medium_names.get(&name.value) {
                        let at = self.ctx.sources.position(self.medium_defs[old].1);
                        self.ctx.warn(name.loc, format!("named medium \"{}\" redefined (first defined at {at}); later statements use the new definition", name.value), "redefinition");
                    }
                    self.medium_defs.push((m, name.loc, None));
                    self.medium_names.insert(name.value.clone(), self.medium_defs.len() - 1);
                }
            }
            K::MediumInterface => {
                let Directive::MediumInterface(inside, outside) = &s.dir else { return };
                // One name: the same medium on both sides (pbrt-v3's parser).
                let outside = outside.as_ref().unwrap_or(inside);
                self.graphics.media = Rc::new((inside.value.clone(), outside.value.clone(), s.loc));
                self.first_medium_interface.get_or_insert(s.loc);
            }
            K::Include => {}
        }
    }

    fn push(&mut self, kind: FrameKind, loc: Loc) {
        self.stack.push(Frame {
            kind,
            loc,
            ctm: self.ctm,
            active: self.active,
            graphics: (kind != FrameKind::Transform).then(|| self.graphics.clone()),
        });
    }

    /// Pops a frame of `kind`; a missing or mismatched frame is an error.
    fn pop(&mut self, kind: FrameKind, s: &Stmt) -> bool {
        let end = s.kind.name();
        match self.stack.last() {
            None => {
                self.ctx.error(
                    s.loc,
                    format!("unbalanced {end}: there is no matching {}", kind.begin()),
                    format!("no open {}", kind.begin()),
                    None,
                );
                false
            }
            Some(f) if f.kind != kind => {
                let at = self.ctx.sources.position(f.loc);
                let open = f.kind.begin();
                self.ctx.error(
                    s.loc,
                    format!("unbalanced {end}: the innermost open block is {open} at {at}"),
                    format!("expected the end of {open}"),
                    None,
                );
                false
            }
            Some(_) => {
                let f = self.stack.pop().expect("checked");
                self.ctm = f.ctm;
                self.active = f.active;
                if let Some(g) = f.graphics {
                    self.graphics = g;
                }
                true
            }
        }
    }

    fn end_world(&mut self) {
        // pbrt-v3 makes the camera at WorldEnd (RenderOptions::MakeCamera
        // from pbrtWorldEnd) with the graphics state's medium interface of
        // that moment: its outside medium is the camera's.
        let graphics = self.graphics.clone();
        let outside = graphics.media.1.clone();
        self.camera_medium = self.medium_id(&outside, graphics.media.2);
        if let Some((at_camera, loc)) = self.camera_outside.take() {
            if at_camera != outside {
                let shown = |n: &str| {
                    if n.is_empty() {
                        "none".to_string()
                    } else {
                        format!("\"{n}\"")
                    }
                };
                self.ctx.warn(loc, format!("the camera's medium is the outside medium current at WorldEnd ({}), not the one current here ({}): pbrt-v3 makes the camera at WorldEnd, and pbrs does as pbrt-v3", shown(&outside), shown(&at_camera)), "camera medium");
            }
        }
        if let Some((name, def)) = self.current_object.take() {
            self.ctx.warn(def.loc, format!("object \"{name}\" is not closed by ObjectEnd before the end of the world block; its definition is dropped"), "ObjectBegin without ObjectEnd");
        }
        for f in std::mem::take(&mut self.stack).iter().rev() {
            self.ctx.warn(
                f.loc,
                format!(
                    "{} is not closed before the end of the world block",
                    f.kind.begin()
                ),
                "unclosed",
            );
        }
        self.phase = Phase::After;
        self.world_ended = true;
    }

    fn instance(&mut self, n: &Name) {
        let media = self.graphics.media.clone();
        if media.0 != media.1 {
            let at = self.ctx.sources.position(media.2);
            self.ctx.warn(n.loc, format!("the MediumInterface current here (set at {at}) does not apply to the instance (as pbrt-v3): its shapes keep the interfaces current at their Shape statements inside ObjectBegin"), "interface ignored for this instance");
        }
        if let Some((outer, _)) = &self.current_object {
            let outer = outer.clone();
            self.ctx.error(n.loc, format!("ObjectInstance \"{}\" inside the definition of object \"{outer}\" (pbrt-v3 does not allow it)", n.value), "inside ObjectBegin", None);
            return;
        }
        let Some(def) = self.objects.get_mut(&n.value) else {
            let names: Vec<&str> = self.object_order.iter().map(String::as_str).collect();
            let help = closest_name(&n.value, &names).map(|c| format!("did you mean \"{c}\"?"));
            self.ctx.error(
                n.loc,
                format!("unknown object \"{}\"", n.value),
                "not defined by ObjectBegin before this line",
                help,
            );
            return;
        };
        let index = match def.built {
            Some(i) => i,
            None => {
                let pending = std::mem::take(&mut def.shapes);
                let mut shapes = Vec::new();
                for p in &pending {
                    let mut ctm = p.ctm;
                    if ctm[0] != ctm[1] {
                        let loc = self.stmts[p.stmt].loc;
                        self.ctx.warn(loc, "animated shape transform inside an object definition: pbrs does not nest motion in instances; the start transform is used (animate the ObjectInstance instead)", "this Shape");
                        ctm[1] = ctm[0];
                    }
                    shapes.extend(self.build_shape(p.stmt, ctm, &p.graphics, None, p.media));
                }
                self.scene_objects.push(ObjectDesc {
                    name: n.value.clone(),
                    shapes,
                });
                let i = self.scene_objects.len() - 1;
                self.objects.get_mut(&n.value).expect("present").built = Some(i);
                i
            }
        };
        if !self.ctm[0].is_finite() || !self.ctm[1].is_finite() {
            self.ctx.error(n.loc, "the instance transform has non-finite entries (overflow in the transform statements)", "this ObjectInstance", None);
            return;
        }
        let motion = self.animated(self.ctm);
        if motion.is_some() {
            self.check_motion(self.ctm, n.loc, "this ObjectInstance");
        }
        self.instances.push(InstanceDesc {
            object: index,
            instance_to_world: self.ctm[0],
            motion,
        });
    }

    /// Builds the render options and notes what was left out.
    pub fn finish(
        &mut self,
    ) -> (
        CameraDesc,
        FilmDesc,
        crate::filters::Filter,
        SamplerDesc,
        IntegratorSettings,
    ) {
        let stmts = self.stmts;
        let ent = |i: Option<usize>| {
            i.and_then(|i| match &stmts[i].dir {
                Directive::Entity { name, params } => Some((name, params)),
                _ => None,
            })
        };
        // The film first: the realistic camera needs its size.
        let film = options::film(self.ctx, ent(self.film));
        let mut camera = options::camera(
            self.ctx,
            self.camera
                .and_then(|(i, m)| ent(Some(i)).map(|e| (e, m[0]))),
            &film,
        );
        if let Some((i, [start, end])) = self.camera {
            if start != end {
                // The start inverse was checked by `options::camera`.
                let end_inv = end.inverse();
                if end_inv.is_finite() && end.determinant().abs() >= 1e-300 {
                    camera.motion = self.animated([camera.camera_to_world, end_inv]);
                    Self::warn_mirror(self.ctx, [start, end], stmts[i].loc, "this Camera");
                } else {
                    self.ctx.error(stmts[i].loc, "the camera's end transform (the CTM at Camera under ActiveTransform EndTime) is singular: it cannot be inverted", "this Camera", None);
                }
            }
        }
        let filter = options::filter(self.ctx, ent(self.filter));
        let sampler = options::sampler(self.ctx, ent(self.sampler));
        let integrator = options::integrator(self.ctx, ent(self.integrator));
        if let IntegratorSettings::AmbientOcclusion(ao) = &integrator {
            // pbrt-v3's AOIntegrator: the sampler's RoundCount, with its warning.
            let taken = crate::samplers::round_count(&sampler, ao.n_samples);
            if taken != ao.n_samples {
                if let Some((name, params)) = ent(self.integrator) {
                    let loc = params.get("nsamples").map_or(name.loc, |p| p.loc);
                    self.ctx.warn(
                        loc,
                        format!("Taking {taken} samples, not {} as specified", ao.n_samples),
                        "rounded by the sampler",
                    );
                }
            }
        }
        if let (
            crate::integrators::IntegratorSettings::Bdpt(_)
            | crate::integrators::IntegratorSettings::Mlt(_),
            Some((name, _)),
        ) = (&integrator, ent(self.integrator))
        {
            // pbrt-v3's bdpt and mlt ask the camera for its importance
            // (We), which only the perspective camera has.
            if !matches!(
                camera.projection,
                crate::cameras::Projection::Perspective(_)
            ) {
                let kind = integrator.name();
                self.ctx.error(name.loc, format!("the \"{kind}\" integrator needs the camera's importance (We), which only the \"perspective\" camera has (as in pbrt-v3): the \"{}\" camera cannot be used with {kind}", camera.projection.kind_name()), "needs a perspective camera", None);
            }
        }
        if let Some(loc) = self.first_medium_interface {
            // pbrt-v3's warning for integrators without volume scattering.
            let name = (!integrator.renders_media()).then(|| integrator.name());
            if let Some(name) = name {
                self.ctx.warn(loc, format!("the scene has participating media but the \"{name}\" integrator ignores them (as pbrt-v3's): use \"volpath\" to render them"), "media ignored by this integrator");
            }
        }
        if let Some(loc) = self.first_subsurface {
            let name = (!integrator.samples_subsurface()).then(|| integrator.name());
            if let Some(name) = name {
                self.ctx.warn(loc, format!("the \"{name}\" integrator does not sample subsurface scattering (as pbrt-v3's): this material renders as its dielectric boundary only; use \"path\" or \"volpath\""), "subsurface ignored by this integrator");
            }
        }
        for (m, loc, id) in &self.medium_defs {
            if id.is_none() {
                self.skipped.push(format!("named medium \"{}\" (defined at {}): not used by the camera or any shape, not built", m.name, self.ctx.sources.position(*loc)));
            }
        }
        if let Some((name, params)) = ent(self.accelerator) {
            params.mark_all_used();
            self.skipped.push(format!(
                "Accelerator \"{}\" at {}: ignored, pbrs always builds its own BVH",
                name.value,
                self.ctx.sources.position(name.loc)
            ));
        }
        for name in &self.object_order {
            let def = &self.objects[name];
            if def.built.is_none() {
                self.skipped.push(format!(
                    "object \"{name}\" ({} shapes, defined at {}): never instanced, not built",
                    def.shapes.len(),
                    self.ctx.sources.position(def.loc)
                ));
            }
        }
        let mut seen = HashSet::new();
        for (name, spec) in &self.named_material_defs {
            let used = self.material_ids.contains_key(&spec.stmt)
                || self.reported_materials.contains(&spec.stmt);
            if !used && seen.insert(spec.stmt) {
                self.skipped.push(format!("named material \"{name}\" ({}, defined at {}): not used by any shape, not built", spec.ty, self.ctx.sources.position(spec.loc)));
            }
        }
        if self.unsupported_shapes > 0 {
            self.skipped.push(format!(
                "{} shapes of unsupported types (see the warnings)",
                self.unsupported_shapes
            ));
        }
        (camera, film, filter, sampler, integrator)
    }
}

/// pbrt-v3 `LookAt`: the world-to-camera matrix, or `None` if degenerate.
fn look_at(v: &[f64]) -> Option<DMat4> {
    let pos = DVec3::new(v[0], v[1], v[2]);
    let look = DVec3::new(v[3], v[4], v[5]);
    let up = DVec3::new(v[6], v[7], v[8]);
    let dir = (look - pos).normalize_or_zero();
    let up = up.normalize_or_zero();
    let right = up.cross(dir);
    if dir == DVec3::ZERO || right.length() == 0.0 || !right.is_finite() {
        return None;
    }
    let right = right.normalize();
    let new_up = dir.cross(right);
    let camera_to_world = DMat4::from_cols(
        right.extend(0.0),
        new_up.extend(0.0),
        dir.extend(0.0),
        DVec4::new(pos.x, pos.y, pos.z, 1.0),
    );
    Some(camera_to_world.inverse())
}

pub(crate) use crate::scene::kind::closest_name;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn look_at_matches_pbrt() {
        // Looking down -z from +z: camera +z maps to world -z.
        let w2c = look_at(&[0.0, 0.0, 5.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0]).unwrap();
        let c2w = w2c.inverse();
        let fwd = c2w.transform_vector3(DVec3::Z);
        assert!((fwd - DVec3::new(0.0, 0.0, -1.0)).length() < 1e-12);
        // pbrt: right = cross(up, dir) = cross(y, -z) = -x.
        let right = c2w.transform_vector3(DVec3::X);
        assert!((right - DVec3::new(-1.0, 0.0, 0.0)).length() < 1e-12);
        assert!(look_at(&[0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0]).is_none());
    }
}
