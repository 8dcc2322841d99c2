//! A `Shape` statement with the graphics state current at it (pbrt-v3's
//! `pbrtShape`): its transforms and motion, the media on either side, the
//! area light and the material; inside `ObjectBegin` it is recorded and
//! built when the object is first instanced.

use super::*;
use crate::loader::lookup;

impl<'s, 'c> Builder<'s, 'c> {
    pub(super) fn shape(&mut self, i: usize, s: &'s Stmt) {
        if let Some((name, _)) = &self.current_object {
            if self.graphics.area_light.is_some() {
                let name = name.clone();
                self.ctx.warn(s.loc, format!("area light inside the definition of object \"{name}\" is ignored (as pbrt-v3)"), "this shape is not emissive");
            }
            let graphics = self.graphics.clone();
            let media = self.medium_interface(&graphics);
            if let Some((_, def)) = &mut self.current_object {
                def.shapes.push(PendingShape {
                    stmt: i,
                    ctm: self.ctm,
                    graphics,
                    media,
                });
            }
            return;
        }
        let graphics = self.graphics.clone();
        let mut area = graphics.area_light.map(|(i, _)| i);
        if self.ctm[0] != self.ctm[1] {
            if self.ctm[0].is_finite() && self.ctm[1].is_finite() {
                self.check_motion(self.ctm, s.loc, "this Shape");
            }
            if area.take().is_some() {
                self.ctx.warn(
                    s.loc,
                    "the current area light is ignored for an animated shape (as pbrt-v3)",
                    "this Shape is not emissive",
                );
            }
        }
        let media = self.medium_interface(&graphics);
        if let Some(shape) = self.build_shape(i, self.ctm, &graphics, area, media) {
            self.shapes.push(shape);
        }
    }

    /// Warnings for an animated transform pbrs renders other than the scene
    /// may expect: a singular keyframe (the shape or instance is left out,
    /// where pbrt-v3 would trace NaN rays) or a projective one (the
    /// decomposition keeps only the affine part, as pbrt-v3's).
    pub(super) fn check_motion(&mut self, ctm: [DMat4; 2], loc: Loc, what: &str) {
        for (m, which) in ctm.iter().zip(["start", "end"]) {
            let det = DMat3::from_mat4(*m).determinant();
            if !(det.is_finite() && det != 0.0) {
                self.ctx.warn(loc, format!("the animated transform's {which} transform is singular: left out of the render"), what);
                return;
            }
        }
        if !(motion::is_affine(&ctm[0]) && motion::is_affine(&ctm[1])) {
            self.ctx.warn(loc, "projective animated transform: interpolated as its affine part (as pbrt-v3's decomposition)", what);
        }
        Self::warn_mirror(self.ctx, ctm, loc, what);
    }

    /// pbrt-v3's decomposition leaves a mirror in its rotation, which a
    /// quaternion cannot hold, so its in-between transforms are wrong (an
    /// animated camera under `Scale -1 1 1` looks away from the scene);
    /// pbrs keeps the mirror in the scale part and differs from pbrt-v3 there.
    pub(super) fn warn_mirror(ctx: &mut Ctx, ctm: [DMat4; 2], loc: Loc, what: &str) {
        if ctm.iter().any(|m| DMat3::from_mat4(*m).determinant() < 0.0) {
            ctx.warn(loc, "animated transform with a mirror (negative determinant): between the keyframes pbrt-v3 interpolates it wrongly (its rotation quaternion cannot hold the mirror); pbrs interpolates the mirror as part of the scale, so its image differs from pbrt-v3's", what);
        }
    }

    /// The animated transform of a CTM pair, `None` if both are equal.
    pub(super) fn animated(&self, ctm: [DMat4; 2]) -> Option<Arc<AnimatedTransform>> {
        let (t0, t1) = self.transform_times;
        AnimatedTransform::new(ctm[0], t0, ctm[1], t1).map(Arc::new)
    }

    pub(super) fn build_shape(
        &mut self,
        i: usize,
        ctms: [DMat4; 2],
        g: &Graphics,
        area: Option<usize>,
        medium_interface: MediumInterfaceDesc,
    ) -> Option<ShapeDesc> {
        let stmts = self.stmts;
        let Directive::Entity { name, params } = &stmts[i].dir else {
            return None;
        };
        let ctm = ctms[0];
        if !ctm.is_finite() || !ctms[1].is_finite() {
            self.ctx.error(stmts[i].loc, "the shape's transform has non-finite entries (overflow in the transform statements)", "this Shape", None);
            params.mark_all_used();
            return None;
        }
        let surface = crate::loader::shapes::surface(self.ctx, name, params, &mut self.meshes);
        let Some(surface) = surface else {
            // Otherwise an error or an empty-shape warning was reported.
            if crate::loader::shapes::is_unsupported_shape(&name.value) {
                self.unsupported_shapes += 1;
            }
            params.mark_all_used();
            return None;
        };
        if let Surface::TriangleMesh(m) = &surface {
            if !self.memory_fits(m, ctm, stmts[i].loc) {
                params.mark_all_used();
                return None;
            }
        }
        // pbrt-v3 reads alpha textures for triangle meshes only (and passes
        // none to the meshes it refines from other shapes).
        let refined = crate::loader::refine::REFINED_SHAPES.contains(&name.value.as_str());
        let (alpha, shadow_alpha) = match surface {
            Surface::TriangleMesh(_) if refined => (None, None),
            Surface::TriangleMesh(_) => (
                texture::shape_alpha(self.ctx, params, "alpha", &g.textures),
                texture::shape_alpha(self.ctx, params, "shadowalpha", &g.textures),
            ),
            _ => (None, None),
        };
        let material = self.material_for_shape(&g.material, params, &g.textures);
        let mut area_light = area.and_then(|a| self.area_light(a));
        if matches!(surface, Surface::Curve(_)) && area_light.is_some() {
            // pbrt-v3 aborts when it samples one (`Curve::Sample`).
            self.ctx.warn(stmts[i].loc, "an area light on a curve is not supported by pbrs (pbrt-v3 cannot sample curves): the curve does not emit", "this curve is not emissive");
            area_light = None;
        }
        self.ctx
            .report_unused(params, &format!("Shape \"{}\"", name.value));
        let emits = area_light.is_some_and(|a| a.l.max_element() > 0.0);
        if alpha == Some(FloatTex::Constant(0.0)) && !emits {
            // Every ray ignores it (an emitter stays: lights sample it).
            self.skipped.push(format!(
                "Shape \"{}\" at {}: \"alpha\" 0 makes it invisible to every ray (as pbrt-v3): left out",
                name.value,
                self.ctx.sources.position(stmts[i].loc)
            ));
            return None;
        }
        Some(ShapeDesc {
            surface,
            object_to_world: ctm,
            motion: self.animated(ctms),
            reverse_orientation: g.reverse,
            material,
            area_light,
            alpha,
            shadow_alpha,
            medium_interface,
        })
    }

    /// The memory estimate of the render's side of the meshes so far (with
    /// `m`): a copy of positions and normals for a mesh that is not in
    /// world space already, and the BVH ([`crate::accel::bvh_memory_estimate`]),
    /// checked against the machine's memory before anything is built. Too
    /// much: an error at this `Shape` (instead of the system's OOM kill
    /// during the build).
    fn memory_fits(&mut self, m: &crate::scene::MeshData, ctm: DMat4, loc: Loc) -> bool {
        let triangles = m.triangle_count() as u64;
        let copies = if ctm == DMat4::IDENTITY {
            0
        } else {
            12 * (m.positions.len() + m.normals.as_ref().map_or(0, Vec::len)) as u64
        };
        self.scene_triangles += triangles;
        self.render_bytes += copies;
        if self.too_big {
            return false;
        }
        if self.scene_triangles > crate::accel::MAX_LEVEL_PRIMITIVES {
            self.too_big = true;
            self.ctx.error(
                loc,
                format!(
                    "the scene's meshes have {} triangles so far, more than the {} one BVH holds",
                    self.scene_triangles,
                    crate::accel::MAX_LEVEL_PRIMITIVES
                ),
                "this mesh brings the scene past the BVH's limit",
                None,
            );
            return false;
        }
        let bvh = crate::accel::bvh_memory_estimate(self.scene_triangles);
        let triangles = self.scene_triangles;
        let what = || {
            format!(
                "rendering the scene's {triangles} triangles so far (BVH and world-space copies, estimated)"
            )
        };
        match self.budget.check(bvh + self.render_bytes, what) {
            Ok(()) => true,
            Err(why) => {
                self.too_big = true;
                self.ctx.error(
                    loc,
                    why,
                    "this mesh brings the scene past the memory available",
                    Some(format!(
                        "the BVH takes about {} bytes per triangle; render fewer or smaller meshes, or on a machine with more memory (later meshes are refused too)",
                        crate::accel::BVH_BYTES_PER_TRIANGLE
                    )),
                );
                false
            }
        }
    }

    /// pbrt-v3's `CreateMediumInterface`: the current inside and outside
    /// media by name ("" is none); an undefined name is an error (once per
    /// `MediumInterface` statement and name) and no medium.
    fn medium_interface(&mut self, g: &Graphics) -> MediumInterfaceDesc {
        let (inside, outside, loc) = &*g.media.clone();
        MediumInterfaceDesc {
            inside: self.medium_id(inside, *loc),
            outside: self.medium_id(outside, *loc),
        }
    }

    pub(super) fn medium_id(&mut self, name: &str, loc: Loc) -> Option<MediumId> {
        if name.is_empty() {
            return None;
        }
        let Some(&def) = self.medium_names.get(name) else {
            if self
                .reported_media
                .insert((name.to_string(), loc.file, loc.start, loc.chain))
            {
                let names: Vec<&str> = self.medium_names.keys().map(String::as_str).collect();
                let help = closest_name(name, &names)
                    .map(|c| format!("did you mean \"{c}\"?"))
                    .or_else(|| {
                        Some(if names.is_empty() {
                            "no medium is defined before this point (MakeNamedMedium)".into()
                        } else {
                            format!("defined here: {}", names.join(", "))
                        })
                    });
                self.ctx.error(
                    loc,
                    format!("named medium \"{name}\" undefined (pbrt-v3 reports the same error)"),
                    "not defined by MakeNamedMedium before its use",
                    help,
                );
            }
            return None;
        };
        if let Some(id) = self.medium_defs[def].2 {
            return Some(id);
        }
        let id = MediumId(self.scene_media.len() as u32);
        self.scene_media.push(self.medium_defs[def].0.clone());
        self.medium_defs[def].2 = Some(id);
        Some(id)
    }

    /// The emission of `AreaLightSource` statement `i`, read at its first
    /// use.
    fn area_light(&mut self, i: usize) -> Option<DiffuseEmission> {
        if let Some(a) = self.area_lights.get(&i) {
            return *a;
        }
        let stmts = self.stmts;
        let Directive::Entity { name, params } = &stmts[i].dir else {
            unreachable!("area light statement")
        };
        let a = lights::area_light(self.ctx, name, params);
        self.area_lights.insert(i, a);
        a
    }

    fn material_for_shape(
        &mut self,
        spec: &Rc<MaterialSpec>,
        shape_params: &crate::lang::params::ParamList,
        textures: &Rc<Textures>,
    ) -> MaterialId {
        let stmts = self.stmts;
        let mat_params = spec.stmt.and_then(|i| stmts[i].params());
        let overrides = lookup::shape_may_set_material_params(shape_params);
        if !overrides {
            if let Some(&id) = self.material_ids.get(&spec.stmt) {
                return id;
            }
        }
        let empty = crate::lang::params::ParamList::default();
        let lookup = Lookup {
            first: if overrides { Some(shape_params) } else { None },
            second: mat_params.unwrap_or(&empty),
            textures: if overrides { textures } else { &spec.textures },
        };
        let (mut desc, kind, refs) = material::material(self.ctx, spec, &lookup);
        if matches!(desc.kind, "subsurface" | "kdsubsurface") {
            self.first_subsurface.get_or_insert(spec.loc);
        }
        for r in refs {
            let id = match spec.named.get(&r.name) {
                Some(named) => {
                    let named = named.clone();
                    let empty = crate::lang::params::ParamList::default();
                    self.material_for_shape(&named, &empty, &named.textures.clone())
                }
                None => {
                    let what = if r.name.is_empty() {
                        format!("\"{}\" is not given", r.param)
                    } else {
                        format!(
                            "named material \"{}\" (\"{}\") is not defined before this material",
                            r.name, r.param
                        )
                    };
                    self.ctx.warn(
                        if r.name.is_empty() { spec.loc } else { r.loc },
                        format!("{what}: using a matte (as pbrt-v3)"),
                        "undefined named material",
                    );
                    let matte = Rc::new(MaterialSpec::default_matte());
                    let empty = crate::lang::params::ParamList::default();
                    self.material_for_shape(&matte, &empty, &matte.textures.clone())
                }
            };
            desc.params.set(r.param, ParamValue::Material(id));
        }
        if self.reported_materials.insert(spec.stmt) {
            if let Some(p) = mat_params {
                if overrides {
                    // pbrt-v3 does not report material parameters a shape overrode.
                    for q in &p.items {
                        if shape_params.get(&q.name).is_some() {
                            q.used.set(true);
                        }
                    }
                }
                // Hints only for a known kind: an unknown one is read as a
                // matte, whose names would mislead.
                let specs = crate::materials::kind(&spec.ty).map_or(&[][..], |k| k.params);
                self.ctx.report_unused_with_specs(
                    p,
                    &format!("Material \"{}\"", spec.ty),
                    &["type"],
                    specs,
                );
            }
        }
        // The declared kind is part of the key: a substituted material stays
        // apart from a matte of the same Kd, so that the summary counts it.
        let key = format!("{kind:?}{desc:?}");
        let id = match self.material_keys.get(&key) {
            Some(&id) => id,
            None => {
                let lobes_of =
                    |id: MaterialId| self.material_lobes.get(id.0 as usize).copied().unwrap_or(0);
                let lobes = Material::new(&desc).max_lobes(&lobes_of);
                if lobes > MAX_BXDFS {
                    let what = match &spec.name {
                        Some(n) => format!("named material \"{n}\""),
                        None => format!("Material \"{}\"", spec.ty),
                    };
                    self.ctx.warn(
                        spec.loc,
                        format!("{what}: up to {lobes} lobes, more than the {MAX_BXDFS} a BSDF holds (pbrt-v3 aborts there): lobes beyond {MAX_BXDFS} are dropped"),
                        "too many lobes",
                    );
                }
                self.material_lobes.push(lobes);
                self.scene_materials.push(desc);
                self.material_kinds.push(kind);
                let id = MaterialId((self.scene_materials.len() - 1) as u32);
                self.material_keys.insert(key, id);
                id
            }
        };
        if !overrides {
            self.material_ids.insert(spec.stmt, id);
        }
        id
    }
}
