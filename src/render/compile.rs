//! Compiling the scene description into the render-ready scene
//! ([`RenderScene`]): world-space geometry with a BVH, materials, lights and
//! a camera. Only what the scene references is built; what was left out is
//! recorded for `--stats`.

use crate::accel::{Aggregate, Instance, MovingInstance, Object};
use crate::cameras::Camera;
use crate::integrators::{RenderScene, SurfaceMedia};
use crate::lights::{AreaShape, DiffuseEmission, DiffuseLight, Light};
use crate::materials::{link_materials, Material};
use crate::media::Medium;
use crate::scene::{self, MediumInterfaceDesc, SceneDescription, ShapeDesc};
use crate::shapes::{AlphaMask, AnalyticShape, Curve, CurveCommon, TriangleMesh};
use glam::{DMat3, DMat4, Vec3};
use std::collections::HashMap;
use std::sync::Arc;

/// Material slots for the shapes that are medium transitions.
struct Slots {
    map: HashMap<(u32, MediumInterfaceDesc), u32>,
}

impl Slots {
    fn of(&self, s: &ShapeDesc) -> u32 {
        if s.medium_interface.is_transition() {
            self.map[&(s.material.0, s.medium_interface)]
        } else {
            s.material.0
        }
    }
}

impl RenderScene {
    pub fn new(desc: &SceneDescription) -> RenderScene {
        let (materials, surface_media, slots) = material_slots(desc);
        let mut notes = Vec::new();
        let WorldShapes {
            meshes,
            quadrics,
            area,
            mut moving,
            mut singular_moving,
        } = world_shapes(desc, &slots);
        let (objects, instances, singular) =
            place_instances(desc, &slots, &mut moving, &mut singular_moving);
        if singular > 0 {
            notes.push(format!(
                "{singular} instances with a singular transform left out"
            ));
        }
        if singular_moving > 0 {
            notes.push(format!(
                "{singular_moving} animated shapes or instances with a singular start or end transform left out"
            ));
        }
        let instanced_triangles: u64 = instances.iter().map(|i| i.object().triangle_count()).sum();
        let object_triangles: u64 = objects.iter().flatten().map(|o| o.triangle_count()).sum();
        let emissive_shapes = desc
            .shapes
            .iter()
            .filter(|s| s.area_light.is_some())
            .count();
        let aggregate = Aggregate::with_motion(meshes, quadrics, instances, moving);
        if aggregate.degenerate_triangles > 0 {
            notes.push(format!(
                "{} zero-area triangles left out of the BVH",
                aggregate.degenerate_triangles
            ));
        }
        if aggregate.build_work.bounded {
            notes.push(format!(
                "BVH: {} primitives share one box, so the scene level was built by binned SAH with median splits (bounded O(n log n)) instead of PLOC",
                aggregate.build_work.largest_coincident
            ));
        }
        if !aggregate.has_bvh() {
            notes.push("no geometry: no BVH built".into());
        }

        let SceneLights {
            lights,
            infinite: infinite_lights,
            media: light_media,
        } = scene_lights(desc, &area, &aggregate);
        let zero = lights.iter().filter(|l| l.power() <= 0.0).count();
        if zero > 0 {
            notes.push(format!("{zero} lights of zero power are never sampled"));
        }
        let (bvh_nodes, bvh_leaves) = aggregate.bvh_counts();
        notes.push(format!(
            "built: {} triangles in {} meshes, {} quadrics, BVH over {} primitives in {:.1} ms ({}, {:.1} MiB in {} nodes and {} leaves); {} lights ({} area lights from {} emissive shapes)",
            aggregate.meshes.iter().map(|m| m.triangle_count() as u64).sum::<u64>(),
            aggregate.meshes.len(),
            aggregate.quadrics.len(),
            aggregate.primitive_count(),
            aggregate.build_time.as_secs_f64() * 1e3,
            if aggregate.build_work.binned {
                "parallel binned SAH"
            } else {
                "PLOC"
            },
            aggregate.bvh_bytes() as f64 / (1024.0 * 1024.0),
            bvh_nodes,
            bvh_leaves,
            lights.len(),
            area.len(),
            emissive_shapes
        ));
        let camera = Camera::new(&desc.camera, &desc.film);
        if aggregate.moving_count() > 0 || camera.is_moving() {
            notes.push(format!(
                "motion: {} moving shapes or instances (BVH over their motion bounds), {} camera, shutter {}..{}",
                aggregate.moving_count(),
                if camera.is_moving() { "moving" } else { "static" },
                desc.camera.shutter_open,
                desc.camera.shutter_close
            ));
        } else {
            notes.push("motion: none (no motion structures built)".into());
        }
        if aggregate.instance_count() > 0 {
            notes.push(format!(
                "instancing: {} instances of {} objects ({} triangles stored once, {} as instanced)",
                aggregate.instance_count(),
                objects.iter().flatten().count(),
                object_triangles,
                instanced_triangles
            ));
        }
        let material_needs_geom = materials.iter().map(Material::needs_geom).collect();
        let differentials = materials.iter().any(|m| m.needs_geom());
        let media: Vec<Medium> = desc.media.clone();
        if !media.is_empty() {
            notes.push(format!(
                "media: {} ({} material slots for medium boundaries)",
                media.len(),
                surface_media.iter().flatten().count()
            ));
        }
        let has_pass_through = materials.iter().any(Material::is_none);
        RenderScene {
            aggregate,
            materials,
            material_needs_geom,
            lights,
            infinite_lights,
            camera,
            differentials,
            notes,
            media,
            camera_medium: desc.camera_medium.map(|m| m.0),
            light_media,
            surface_media,
            has_pass_through,
        }
    }
}

/// The world's shapes placed for the render core: triangle meshes, analytic
/// shapes (curve pieces included), the emitting ones' area lights, and the
/// animated shapes as moving one-shape objects.
struct WorldShapes {
    meshes: Vec<TriangleMesh>,
    quadrics: Vec<AnalyticShape>,
    /// The area lights: shape, emission and the medium their rays start
    /// in (pbrt-v3: the shape's outside medium, on either side).
    area: Vec<(AreaShape, DiffuseEmission, Option<u32>)>,
    moving: Vec<MovingInstance>,
    /// Animated shapes left out for a singular start or end transform.
    singular_moving: usize,
}

fn world_shapes(desc: &SceneDescription, slots: &Slots) -> WorldShapes {
    let mut meshes = Vec::new();
    let mut quadrics = Vec::new();
    let mut area: Vec<(AreaShape, DiffuseEmission, Option<u32>)> = Vec::new();

    let mut add_shape = |s: &ShapeDesc, to_world: DMat4| {
        let emit = s.area_light.filter(|a| a.l.max_element() > 0.0);
        let medium = s.medium_interface.outside.map(|m| m.0);
        match &s.surface {
            scene::Surface::TriangleMesh(m) => {
                let mesh_index = meshes.len() as u32;
                let mut tm = world_mesh(m, to_world, s, slots.of(s));
                if let Some(a) = emit {
                    tm.first_light = Some(area.len() as u32);
                    for tri in 0..tm.triangle_count() {
                        area.push((
                            AreaShape::Triangle {
                                mesh: mesh_index,
                                tri,
                            },
                            a,
                            medium,
                        ));
                    }
                }
                meshes.push(tm);
            }
            // Curves never emit (the loader warned).
            scene::Surface::Curve(c) => quadrics.extend(curve_pieces(c, to_world, s, slots.of(s))),
            g => {
                let Some(mut q) = placed_analytic(g, to_world, s, slots.of(s)) else {
                    return;
                };
                if let Some(a) = emit {
                    q.set_light(Some(area.len() as u32));
                    area.push((AreaShape::Analytic(quadrics.len() as u32), a, medium));
                }
                quadrics.push(q);
            }
        }
    };
    // An animated shape becomes a one-shape object in its own space
    // placed by a moving instance, as pbrt-v3 builds it with the identity
    // transform inside a `TransformedPrimitive` (never emissive: the
    // loader dropped its area light, as pbrt-v3 does).
    let mut moving = Vec::new();
    let mut singular_moving = 0usize;
    for s in &desc.shapes {
        match &s.motion {
            None => add_shape(s, s.object_to_world),
            Some(m) => {
                let obj = Arc::new(object(std::slice::from_ref(s), |_| DMat4::IDENTITY, slots));
                match MovingInstance::new(obj, m.clone()) {
                    Some(i) => moving.push(i),
                    None => singular_moving += 1,
                }
            }
        }
    }
    WorldShapes {
        meshes,
        quadrics,
        area,
        moving,
        singular_moving,
    }
}

/// The lights of a scene: the area lights of the emitting shapes, then the
/// description's lights (preprocessed for the scene's bounds); the
/// indices of the infinite ones; and each light's medium, where its
/// emitted rays start.
struct SceneLights {
    lights: Vec<Light>,
    infinite: Vec<u32>,
    media: Vec<Option<u32>>,
}

fn scene_lights(
    desc: &SceneDescription,
    area: &[(AreaShape, DiffuseEmission, Option<u32>)],
    geometry: &Aggregate,
) -> SceneLights {
    let mut lights: Vec<Light> = area
        .iter()
        .map(|&(shape, a, _)| DiffuseLight::new(a, shape, geometry).into())
        .collect();
    let mut media: Vec<Option<u32>> = area.iter().map(|a| a.2).collect();
    let mut infinite = Vec::new();
    for (i, l) in desc.lights.iter().enumerate() {
        let mut light = l.clone();
        light.preprocess(geometry);
        if light.is_infinite() {
            infinite.push(lights.len() as u32);
        }
        lights.push(light);
        media.push(desc.light_media.get(i).copied().flatten().map(|m| m.0));
    }
    SceneLights {
        lights,
        infinite,
        media,
    }
}

/// The materials, one per description material plus one per (material,
/// medium interface) pair that crosses media, with each slot's media.
fn material_slots(desc: &SceneDescription) -> (Vec<Material>, Vec<Option<SurfaceMedia>>, Slots) {
    let mut materials: Vec<Material> = desc.materials.iter().map(Material::new).collect();
    link_materials(&mut materials);
    let mut surface_media: Vec<Option<SurfaceMedia>> = vec![None; materials.len()];
    let mut slots = Slots {
        map: HashMap::new(),
    };
    let all_shapes = desc
        .shapes
        .iter()
        .chain(desc.objects.iter().flat_map(|o| o.shapes.iter()));
    for s in all_shapes {
        let mi = s.medium_interface;
        if !mi.is_transition() {
            continue;
        }
        slots.map.entry((s.material.0, mi)).or_insert_with(|| {
            materials.push(materials[s.material.0 as usize].clone());
            surface_media.push(Some(SurfaceMedia {
                inside: mi.inside.map(|m| m.0),
                outside: mi.outside.map(|m| m.0),
            }));
            (materials.len() - 1) as u32
        });
    }
    (materials, surface_media, slots)
}

/// Each instanced object built once, in its own space, and the instances
/// that place it (moving ones go to `moving`); the count of instances left
/// out for a singular transform.
fn place_instances(
    desc: &SceneDescription,
    slots: &Slots,
    moving: &mut Vec<MovingInstance>,
    singular_moving: &mut usize,
) -> (Vec<Option<Arc<Object>>>, Vec<Instance>, usize) {
    // Each instanced object is built once, in its own space, with its own
    // BVH; instances refer to it (two-level BVH, no copies of geometry).
    let objects: Vec<Option<Arc<Object>>> = desc
        .objects
        .iter()
        .enumerate()
        .map(|(i, obj)| {
            if !desc.instances.iter().any(|inst| inst.object == i) {
                return None;
            }
            Some(Arc::new(object(&obj.shapes, |s| s.object_to_world, slots)))
        })
        .collect();
    let mut instances = Vec::with_capacity(desc.instances.len());
    let mut singular = 0usize;
    for inst in &desc.instances {
        let Some(Some(obj)) = objects.get(inst.object) else {
            continue;
        };
        if let Some(m) = &inst.motion {
            match MovingInstance::new(obj.clone(), m.clone()) {
                Some(i) => moving.push(i),
                None => *singular_moving += 1,
            }
            continue;
        }
        match Instance::new(obj.clone(), inst.instance_to_world) {
            Some(i) => instances.push(i),
            None => singular += 1,
        }
    }
    (objects, instances, singular)
}

/// Builds an object's shapes in object space (each placed there by
/// `to_object`) and its BVH. Area lights are never set inside objects
/// (pbrt-v3 ignores them there).
fn object(shapes: &[ShapeDesc], to_object: impl Fn(&ShapeDesc) -> DMat4, slots: &Slots) -> Object {
    let mut meshes = Vec::new();
    let mut quadrics = Vec::new();
    for s in shapes {
        let m4 = to_object(s);
        let material = slots.of(s);
        match &s.surface {
            scene::Surface::TriangleMesh(m) => meshes.push(world_mesh(m, m4, s, material)),
            scene::Surface::Curve(c) => quadrics.extend(curve_pieces(c, m4, s, material)),
            g => quadrics.extend(placed_analytic(g, m4, s, material)),
        }
    }
    Object::new(meshes, quadrics)
}

/// The pieces of a curve's segments (pbrt-v3's `CreateCurve` for each), in
/// the space `to_world` maps to.
fn curve_pieces<'a>(
    c: &'a scene::CurveData,
    to_world: DMat4,
    s: &ShapeDesc,
    material: u32,
) -> impl Iterator<Item = AnalyticShape> + 'a {
    let reverse = s.reverse_orientation;
    c.segments.iter().flat_map(move |seg| {
        let common = Arc::new(CurveCommon::new(
            c.kind,
            seg.cp,
            seg.width,
            seg.normals,
            to_world,
            reverse,
        ));
        Curve::pieces(common, c.split_depth, material).map(AnalyticShape::Curve)
    })
}

/// An analytic shape in the space `to_world` maps to (`None` for meshes and
/// curves).
fn placed_analytic(
    surface: &scene::Surface,
    to_world: DMat4,
    s: &ShapeDesc,
    material: u32,
) -> Option<AnalyticShape> {
    match surface {
        scene::Surface::Analytic(a) => Some(a.placed(to_world, s.reverse_orientation, material)),
        scene::Surface::TriangleMesh(_) | scene::Surface::Curve(_) => None,
    }
}

/// Transform an object-space mesh to world space (positions in f64 before
/// rounding; normals by the inverse transpose), with the shape's material,
/// orientation and alpha masks.
fn world_mesh(m: &scene::MeshData, to_world: DMat4, s: &ShapeDesc, material: u32) -> TriangleMesh {
    let reverse = s.reverse_orientation;
    // An identity transform maps every position to itself exactly: the
    // scene's positions are shared, not copied.
    let p = if to_world == DMat4::IDENTITY {
        m.positions.clone()
    } else {
        Arc::new(
            m.positions
                .iter()
                .map(|v| to_world.transform_point3(v.as_dvec3()).as_vec3())
                .collect(),
        )
    };
    let lin = DMat3::from_mat4(to_world);
    let nm = lin.inverse().transpose();
    let n = m.normals.as_ref().map(|ns| {
        ns.iter()
            .map(|v| (nm * v.as_dvec3()).as_vec3())
            .collect::<Vec<Vec3>>()
    });
    TriangleMesh {
        p,
        n,
        uv: m.uvs.clone(),
        indices: m.indices.clone(),
        face_indices: m.face_indices.clone(),
        flip_normal: reverse ^ (lin.determinant() < 0.0),
        reverse_orientation: reverse,
        material,
        first_light: None,
        alpha: (s.alpha.is_some() || s.shadow_alpha.is_some()).then(|| {
            Arc::new(AlphaMask {
                alpha: s.alpha.clone(),
                shadow: s.shadow_alpha.clone(),
            })
        }),
    }
}
