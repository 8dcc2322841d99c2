//! Objects made from one directive's parameters, with pbrt-v3's defaults:
//! cameras, film, filters, samplers, integrators, materials, textures, lights and
//! shapes. Every lookup marks its parameter used.

use super::color::{blackbody_to_rgb, repeated_wavelength, sampled_to_rgb, xyz_to_rgb};
use super::meshfile::{read_gltf, read_obj};
use super::ply::{read_ply, PlyMesh};
use super::spd;
use super::Ctx;
use crate::lang::params::{Param, ParamList, ParamType};
use crate::lang::parser::Name;
use crate::lang::Loc;
use crate::scene::*;
use glam::{DMat4, DVec3, Vec2, Vec3};
use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;

pub const MAX_RESOLUTION: i64 = 32768;
pub const MAX_SAMPLES: i64 = 1 << 24;

// ---------------------------------------------------------------- lookups

pub(super) fn one<'a>(
    p: &'a ParamList,
    name: &str,
    ty: impl Fn(ParamType) -> bool,
) -> Option<&'a Param> {
    p.items
        .iter()
        .find(|q| q.name == name && ty(q.ty) && q.count() == 1)
        .inspect(|q| q.used.set(true))
}

pub fn float(p: &ParamList, name: &str, def: f64) -> f64 {
    one(p, name, |t| t == ParamType::Float)
        .map(|q| q.nums()[0])
        .unwrap_or(def)
}

pub(super) fn float_opt(p: &ParamList, name: &str) -> Option<(f64, Loc)> {
    one(p, name, |t| t == ParamType::Float).map(|q| (q.nums()[0], q.values_loc))
}

pub fn int(p: &ParamList, name: &str, def: i64) -> (i64, Option<Loc>) {
    one(p, name, |t| t == ParamType::Integer)
        .map(|q| (q.nums()[0] as i64, Some(q.values_loc)))
        .unwrap_or((def, None))
}

pub fn boolean(p: &ParamList, name: &str, def: bool) -> bool {
    one(p, name, |t| t == ParamType::Bool)
        .map(|q| q.bools()[0])
        .unwrap_or(def)
}

pub fn string<'a>(p: &'a ParamList, name: &str) -> Option<(&'a str, Loc)> {
    one(p, name, |t| t == ParamType::String).map(|q| (q.strs()[0].as_str(), q.values_loc))
}

pub(super) fn point3(p: &ParamList, name: &str, def: DVec3) -> DVec3 {
    one(p, name, |t| t == ParamType::Point3)
        .map(|q| DVec3::new(q.nums()[0], q.nums()[1], q.nums()[2]))
        .unwrap_or(def)
}

/// A spectrum-typed parameter as linear RGB (`None` for a type that is not a spectrum).
pub(super) fn spectrum_value(ctx: &mut Ctx, q: &Param) -> Option<Vec3> {
    let v = q.nums();
    match q.ty {
        ParamType::Rgb => Some(Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32)),
        ParamType::Xyz => Some(xyz_to_rgb(v[0], v[1], v[2])),
        ParamType::Blackbody => Some(blackbody_to_rgb(v[0], v[1])),
        ParamType::Spectrum if !q.strs().is_empty() => Some(spectrum_file(ctx, q)),
        ParamType::Spectrum => {
            if let Some(l) = repeated_wavelength(v) {
                ctx.warn(q.values_loc, format!("\"{}\": wavelength {l} nm is given twice (pbrt-v3 stops on a failed check here): read as a step", q.name), "repeated wavelength");
            }
            Some(sampled_to_rgb(v))
        }
        _ => None,
    }
}

/// A spectrum file named by `q` (pbrt-v3 `AddSampledSpectrumFiles`): read once
/// per scene through `ctx.loader`, relative to the top-level file's directory.
/// A file that cannot be read, or that holds no pair, gives black, as in
/// pbrt-v3; problems inside it are warnings at the parameter.
fn spectrum_file(ctx: &mut Ctx, q: &Param) -> Vec3 {
    let name = &q.strs()[0];
    let path = ctx.resolve(q.values_loc, name);
    if let Some(&c) = ctx.spectra.get(&path) {
        return c;
    }
    let shown = path.display().to_string();
    let rgb = match ctx.loader.load(&path) {
        Err(e) => {
            ctx.warn(
                q.values_loc,
                format!("cannot read spectrum file \"{shown}\" for \"{}\": {e}: black is used (as pbrt-v3)", q.name),
                "spectrum file not read",
            );
            Vec3::ZERO
        }
        Ok(bytes) => {
            let file = spd::parse(&String::from_utf8_lossy(&bytes));
            for n in &file.notes {
                ctx.warn(
                    q.values_loc,
                    format!("spectrum file \"{shown}\": {n}"),
                    "in this spectrum file",
                );
            }
            if file.pairs.is_empty() {
                ctx.warn(q.values_loc, format!("spectrum file \"{shown}\" for \"{}\" holds no (wavelength, value) pair: black is used", q.name), "empty spectrum file");
            } else if let Some(l) = repeated_wavelength(&file.pairs) {
                ctx.warn(q.values_loc, format!("spectrum file \"{shown}\": wavelength {l} nm is given twice (pbrt-v3 stops on a failed check here): read as a step"), "repeated wavelength");
            }
            sampled_to_rgb(&file.pairs)
        }
    };
    ctx.spectra.insert(path, rgb);
    rgb
}

pub(super) fn find_spectrum<'a>(p: &'a ParamList, name: &str) -> Option<&'a Param> {
    let q = p
        .items
        .iter()
        .find(|q| q.name == name && q.ty.is_spectrum())?;
    // One spectrum: one triple for rgb/xyz, one pair for blackbody, any pairs
    // or one file name for spectrum (several files are several spectra).
    let single = match q.ty {
        ParamType::Spectrum => q.strs().len() <= 1,
        _ => q.count() == 1,
    };
    if single {
        q.used.set(true);
        Some(q)
    } else {
        None
    }
}

/// A spectrum parameter (rgb, color, xyz, blackbody or spectrum) as RGB.
pub fn spectrum(ctx: &mut Ctx, p: &ParamList, name: &str, def: Vec3) -> Vec3 {
    find_spectrum(p, name)
        .and_then(|q| spectrum_value(ctx, q))
        .unwrap_or(def)
}

/// Light `scale`: a spectrum in pbrt-v3; a plain float is accepted too.
fn light_scale(ctx: &mut Ctx, p: &ParamList) -> Vec3 {
    if let Some((f, _)) = float_opt(p, "scale") {
        return Vec3::splat(f as f32);
    }
    spectrum(ctx, p, "scale", Vec3::ONE)
}

/// pbrt-v3 `shapeMaySetMaterialParameters` (api.cpp): whether a shape's parameters
/// may override its material's.
pub fn shape_may_set_material_params(p: &ParamList) -> bool {
    p.items.iter().any(|q| match q.ty {
        ParamType::Texture => q.name != "alpha" && q.name != "shadowalpha",
        ParamType::Float => q.count() == 1 && q.name != "radius",
        ParamType::String => {
            q.count() == 1 && !matches!(q.name.as_str(), "filename" | "type" | "scheme")
        }
        ParamType::Spectrum => true,
        _ => q.count() == 1,
    })
}

// ---------------------------------------------------------------- lights

pub fn area_light(ctx: &mut Ctx, p: &ParamList) -> AreaLightDesc {
    let l = spectrum(ctx, p, "L", Vec3::ONE) * light_scale(ctx, p);
    let (ns, _) = int(p, "nsamples", 1);
    let (n, _) = int(p, "samples", ns);
    let two_sided = boolean(p, "twosided", false);
    AreaLightDesc {
        l,
        two_sided,
        n_samples: n.clamp(1, MAX_SAMPLES) as u32,
    }
}

/// `LightSource`: point, spot, distant, infinite; others are warned about and skipped.
pub fn light(ctx: &mut Ctx, name: &Name, p: &ParamList, ctm: DMat4) -> Option<LightDesc> {
    match name.value.as_str() {
        "point" => {
            let i = spectrum(ctx, p, "I", Vec3::ONE) * light_scale(ctx, p);
            let from = point3(p, "from", DVec3::ZERO);
            // pbrt-v3 point.cpp: light-to-world = Translate(from) · CTM, so the light
            // sits at CTM·origin + from (not CTM·from when the CTM scales or rotates).
            Some(LightDesc::Point {
                position: ctm.transform_point3(DVec3::ZERO) + from,
                intensity: i,
            })
        }
        "spot" => {
            let i = spectrum(ctx, p, "I", Vec3::ONE) * light_scale(ctx, p);
            let cone = float(p, "coneangle", 30.0);
            let delta = float(p, "conedeltaangle", 5.0);
            let from = point3(p, "from", DVec3::ZERO);
            let to = point3(p, "to", DVec3::Z);
            let dir = to - from;
            if dir.length_squared() == 0.0 {
                ctx.warn(
                    name.loc,
                    "spot light with \"from\" equal to \"to\" has no direction: skipped",
                    "degenerate spot light",
                );
                return None;
            }
            let dir = dir.normalize();
            // pbrt-v3 CoordinateSystem(dir, &du, &dv); light2world = CTM · Translate(from) · Inverse(dirToZ).
            let du = if dir.x.abs() > dir.y.abs() {
                DVec3::new(-dir.z, 0.0, dir.x) / (dir.x * dir.x + dir.z * dir.z).sqrt()
            } else {
                DVec3::new(0.0, dir.z, -dir.y) / (dir.y * dir.y + dir.z * dir.z).sqrt()
            };
            let dv = dir.cross(du);
            let frame = DMat4::from_cols(
                du.extend(0.0),
                dv.extend(0.0),
                dir.extend(0.0),
                glam::DVec4::W,
            );
            let light_to_world = ctm * DMat4::from_translation(from) * frame;
            if !light_to_world.is_finite() {
                ctx.warn(
                    name.loc,
                    "spot light transform is not finite (from/to too large): skipped",
                    "degenerate spot light",
                );
                return None;
            }
            Some(LightDesc::Spot {
                light_to_world,
                intensity: i,
                cone_angle: cone as f32,
                cone_delta_angle: delta as f32,
            })
        }
        "distant" => {
            let l = spectrum(ctx, p, "L", Vec3::ONE) * light_scale(ctx, p);
            let from = point3(p, "from", DVec3::ZERO);
            let to = point3(p, "to", DVec3::Z);
            let d = ctm.transform_vector3(from - to);
            if d.length_squared() == 0.0 || !d.is_finite() {
                ctx.warn(
                    name.loc,
                    "distant light with \"from\" equal to \"to\" has no direction: skipped",
                    "degenerate distant light",
                );
                return None;
            }
            Some(LightDesc::Distant {
                radiance: l,
                direction: d.normalize(),
            })
        }
        "infinite" | "exinfinite" => {
            // pbrt-v3 reads `scale` as a spectrum only: "float scale" stays unused.
            let l = spectrum(ctx, p, "L", Vec3::ONE) * spectrum(ctx, p, "scale", Vec3::ONE);
            let (ns, _) = int(p, "nsamples", 1);
            let (n, _) = int(p, "samples", ns);
            let image = match string(p, "mapname") {
                Some((map, loc)) if !map.is_empty() => {
                    // Raw values: pbrt-v3's infinite light does not sRGB-decode.
                    Some(super::image::load_image(ctx, loc, map, Decode::Raw)?)
                }
                _ => None,
            };
            let sampling = match string(p, "sampling") {
                None | Some(("map", _)) => EnvSampling::Map,
                Some(("uniform", _)) => EnvSampling::Uniform,
                Some((other, loc)) => {
                    ctx.warn(
                        loc,
                        format!("unknown infinite light sampling \"{other}\" (pbrs has \"map\" and \"uniform\"): \"map\" is used"),
                        "unknown sampling",
                    );
                    EnvSampling::Map
                }
            };
            Some(LightDesc::Infinite {
                radiance: l,
                image,
                light_to_world: ctm,
                n_samples: n.clamp(1, MAX_SAMPLES) as u32,
                sampling,
            })
        }
        other => {
            p.mark_all_used();
            if matches!(other, "goniometric" | "projection") {
                ctx.warn(
                    name.loc,
                    format!("light \"{other}\" is not supported by pbrs: ignored"),
                    "light ignored",
                );
            } else {
                ctx.warn(name.loc, format!("unknown light type \"{other}\": ignored (pbrt-v3 has point, spot, goniometric, projection, distant, infinite)"), "unknown light");
            }
            None
        }
    }
}

// ---------------------------------------------------------------- shapes

/// The shapes pbrs builds (pbrt-v3's, and the mesh-file extensions).
const SHAPES: &[&str] = &[
    "sphere",
    "disk",
    "cylinder",
    "cone",
    "paraboloid",
    "hyperboloid",
    "curve",
    "trianglemesh",
    "plymesh",
    "objmesh",
    "gltfmesh",
];

/// True for shapes pbrs skips as unsupported or unknown (an invalid shape of
/// a supported type got an error or warning of its own).
pub fn is_unsupported_shape(name: &str) -> bool {
    !SHAPES.contains(&name) && !super::refine::REFINED_SHAPES.contains(&name)
}

/// The geometry of a `Shape`, or `None` (unsupported: warning; invalid: error).
pub fn geometry(
    ctx: &mut Ctx,
    name: &Name,
    p: &ParamList,
    meshes: &mut HashMap<PathBuf, Option<Arc<MeshData>>>,
) -> Option<Geometry> {
    match name.value.as_str() {
        "sphere" => {
            let radius = float(p, "radius", 1.0);
            if radius <= 0.0 {
                let loc = p.get("radius").map(|q| q.values_loc).unwrap_or(name.loc);
                ctx.error(
                    loc,
                    format!("sphere radius {radius} is not positive"),
                    "radius must be > 0",
                    None,
                );
                return None;
            }
            let zmin = float(p, "zmin", -radius);
            let zmax = float(p, "zmax", radius);
            let phimax = float(p, "phimax", 360.0).clamp(0.0, 360.0);
            let (z0, z1) = (
                zmin.min(zmax).clamp(-radius, radius),
                zmin.max(zmax).clamp(-radius, radius),
            );
            if phimax <= 0.0 || z0 >= z1 {
                ctx.warn(
                    name.loc,
                    "sphere with an empty extent (phimax 0 or zmin = zmax): skipped",
                    "empty sphere",
                );
                return None;
            }
            if radius as f32 == f32::INFINITY {
                ctx.error(
                    name.loc,
                    "sphere radius does not fit a 32-bit float",
                    "radius too large",
                    None,
                );
                return None;
            }
            Some(Geometry::Sphere {
                radius: radius as f32,
                z_min: z0 as f32,
                z_max: z1 as f32,
                phi_max: phimax as f32,
            })
        }
        "disk" => disk(ctx, name, p),
        "cylinder" => cylinder(ctx, name, p),
        "cone" => cone(ctx, name, p),
        "paraboloid" => paraboloid(ctx, name, p),
        "hyperboloid" => hyperboloid(ctx, name, p),
        "curve" => curve(ctx, name, p),
        "trianglemesh" => triangle_mesh(ctx, name, p).map(|m| Geometry::TriangleMesh(Arc::new(m))),
        "plymesh" | "objmesh" | "gltfmesh" => mesh_file(ctx, name, p, meshes),
        "loopsubdiv" | "nurbs" | "heightfield" => super::refine::shape(ctx, name, p),
        other => {
            p.mark_all_used();
            let all: Vec<&str> = SHAPES
                .iter()
                .chain(super::refine::REFINED_SHAPES)
                .copied()
                .collect();
            let hint = super::state::closest_name(other, &all)
                .map(|c| format!(" (did you mean \"{c}\"?)"))
                .unwrap_or_default();
            ctx.warn(
                name.loc,
                format!("unknown shape \"{other}\"{hint}: skipped (as pbrt-v3)"),
                "unknown shape",
            );
            None
        }
    }
}

/// pbrt-v3's `cylinder` (`radius` 1, `zmin` -1, `zmax` 1, `phimax` 360).
fn cylinder(ctx: &mut Ctx, name: &Name, p: &ParamList) -> Option<Geometry> {
    let radius = float(p, "radius", 1.0);
    let (zmin, zmax) = (float(p, "zmin", -1.0), float(p, "zmax", 1.0));
    let phimax = float(p, "phimax", 360.0).clamp(0.0, 360.0);
    let fits = |v: f64| (v as f32).is_finite();
    if radius.is_nan() || radius <= 0.0 || !fits(radius) || !fits(zmin) || !fits(zmax) {
        let loc = p.get("radius").map(|q| q.values_loc).unwrap_or(name.loc);
        ctx.error(
            loc,
            format!("cylinder radius {radius} (zmin {zmin}, zmax {zmax}) is not a positive 32-bit float"),
            "bad cylinder",
            None,
        );
        return None;
    }
    // pbrt-v3 orders zmin and zmax itself.
    let (z0, z1) = (zmin.min(zmax), zmin.max(zmax));
    if z0 >= z1 || phimax <= 0.0 {
        ctx.warn(
            name.loc,
            "cylinder with an empty extent (zmin = zmax or phimax 0): skipped",
            "empty cylinder",
        );
        return None;
    }
    Some(Geometry::Cylinder {
        radius: radius as f32,
        z_min: z0 as f32,
        z_max: z1 as f32,
        phi_max: phimax as f32,
    })
}

/// `phimax` clamped to [0, 360] as pbrt-v3; `None` (with a warning) at 0.
fn phi_max(ctx: &mut Ctx, name: &Name, p: &ParamList) -> Option<f32> {
    let phimax = float(p, "phimax", 360.0);
    let clamped = if phimax.is_nan() {
        0.0
    } else {
        phimax.clamp(0.0, 360.0)
    };
    if clamped <= 0.0 {
        let loc = p.get("phimax").map(|q| q.values_loc).unwrap_or(name.loc);
        ctx.warn(
            loc,
            format!(
                "{} with phimax {phimax}: an empty surface, skipped",
                name.value
            ),
            "phimax must be > 0",
        );
        return None;
    }
    Some(clamped as f32)
}

/// An error unless every value is a finite 32-bit float and `positive` ones
/// are > 0.
fn check_floats(ctx: &mut Ctx, name: &Name, p: &ParamList, values: &[(&str, f64, bool)]) -> bool {
    for &(k, v, positive) in values {
        let ok = (v as f32).is_finite() && (!positive || v > 0.0);
        if !ok {
            let loc = p.get(k).map(|q| q.values_loc).unwrap_or(name.loc);
            let what = if positive {
                "a positive 32-bit float"
            } else {
                "a finite 32-bit float"
            };
            ctx.error(
                loc,
                format!("{} {k} {v} is not {what}", name.value),
                format!("bad {k}"),
                None,
            );
            return false;
        }
    }
    true
}

/// pbrt-v3's `cone` (`radius` 1, `height` 1, `phimax` 360).
fn cone(ctx: &mut Ctx, name: &Name, p: &ParamList) -> Option<Geometry> {
    let radius = float(p, "radius", 1.0);
    let height = float(p, "height", 1.0);
    if !check_floats(
        ctx,
        name,
        p,
        &[("radius", radius, true), ("height", height, true)],
    ) {
        return None;
    }
    Some(Geometry::Cone {
        radius: radius as f32,
        height: height as f32,
        phi_max: phi_max(ctx, name, p)?,
    })
}

/// pbrt-v3's `paraboloid` (`radius` 1, `zmin` 0, `zmax` 1, `phimax` 360).
fn paraboloid(ctx: &mut Ctx, name: &Name, p: &ParamList) -> Option<Geometry> {
    let radius = float(p, "radius", 1.0);
    let (zmin, zmax) = (float(p, "zmin", 0.0), float(p, "zmax", 1.0));
    if !check_floats(
        ctx,
        name,
        p,
        &[
            ("radius", radius, true),
            ("zmin", zmin, false),
            ("zmax", zmax, false),
        ],
    ) {
        return None;
    }
    // pbrt-v3 orders zmin and zmax; its surface x² + y² = r² z / zmax has
    // points only where z / zmax >= 0.
    let (mut z0, z1) = (zmin.min(zmax), zmin.max(zmax));
    if z1 <= 0.0 {
        let loc = p.get("zmax").map(|q| q.values_loc).unwrap_or(name.loc);
        ctx.error(
            loc,
            format!(
                "paraboloid zmax {z1} is not positive (the paraboloid opens upwards from z = 0)"
            ),
            "zmax must be > 0",
            None,
        );
        return None;
    }
    if z0 < 0.0 {
        let loc = p.get("zmin").map(|q| q.values_loc).unwrap_or(name.loc);
        ctx.warn(
            loc,
            format!("paraboloid zmin {z0} is below its apex at z = 0: 0 is used (the surface has no points below)"),
            "negative zmin",
        );
        z0 = 0.0;
    }
    if z0 >= z1 {
        ctx.warn(
            name.loc,
            format!("paraboloid with zmin = zmax = {z1}: an empty surface, skipped"),
            "empty paraboloid",
        );
        return None;
    }
    Some(Geometry::Paraboloid {
        radius: radius as f32,
        z_min: z0 as f32,
        z_max: z1 as f32,
        phi_max: phi_max(ctx, name, p)?,
    })
}

/// pbrt-v3's `hyperboloid` (`p1` 0 0 0, `p2` 1 1 1, `phimax` 360).
fn hyperboloid(ctx: &mut Ctx, name: &Name, p: &ParamList) -> Option<Geometry> {
    let p1 = point3(p, "p1", DVec3::ZERO);
    let p2 = point3(p, "p2", DVec3::ONE);
    let loc = p
        .get("p1")
        .or_else(|| p.get("p2"))
        .map(|q| q.values_loc)
        .unwrap_or(name.loc);
    if !(p1.as_vec3().is_finite() && p2.as_vec3().is_finite()) {
        ctx.error(
            loc,
            "hyperboloid p1/p2 are not finite 32-bit floats",
            "bad point",
            None,
        );
        return None;
    }
    let (p1, p2) = (p1.as_vec3(), p2.as_vec3());
    let bad = |why: &str| {
        format!(
            "hyperboloid p1 [{} {} {}], p2 [{} {} {}]: {why}",
            p1.x, p1.y, p1.z, p2.x, p2.y, p2.z
        )
    };
    if p1.z == p2.z {
        ctx.error(loc, bad("p1 and p2 are at the same height, so they define no hyperboloid (pbrt-v3 divides by zero); use a disk for an annulus"), "p1.z = p2.z", None);
        return None;
    }
    let Some((a, c)) =
        crate::render::shapes::hyperboloid_coefficients(p1.as_dvec3(), p2.as_dvec3())
    else {
        ctx.error(loc, bad("the line through them meets the z axis, which makes a cone, not a hyperboloid (pbrt-v3 never finishes building it); use a cone"), "no hyperboloid", None);
        return None;
    };
    let (z0, z1) = (p1.z.min(p2.z) as f64, p1.z.max(p2.z) as f64);
    let rho2 = |z: f64| (1.0 + c * z * z) / a;
    let inside = z0 < 0.0 && z1 > 0.0;
    if !(rho2(z0) > 0.0 && rho2(z1) > 0.0 && (!inside || rho2(0.0) > 0.0)) {
        ctx.error(loc, bad("the implicit surface pbrt-v3 fits to them has no points at some heights between p1 and p2 (not a hyperboloid of one sheet there)"), "not a hyperboloid", None);
        return None;
    }
    Some(Geometry::Hyperboloid {
        p1,
        p2,
        phi_max: phi_max(ctx, name, p)?,
    })
}

/// pbrt-v3's `disk` (`height` 0, `radius` 1, `innerradius` 0, `phimax` 360).
fn disk(ctx: &mut Ctx, name: &Name, p: &ParamList) -> Option<Geometry> {
    let loc_of = |k: &str| p.get(k).map(|q| q.values_loc).unwrap_or(name.loc);
    let height = float(p, "height", 0.0);
    let radius = float(p, "radius", 1.0);
    let mut inner = float(p, "innerradius", 0.0);
    let phimax = float(p, "phimax", 360.0).clamp(0.0, 360.0);
    let fits = |v: f64| (v as f32).is_finite();
    if radius.is_nan() || radius <= 0.0 || !fits(radius) || !fits(height) || !fits(inner) {
        ctx.error(
            loc_of("radius"),
            format!("disk radius {radius} (height {height}, innerradius {inner}) is not a positive 32-bit float"),
            "bad disk",
            None,
        );
        return None;
    }
    if inner < 0.0 {
        ctx.warn(
            loc_of("innerradius"),
            format!("disk innerradius {inner} is negative: 0 is used"),
            "negative innerradius",
        );
        inner = 0.0;
    }
    if inner >= radius || phimax <= 0.0 {
        ctx.warn(
            name.loc,
            format!("disk with an empty extent (innerradius {inner} >= radius {radius}, or phimax 0): skipped"),
            "empty disk",
        );
        return None;
    }
    Some(Geometry::Disk {
        height: height as f32,
        radius: radius as f32,
        inner_radius: inner as f32,
        phi_max: phimax as f32,
    })
}

/// `plymesh`, and the pbrs extensions `objmesh` and `gltfmesh`: a mesh read
/// from a file (once per file, shared by every shape that names it).
fn mesh_file(
    ctx: &mut Ctx,
    name: &Name,
    p: &ParamList,
    meshes: &mut HashMap<PathBuf, Option<Arc<MeshData>>>,
) -> Option<Geometry> {
    let kind = match name.value.as_str() {
        "plymesh" => "PLY",
        "objmesh" => "OBJ",
        _ => "glTF",
    };
    let Some((file, floc)) = string(p, "filename") else {
        ctx.error(
            name.loc,
            format!("{} needs a \"string filename\" parameter", name.value),
            "no filename",
            None,
        );
        return None;
    };
    let path = ctx.resolve(floc, file);
    if let Some(m) = meshes.get(&path) {
        return m.clone().map(Geometry::TriangleMesh);
    }
    let result = match ctx.loader.load(&path) {
        Err(e) => Err(format!(
            "cannot read {kind} file \"{}\": {e}",
            path.display()
        )),
        Ok(bytes) => {
            let read = match kind {
                "PLY" => read_ply(&bytes),
                "OBJ" => read_obj(&bytes).map(|mesh| PlyMesh {
                    mesh,
                    notes: Vec::new(),
                }),
                _ => {
                    let dir = path.parent().unwrap_or(std::path::Path::new("."));
                    let loader = &ctx.loader;
                    read_gltf(&bytes, dir, &|f| loader.load(f)).map(|mesh| PlyMesh {
                        mesh,
                        notes: Vec::new(),
                    })
                }
            };
            read.map_err(|e| format!("{kind} file \"{}\": {e}", path.display()))
        }
    };
    let mesh = match result {
        Ok(m) => {
            for n in m.notes {
                ctx.warn(
                    floc,
                    format!("{kind} file \"{}\": {n}", path.display()),
                    "this mesh",
                );
            }
            if m.mesh.positions.iter().any(|v| !v.is_finite()) {
                ctx.error(
                    floc,
                    format!(
                        "{kind} file \"{}\" has a vertex that is not a finite 32-bit number",
                        path.display()
                    ),
                    "this mesh",
                    None,
                );
                None
            } else {
                Some(Arc::new(m.mesh))
            }
        }
        Err(e) => {
            ctx.error(floc, e, "this mesh", None);
            None
        }
    };
    meshes.insert(path, mesh.clone());
    mesh.map(Geometry::TriangleMesh)
}

/// Most Bézier segments one `curve` may have (each becomes 2^splitdepth BVH
/// primitives).
const MAX_CURVE_SEGMENTS: usize = 1 << 22;

/// pbrt-v3's `CreateCurveShape`: the curve as cubic Bézier segments, with
/// its checks (located errors where pbrt-v3 reports an error and makes no
/// shape).
fn curve(ctx: &mut Ctx, name: &Name, p: &ParamList) -> Option<Geometry> {
    let width = float(p, "width", 1.0);
    let width0 = float(p, "width0", width);
    let width1 = float(p, "width1", width);
    let (degree, degree_loc) = int(p, "degree", 3);
    if degree != 2 && degree != 3 {
        ctx.error(
            degree_loc.unwrap_or(name.loc),
            format!("curve degree {degree}: only degree 2 and 3 curves are supported (as pbrt-v3)"),
            "degree must be 2 or 3",
            None,
        );
        return None;
    }
    let degree = degree as usize;
    let bspline = match string(p, "basis") {
        None | Some(("bezier", _)) => false,
        Some(("bspline", _)) => true,
        Some((other, loc)) => {
            ctx.error(
                loc,
                format!("curve basis \"{other}\": only \"bezier\" and \"bspline\" are supported (as pbrt-v3)"),
                "unknown basis",
                None,
            );
            return None;
        }
    };
    let Some(pp) = p.find("P", |t| t == ParamType::Point3) else {
        ctx.error(
            name.loc,
            "curve needs control points \"point P\"",
            "no \"point P\"",
            None,
        );
        return None;
    };
    let cp = to_vec3(pp.nums());
    let ncp = cp.len();
    let segments = if bspline {
        if ncp < degree + 1 {
            ctx.error(
                pp.values_loc,
                format!(
                    "{ncp} control points: a degree {degree} b-spline curve needs at least {}",
                    degree + 1
                ),
                "too few control points",
                None,
            );
            return None;
        }
        ncp - degree
    } else {
        if ncp < degree + 1 || !(ncp - 1 - degree).is_multiple_of(degree) {
            ctx.error(
                pp.values_loc,
                format!("{ncp} control points: a degree {degree} Bézier curve needs {} + n·{degree} (n ≥ 0)", degree + 1),
                "wrong number of control points",
                None,
            );
            return None;
        }
        (ncp - 1) / degree
    };
    if cp.iter().any(|v| !v.is_finite()) {
        ctx.error(
            pp.values_loc,
            "a control point of \"P\" does not fit a 32-bit float",
            "too large",
            None,
        );
        return None;
    }
    if segments > MAX_CURVE_SEGMENTS {
        ctx.error(
            pp.values_loc,
            format!("{segments} curve segments: pbrs takes at most {MAX_CURVE_SEGMENTS} per curve"),
            "too many segments",
            None,
        );
        return None;
    }
    let kind = match string(p, "type") {
        None | Some(("flat", _)) => CurveKind::Flat,
        Some(("ribbon", _)) => CurveKind::Ribbon,
        Some(("cylinder", _)) => CurveKind::Cylinder,
        Some((other, loc)) => {
            ctx.warn(
                loc,
                format!("unknown curve type \"{other}\": \"cylinder\" is used (as pbrt-v3)"),
                "unknown curve type",
            );
            CurveKind::Cylinder
        }
    };
    let mut normals = None;
    match p.find("N", |t| t == ParamType::Normal) {
        Some(q) if kind != CurveKind::Ribbon => {
            ctx.warn(
                q.values_loc,
                "curve normals \"N\" are only used by \"ribbon\" curves: ignored (as pbrt-v3)",
                "ignored",
            );
        }
        Some(q) => {
            let n = to_vec3(q.nums());
            if n.len() != segments + 1 {
                ctx.error(
                    q.values_loc,
                    format!(
                        "{} normals: a ribbon curve with {segments} segments needs {}",
                        n.len(),
                        segments + 1
                    ),
                    "wrong number of normals",
                    None,
                );
                return None;
            }
            if n.iter()
                .any(|v| !(v.is_finite() && v.length_squared() > 0.0 && v.normalize().is_finite()))
            {
                ctx.error(
                    q.values_loc,
                    "a ribbon normal is zero or not a finite 32-bit vector",
                    "bad normal",
                    None,
                );
                return None;
            }
            normals = Some(n);
        }
        None if kind == CurveKind::Ribbon => {
            ctx.error(
                name.loc,
                "a ribbon curve needs normals \"N\" at its segments' ends (as pbrt-v3)",
                "no \"normal N\"",
                None,
            );
            return None;
        }
        None => {}
    }
    let split_depth = match int(p, "splitdepth", -1) {
        (-1, None) => float(p, "splitdepth", 3.0) as i64,
        (d, _) => d,
    };
    // pbrt-v3 takes a negative depth as no split and overflows past 31;
    // beyond 10 a piece is already far below the subdivision's resolution.
    let split_depth = split_depth.clamp(0, 10) as u32;
    let (w0, w1) = (width0 as f32, width1 as f32);
    let wloc = p
        .get("width0")
        .or_else(|| p.get("width1"))
        .or_else(|| p.get("width"))
        .map(|q| q.values_loc)
        .unwrap_or(name.loc);
    if !(w0 > 0.0 && w1 > 0.0 && w0.is_finite() && w1.is_finite()) {
        ctx.error(
            wloc,
            format!("curve widths {width0} and {width1}: both must be positive 32-bit floats (pbrt-v3 gives NaN or no curve otherwise)"),
            "width must be > 0",
            None,
        );
        return None;
    }
    let mut out = Vec::with_capacity(segments);
    for seg in 0..segments {
        let bez = if bspline {
            bspline_to_bezier(&cp[seg..seg + degree + 1])
        } else {
            bezier_to_cubic(&cp[seg * degree..seg * degree + degree + 1])
        };
        let t0 = seg as f32 / segments as f32;
        let t1 = (seg + 1) as f32 / segments as f32;
        out.push(CurveSegment {
            cp: bez,
            width: [w0 + (w1 - w0) * t0, w0 + (w1 - w0) * t1],
            normals: normals.as_ref().map(|n: &Vec<Vec3>| [n[seg], n[seg + 1]]),
        });
    }
    Some(Geometry::Curve(Arc::new(CurveData {
        kind,
        segments: out,
        split_depth,
    })))
}

/// A Bézier segment of degree 2 or 3 as a cubic (degree elevation).
fn bezier_to_cubic(c: &[Vec3]) -> [Vec3; 4] {
    if c.len() == 3 {
        [
            c[0],
            c[0].lerp(c[1], 2.0 / 3.0),
            c[1].lerp(c[2], 1.0 / 3.0),
            c[2],
        ]
    } else {
        [c[0], c[1], c[2], c[3]]
    }
}

/// A uniform b-spline segment of degree 2 or 3 as the cubic Bézier of the
/// same curve (by blossoming, as pbrt-v3).
fn bspline_to_bezier(c: &[Vec3]) -> [Vec3; 4] {
    if c.len() == 3 {
        let (p11, p12, p22) = (c[0].lerp(c[1], 0.5), c[1], c[1].lerp(c[2], 0.5));
        [p11, p11.lerp(p12, 2.0 / 3.0), p12.lerp(p22, 1.0 / 3.0), p22]
    } else {
        let p122 = c[0].lerp(c[1], 2.0 / 3.0);
        let p223 = c[1].lerp(c[2], 1.0 / 3.0);
        let p233 = c[1].lerp(c[2], 2.0 / 3.0);
        let p334 = c[2].lerp(c[3], 1.0 / 3.0);
        [p122.lerp(p223, 0.5), p223, p233, p233.lerp(p334, 0.5)]
    }
}

fn to_vec3(v: &[f64]) -> Vec<Vec3> {
    v.chunks_exact(3)
        .map(|c| Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32))
        .collect()
}

fn triangle_mesh(ctx: &mut Ctx, name: &Name, p: &ParamList) -> Option<MeshData> {
    let Some(pp) = p
        .items
        .iter()
        .find(|q| q.name == "P" && q.ty == ParamType::Point3)
    else {
        ctx.error(
            name.loc,
            "trianglemesh needs vertex positions \"point P\"",
            "no \"point P\"",
            None,
        );
        return None;
    };
    pp.used.set(true);
    let positions = to_vec3(pp.nums());
    let nv = positions.len();
    if nv == 0 {
        ctx.error(
            pp.values_loc,
            "trianglemesh has no vertices",
            "empty \"point P\"",
            None,
        );
        return None;
    }
    if positions.iter().any(|v| !v.is_finite()) {
        ctx.error(
            pp.values_loc,
            "a vertex of \"P\" does not fit a 32-bit float",
            "too large",
            None,
        );
        return None;
    }
    let indices: Vec<u32> = match p
        .items
        .iter()
        .find(|q| q.name == "indices" && q.ty == ParamType::Integer)
    {
        Some(q) => {
            q.used.set(true);
            let v = q.nums();
            if v.len() % 3 != 0 {
                ctx.error(
                    q.values_loc,
                    format!(
                        "trianglemesh \"indices\" has {} values, not a multiple of 3",
                        v.len()
                    ),
                    "indices",
                    None,
                );
                return None;
            }
            if let Some((k, &bad)) = v
                .iter()
                .enumerate()
                .find(|(_, &x)| x < 0.0 || x >= nv as f64)
            {
                let why = if bad < 0.0 {
                    "negative"
                } else {
                    "out of range"
                };
                ctx.error(
                    q.values_loc,
                    format!(
                        "trianglemesh index {bad} (entry {k}) is {why}: \"P\" has {nv} vertices"
                    ),
                    format!("{why} index"),
                    None,
                );
                return None;
            }
            v.iter().map(|&x| x as u32).collect()
        }
        None if nv == 3 => vec![0, 1, 2],
        None => {
            ctx.error(name.loc, format!("trianglemesh needs \"integer indices\" (it has {nv} vertices; only a single triangle may omit them)"), "no \"integer indices\"", None);
            return None;
        }
    };
    let normals = match p
        .items
        .iter()
        .find(|q| q.name == "N" && q.ty == ParamType::Normal)
    {
        Some(q) => {
            q.used.set(true);
            let n = to_vec3(q.nums());
            if q.count() != nv {
                ctx.warn(q.values_loc, format!("\"N\" has {} normals but \"P\" has {nv} vertices: normals dropped (as pbrt-v3)", q.count()), "count mismatch");
                None
            } else if n.iter().any(|v| !v.is_finite() || *v == Vec3::ZERO) {
                ctx.warn(
                    q.values_loc,
                    "\"N\" has a zero or non-finite normal: normals dropped",
                    "bad normal",
                );
                None
            } else {
                Some(n)
            }
        }
        None => None,
    };
    let uvq = ["uv", "st"].iter().find_map(|n| {
        p.items
            .iter()
            .find(|q| q.name == *n && matches!(q.ty, ParamType::Point2 | ParamType::Float))
    });
    let uvs = match uvq {
        Some(q) => {
            q.used.set(true);
            let v = q.nums();
            if v.len() != 2 * nv {
                ctx.warn(q.values_loc, format!("\"{}\" has {} numbers but \"P\" has {nv} vertices (expected {}): uvs dropped (as pbrt-v3)", q.name, v.len(), 2 * nv), "count mismatch");
                None
            } else {
                Some(
                    v.chunks_exact(2)
                        .map(|c| Vec2::new(c[0] as f32, c[1] as f32))
                        .collect(),
                )
            }
        }
        None => None,
    };
    Some(MeshData {
        positions,
        indices,
        normals,
        uvs,
    })
}

// ---------------------------------------------------------------- options

type Ent<'a> = Option<(&'a Name, &'a ParamList)>;

/// The `Camera` directive (see `loader/camera.rs`); `film` gives the
/// realistic camera its sensor size.
pub fn camera(
    ctx: &mut Ctx,
    c: Option<((&Name, &ParamList), DMat4)>,
    film: &FilmDesc,
) -> CameraDesc {
    super::camera::camera(ctx, c, film)
}

pub fn default_camera() -> CameraDesc {
    CameraDesc {
        camera_to_world: DMat4::IDENTITY,
        motion: None,
        kind: CameraKind::Perspective {
            fov: 90.0,
            lens_radius: 0.0,
            focal_distance: 1e6,
            frame_aspect_ratio: None,
            screen_window: None,
        },
        shutter_open: 0.0,
        shutter_close: 1.0,
    }
}

fn checked_count(ctx: &mut Ctx, p: &ParamList, name: &str, def: i64, max: i64, what: &str) -> u32 {
    let (v, loc) = int(p, name, def);
    if v < 1 || v > max {
        let loc = loc.unwrap_or_default();
        ctx.error(
            loc,
            format!("{what} \"{name}\" is {v}: it must be between 1 and {max}"),
            "out of range",
            None,
        );
        return def as u32;
    }
    v as u32
}

pub fn film(ctx: &mut Ctx, f: Ent) -> FilmDesc {
    let empty = ParamList::default();
    let p = match f {
        Some((name, p)) if name.value != "image" => {
            p.mark_all_used();
            ctx.error(
                name.loc,
                format!(
                    "unknown film \"{}\" (pbrt-v3 has only \"image\")",
                    name.value
                ),
                "unknown film",
                None,
            );
            &empty
        }
        Some((_, p)) => p,
        None => &empty,
    };
    let xresolution = checked_count(
        ctx,
        p,
        "xresolution",
        1280,
        MAX_RESOLUTION,
        "film resolution",
    );
    let yresolution = checked_count(
        ctx,
        p,
        "yresolution",
        720,
        MAX_RESOLUTION,
        "film resolution",
    );
    let mut cropwindow = [0.0, 1.0, 0.0, 1.0];
    if let Some(q) = p
        .items
        .iter()
        .find(|q| q.name == "cropwindow" && q.ty == ParamType::Float)
    {
        q.used.set(true);
        let v = q.nums();
        if v.len() == 4 {
            let c = |a: f64| a.clamp(0.0, 1.0) as f32;
            cropwindow = [
                c(v[0].min(v[1])),
                c(v[0].max(v[1])),
                c(v[2].min(v[3])),
                c(v[2].max(v[3])),
            ];
            if cropwindow[0] >= cropwindow[1] || cropwindow[2] >= cropwindow[3] {
                ctx.error(
                    q.values_loc,
                    "\"cropwindow\" is empty: it covers no pixels",
                    "empty crop window",
                    None,
                );
                cropwindow = [0.0, 1.0, 0.0, 1.0];
            }
        } else {
            ctx.warn(
                q.values_loc,
                format!(
                    "\"cropwindow\" needs 4 values, found {}: ignored (as pbrt-v3)",
                    v.len()
                ),
                "expected 4 values",
            );
        }
    }
    let filename = string(p, "filename")
        .map(|(s, _)| s.to_string())
        .unwrap_or_else(|| "pbrt.exr".into());
    let scale = float(p, "scale", 1.0) as f32;
    let diagonal = float(p, "diagonal", 35.0) as f32;
    let max_sample_luminance = float(p, "maxsampleluminance", f64::INFINITY) as f32;
    if let Some((name, _)) = f {
        ctx.report_unused(p, &format!("Film \"{}\"", name.value));
    }
    FilmDesc {
        xresolution,
        yresolution,
        cropwindow,
        filename: PathBuf::from(filename),
        scale,
        max_sample_luminance,
        diagonal,
    }
}

pub fn filter(ctx: &mut Ctx, f: Ent) -> FilterDesc {
    let Some((name, p)) = f else {
        return FilterDesc::Box {
            radius: Vec2::splat(0.5),
        };
    };
    let def = match name.value.as_str() {
        "box" => 0.5,
        "gaussian" | "triangle" | "mitchell" => 2.0,
        "sinc" => 4.0,
        other => {
            p.mark_all_used();
            ctx.error(name.loc, format!("unknown filter \"{other}\" (pbrt-v3 has box, gaussian, mitchell, sinc, triangle; an unknown filter is fatal there)"), "unknown filter", None);
            return FilterDesc::Box {
                radius: Vec2::splat(0.5),
            };
        }
    };
    let mut radius = Vec2::new(
        float(p, "xwidth", def) as f32,
        float(p, "ywidth", def) as f32,
    );
    if !(radius.x > 0.0 && radius.y > 0.0 && radius.is_finite()) {
        ctx.error(
            name.loc,
            format!("filter width {} {} must be positive", radius.x, radius.y),
            "bad filter width",
            None,
        );
        radius = Vec2::splat(def as f32);
    }
    let d = match name.value.as_str() {
        "box" => FilterDesc::Box { radius },
        "gaussian" => FilterDesc::Gaussian {
            radius,
            alpha: float(p, "alpha", 2.0) as f32,
        },
        "triangle" => FilterDesc::Triangle { radius },
        "mitchell" => FilterDesc::Mitchell {
            radius,
            b: float(p, "B", 1.0 / 3.0) as f32,
            c: float(p, "C", 1.0 / 3.0) as f32,
        },
        _ => FilterDesc::LanczosSinc {
            radius,
            tau: float(p, "tau", 3.0) as f32,
        },
    };
    ctx.report_unused(p, &format!("PixelFilter \"{}\"", name.value));
    d
}

pub fn sampler(ctx: &mut Ctx, s: Ent) -> SamplerDesc {
    let Some((name, p)) = s else {
        return SamplerDesc {
            kind: SamplerKind::Halton,
            pixel_samples: 16,
            sample_pixel_center: false,
        };
    };
    let mut center = false;
    let (kind, spp) = match name.value.as_str() {
        "halton" => {
            center = boolean(p, "samplepixelcenter", false);
            (
                SamplerKind::Halton,
                checked_count(ctx, p, "pixelsamples", 16, MAX_SAMPLES, "sample count"),
            )
        }
        "random" => (
            SamplerKind::Random,
            checked_count(ctx, p, "pixelsamples", 4, MAX_SAMPLES, "sample count"),
        ),
        "sobol" => (
            SamplerKind::Sobol,
            checked_count(ctx, p, "pixelsamples", 16, MAX_SAMPLES, "sample count"),
        ),
        "02sequence" | "lowdiscrepancy" => {
            int(p, "dimensions", 4);
            (
                SamplerKind::ZeroTwoSequence,
                checked_count(ctx, p, "pixelsamples", 16, MAX_SAMPLES, "sample count"),
            )
        }
        "maxmindist" => {
            int(p, "dimensions", 4);
            (
                SamplerKind::MaxMinDist,
                checked_count(ctx, p, "pixelsamples", 16, MAX_SAMPLES, "sample count"),
            )
        }
        "stratified" => {
            let jitter = boolean(p, "jitter", true);
            let xs = checked_count(ctx, p, "xsamples", 4, MAX_SAMPLES, "sample count");
            let ys = checked_count(ctx, p, "ysamples", 4, MAX_SAMPLES, "sample count");
            int(p, "dimensions", 4);
            let total = xs as u64 * ys as u64;
            if total > MAX_SAMPLES as u64 {
                ctx.error(
                    name.loc,
                    format!(
                        "stratified sampler: xsamples × ysamples = {total} exceeds {MAX_SAMPLES}"
                    ),
                    "too many samples",
                    None,
                );
                (
                    SamplerKind::Stratified {
                        jitter,
                        xsamples: 4,
                        ysamples: 4,
                    },
                    16,
                )
            } else {
                (
                    SamplerKind::Stratified {
                        jitter,
                        xsamples: xs,
                        ysamples: ys,
                    },
                    total as u32,
                )
            }
        }
        other => {
            p.mark_all_used();
            ctx.error(name.loc, format!("unknown sampler \"{other}\" (pbrt-v3 has halton, sobol, random, stratified, 02sequence, lowdiscrepancy, maxmindist)"), "unknown sampler", None);
            (SamplerKind::Halton, 16)
        }
    };
    if matches!(
        kind,
        SamplerKind::Sobol | SamplerKind::ZeroTwoSequence | SamplerKind::MaxMinDist
    ) {
        ctx.warn(
            name.loc,
            format!(
                "sampler \"{}\" is not implemented: rendered with the halton sampler (same expected image, different noise)",
                name.value
            ),
            "rendered with halton",
        );
    }
    ctx.report_unused(p, &format!("Sampler \"{}\"", name.value));
    SamplerDesc {
        kind,
        pixel_samples: spp,
        sample_pixel_center: center,
    }
}

/// The integrator of an `Integrator` statement, read through
/// [`INTEGRATORS`](crate::render::integrators::INTEGRATORS): the kind's
/// builder checks its settings; a kind pbrs does not render is `path` with
/// the statement's `maxdepth`, with a warning.
pub fn integrator(ctx: &mut Ctx, s: Ent) -> IntegratorSettings {
    use super::kinds::{self, Family, StatementReport, Unknown};
    let family = Family {
        directive: "Integrator",
        noun: "integrator",
        table: crate::render::integrators::INTEGRATORS,
        unknown: Unknown::Error,
    };
    let Some((name, p)) = s else {
        return IntegratorSettings::default();
    };
    let Some(read) = kinds::read(ctx, &family, name, p) else {
        return IntegratorSettings::default();
    };
    let mut report = StatementReport {
        ctx,
        at: name.loc,
        params: p,
    };
    let settings = (read.kind.build)(&read.params, &mut report);
    if read.kind.unsupported().is_some() {
        p.mark_all_used();
        ctx.warn(name.loc, format!("integrator \"{}\" is not supported by pbrs: substituted by \"path\" with maxdepth {}", name.value, settings.max_depth()), "substituted by path");
    }
    kinds::report_unused(ctx, &family, &read, name, p);
    settings
}
