//! Meshes from OBJ (through `tobj`) and glTF 2.0 (through `gltf`) files, for
//! the pbrs extensions `Shape "objmesh"` and `Shape "gltfmesh"`.
//!
//! Both give one [`MeshData`] in the file's own coordinates (the CTM applies
//! on top, as for `plymesh`):
//! - OBJ: every model of the file, polygons triangulated as fans (a quad is
//!   (0,1,2),(0,2,3) as in `plymesh`), positions, normals and uvs when every
//!   model has them. Materials (`.mtl`) are not read.
//! - glTF: every triangle primitive of every mesh reachable from the default
//!   scene (or the first scene), under its node's transform; `POSITION`,
//!   `NORMAL` and `TEXCOORD_0`. Buffers are the `.glb` blob, files next to the
//!   `.gltf`, or base64 `data:` URIs.
//!
//! Errors are plain messages; the caller locates them at the `filename`.

use crate::scene::MeshData;
use glam::{DMat3, DMat4, Vec2, Vec3};
use std::path::Path;

/// Reads an OBJ file's bytes.
pub fn read_obj(bytes: &[u8]) -> Result<MeshData, String> {
    let opts = tobj::LoadOptions {
        single_index: true,
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let mut reader = std::io::BufReader::new(bytes);
    let (models, _) =
        tobj::load_obj_buf(&mut reader, &opts, |_| Err(tobj::LoadError::OpenFileFailed))
            .map_err(|e| format!("not a valid OBJ file: {e}"))?;
    let all_normals = models
        .iter()
        .all(|m| !m.mesh.normals.is_empty() && m.mesh.normals.len() == m.mesh.positions.len());
    let all_uvs = models.iter().all(|m| {
        !m.mesh.texcoords.is_empty() && 3 * m.mesh.texcoords.len() == 2 * m.mesh.positions.len()
    });
    let mut out = MeshData::default();
    let mut normals = Vec::new();
    let mut uvs = Vec::new();
    for m in &models {
        let m = &m.mesh;
        if m.positions.len() % 3 != 0 || m.indices.len() % 3 != 0 {
            return Err("malformed OBJ data".into());
        }
        let base = out.positions.len();
        let nv = m.positions.len() / 3;
        if base + nv > u32::MAX as usize {
            return Err("more than 2^32 vertices".into());
        }
        std::sync::Arc::make_mut(&mut out.positions).extend(
            m.positions
                .chunks_exact(3)
                .map(|c| Vec3::new(c[0], c[1], c[2])),
        );
        if all_normals {
            normals.extend(
                m.normals
                    .chunks_exact(3)
                    .map(|c| Vec3::new(c[0], c[1], c[2])),
            );
        }
        if all_uvs {
            uvs.extend(m.texcoords.chunks_exact(2).map(|c| Vec2::new(c[0], c[1])));
        }
        for &i in &m.indices {
            if i as usize >= nv {
                return Err(format!(
                    "a face refers to vertex {} but the model has {nv}",
                    i as u64 + 1
                ));
            }
            std::sync::Arc::make_mut(&mut out.indices).push(base as u32 + i);
        }
    }
    if out.positions.is_empty() {
        return Err("the OBJ file has no vertices".into());
    }
    finish(out, all_normals.then_some(normals), all_uvs.then_some(uvs))
}

fn finish(
    mut out: MeshData,
    normals: Option<Vec<Vec3>>,
    uvs: Option<Vec<Vec2>>,
) -> Result<MeshData, String> {
    if out.positions.iter().any(|p| !p.is_finite()) {
        return Err("a vertex is not a finite 32-bit number".into());
    }
    // Zero or non-finite normals would poison shading: drop them all (as
    // trianglemesh does).
    out.normals = normals.filter(|n| n.iter().all(|v| v.is_finite() && *v != Vec3::ZERO));
    out.uvs = uvs.filter(|u| u.iter().all(|v| v.is_finite()));
    Ok(out)
}

/// Reads a glTF 2.0 file (`.gltf` or `.glb`); `load` reads files the glTF
/// refers to (relative to the glTF's directory).
pub fn read_gltf(
    bytes: &[u8],
    dir: &Path,
    load: &dyn Fn(&Path) -> Result<Vec<u8>, String>,
) -> Result<MeshData, String> {
    // The gltf crate's validation indexes accessors without a bounds check
    // (gltf-json 1.4.1 `primitive_validate_hook`), so those indices are checked
    // first; the rest runs under `catch_unwind` as a last guard.
    // A GLB header's length below the header's own 12 bytes underflows
    // the crate's length arithmetic.
    if let Some(len) = bytes
        .strip_prefix(b"glTF")
        .and_then(|b| b.get(4..8))
        .map(|l| u32::from_le_bytes([l[0], l[1], l[2], l[3]]))
    {
        if len < 12 {
            return Err(format!(
                "not a valid glTF file: its GLB header gives a length of {len} bytes, less than the 12-byte header"
            ));
        }
    }
    let gltf = gltf::Gltf::from_slice_without_validation(bytes)
        .map_err(|e| format!("not a valid glTF file: {e}"))?;
    validate(&gltf)?;
    let buffers = read_buffers(&gltf, dir, load)?;
    let scene = gltf
        .document
        .default_scene()
        .or_else(|| gltf.document.scenes().next())
        .ok_or("the glTF file has no scene")?;
    let mut out = MeshData::default();
    let mut normals = Some(Vec::new());
    let mut uvs = Some(Vec::new());
    let mut stack: Vec<(gltf::Node, DMat4, usize)> =
        scene.nodes().map(|n| (n, DMat4::IDENTITY, 0)).collect();
    stack.reverse();
    while let Some((node, parent, depth)) = stack.pop() {
        if depth > 256 {
            return Err("the node hierarchy is deeper than 256 (a cycle?)".into());
        }
        let m = node.transform().matrix();
        let local = DMat4::from_cols_array_2d(&m.map(|c| c.map(f64::from)));
        let xf = parent * local;
        if let Some(mesh) = node.mesh() {
            for prim in mesh.primitives() {
                if prim.mode() != gltf::mesh::Mode::Triangles {
                    continue;
                }
                check_accessors(&prim, mesh.index(), &buffers)?;
                let reader = prim.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
                let read = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                    let p: Vec<[f32; 3]> = reader.read_positions()?.collect();
                    let n: Option<Vec<[f32; 3]>> = reader.read_normals().map(|i| i.collect());
                    let t: Option<Vec<[f32; 2]>> =
                        reader.read_tex_coords(0).map(|i| i.into_f32().collect());
                    let idx: Option<Vec<u32>> =
                        reader.read_indices().map(|i| i.into_u32().collect());
                    Some((p, n, t, idx))
                }))
                .map_err(|_| "a primitive's accessors do not fit their buffers".to_string())?;
                let Some((p, n, t, idx)) = read else {
                    continue;
                };
                let base = out.positions.len();
                if base + p.len() > u32::MAX as usize {
                    return Err("more than 2^32 vertices".into());
                }
                let identity = xf == DMat4::IDENTITY;
                std::sync::Arc::make_mut(&mut out.positions).extend(p.iter().map(|&v| {
                    let v = Vec3::from(v);
                    if identity {
                        v
                    } else {
                        xf.transform_point3(v.as_dvec3()).as_vec3()
                    }
                }));
                let nm = DMat3::from_mat4(xf).inverse().transpose();
                match (&mut normals, n) {
                    (Some(all), Some(n)) if n.len() == p.len() => all.extend(n.iter().map(|&v| {
                        let v = Vec3::from(v);
                        if identity {
                            v
                        } else {
                            (nm * v.as_dvec3()).as_vec3()
                        }
                    })),
                    _ => normals = None,
                }
                match (&mut uvs, t) {
                    (Some(all), Some(t)) if t.len() == p.len() => {
                        all.extend(t.iter().map(|&v| Vec2::from(v)))
                    }
                    _ => uvs = None,
                }
                let idx = idx.unwrap_or_else(|| (0..p.len() as u32).collect());
                if idx.len() % 3 != 0 {
                    return Err(format!(
                        "a triangle primitive of mesh {} has {} indices, not a multiple of 3",
                        mesh.index(),
                        idx.len()
                    ));
                }
                for i in idx {
                    if i as usize >= p.len() {
                        return Err(format!(
                            "mesh {} refers to vertex {i} but its primitive has {}",
                            mesh.index(),
                            p.len()
                        ));
                    }
                    std::sync::Arc::make_mut(&mut out.indices).push(base as u32 + i);
                }
            }
        }
        for c in node.children().collect::<Vec<_>>().into_iter().rev() {
            stack.push((c, xf, depth + 1));
        }
    }
    if out.positions.is_empty() {
        return Err("the default scene has no triangle primitives".into());
    }
    finish(out, normals, uvs)
}

/// Checks what the gltf crate's reader takes on trust: each accessor pbrs
/// reads has the component type and shape its use allows (positions and
/// normals float VEC3, texture coordinates float or normalized unsigned
/// VEC2, indices unsigned SCALAR), a buffer view, no sparse storage, and
/// every element inside its view and buffer (so a count is never larger
/// than the bytes behind it).
fn check_accessors(prim: &gltf::Primitive, mesh: usize, buffers: &[Vec<u8>]) -> Result<(), String> {
    use gltf::accessor::{DataType as D, Dimensions};
    use gltf::mesh::Semantic;
    let uses: [(&str, Option<gltf::Accessor>, &[D], Dimensions); 4] = [
        (
            "POSITION",
            prim.get(&Semantic::Positions),
            &[D::F32],
            Dimensions::Vec3,
        ),
        (
            "NORMAL",
            prim.get(&Semantic::Normals),
            &[D::F32],
            Dimensions::Vec3,
        ),
        (
            "TEXCOORD_0",
            prim.get(&Semantic::TexCoords(0)),
            &[D::F32, D::U8, D::U16],
            Dimensions::Vec2,
        ),
        (
            "indices",
            prim.indices(),
            &[D::U8, D::U16, D::U32],
            Dimensions::Scalar,
        ),
    ];
    for (what, acc, types, dims) in uses {
        let Some(a) = acc else { continue };
        let bad = |why: String| {
            Err(format!(
                "mesh {mesh}: the {what} accessor ({}) {why}",
                a.index()
            ))
        };
        if !types.contains(&a.data_type()) || a.dimensions() != dims {
            return bad(format!(
                "is {:?} {:?}, but {what} must be {dims:?} of {types:?}",
                a.dimensions(),
                a.data_type()
            ));
        }
        if a.sparse().is_some() {
            return bad("is sparse, which pbrs does not read".into());
        }
        let Some(view) = a.view() else {
            return bad("has no buffer view".into());
        };
        let buffer_len = buffers.get(view.buffer().index()).map_or(0, Vec::len);
        let view_end = view.offset().checked_add(view.length());
        if view_end.is_none_or(|e| e > buffer_len) {
            return bad(format!(
                "has a buffer view of {} bytes at {}, past its buffer's {buffer_len} bytes",
                view.length(),
                view.offset()
            ));
        }
        let size = a.size();
        let stride = view.stride().unwrap_or(size);
        if stride < size {
            return bad(format!(
                "has a buffer view stride of {stride} bytes, less than its {size}-byte elements"
            ));
        }
        if a.count() == 0 {
            return bad("has no elements".into());
        }
        let need = (a.count() as u64 - 1)
            .checked_mul(stride as u64)
            .and_then(|b| b.checked_add(a.offset() as u64))
            .and_then(|b| b.checked_add(size as u64));
        if need.is_none_or(|n| n > view.length() as u64) {
            return bad(format!(
                "claims {} elements, more than its buffer view's {} bytes hold",
                a.count(),
                view.length()
            ));
        }
    }
    Ok(())
}

/// The gltf crate's validation, after checking the accessor indices it
/// reads without a bounds check.
fn validate(gltf: &gltf::Gltf) -> Result<(), String> {
    let root = gltf.document.as_json();
    for (mi, mesh) in root.meshes.iter().enumerate() {
        for prim in &mesh.primitives {
            let accessors = prim.attributes.values().chain(prim.indices.as_ref());
            for a in accessors {
                if a.value() >= root.accessors.len() {
                    return Err(format!(
                        "mesh {mi} refers to accessor {}, but the file has {}",
                        a.value(),
                        root.accessors.len()
                    ));
                }
            }
        }
    }
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        use gltf::json::validation::Validate;
        let mut errors = Vec::new();
        root.validate(root, gltf::json::Path::new, &mut |path, e| {
            errors.push(format!("{}: {e}", path()))
        });
        errors
    }))
    .map_err(|_| "the glTF file failed validation".to_string())
    .and_then(|errors| match errors.first() {
        None => Ok(()),
        Some(e) => Err(format!("not a valid glTF file: {e}")),
    })
}

/// The file's buffers: the GLB binary chunk, base64 `data:` URIs, or files
/// read by `load` relative to `dir`.
fn read_buffers(
    gltf: &gltf::Gltf,
    dir: &Path,
    load: &dyn Fn(&Path) -> Result<Vec<u8>, String>,
) -> Result<Vec<Vec<u8>>, String> {
    let mut buffers: Vec<Vec<u8>> = Vec::new();
    for b in gltf.document.buffers() {
        let data = match b.source() {
            gltf::buffer::Source::Bin => gltf
                .blob
                .clone()
                .ok_or("a buffer refers to the GLB binary chunk, which is missing")?,
            gltf::buffer::Source::Uri(uri) => {
                if let Some(rest) = uri.strip_prefix("data:") {
                    let (_, b64) = rest
                        .split_once(";base64,")
                        .ok_or_else(|| "a data: URI that is not base64".to_string())?;
                    base64_decode(b64).ok_or("a data: URI with bad base64")?
                } else {
                    let path = dir.join(percent_decode(uri));
                    load(&path).map_err(|e| {
                        format!("cannot read glTF buffer \"{}\": {e}", path.display())
                    })?
                }
            }
        };
        if data.len() < b.length() {
            return Err(format!(
                "buffer {} has {} bytes but declares {}",
                b.index(),
                data.len(),
                b.length()
            ));
        }
        buffers.push(data);
    }
    Ok(buffers)
}

fn base64_decode(s: &str) -> Option<Vec<u8>> {
    let val = |c: u8| -> Option<u32> {
        Some(match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            _ => return None,
        } as u32)
    };
    let s: Vec<u8> = s.bytes().filter(|&c| c != b'=').collect();
    let mut out = Vec::with_capacity(s.len() / 4 * 3 + 3);
    for chunk in s.chunks(4) {
        let mut acc = 0u32;
        for (k, &c) in chunk.iter().enumerate() {
            acc |= val(c)? << (18 - 6 * k);
        }
        let n = match chunk.len() {
            4 => 3,
            3 => 2,
            2 => 1,
            _ => return None,
        };
        out.extend_from_slice(&acc.to_be_bytes()[1..1 + n]);
    }
    Some(out)
}

fn percent_decode(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' && i + 2 < b.len() && s.is_char_boundary(i + 3) {
            if let Ok(v) = u8::from_str_radix(&s[i + 1..i + 3], 16) {
                out.push(v);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn obj_quad_and_errors() {
        let m = read_obj(b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n").unwrap();
        assert_eq!(m.triangle_count(), 2);
        assert_eq!(
            [0, 1, 2, 3, 4, 5].map(|k| m.positions[m.indices[k] as usize]),
            [0, 1, 2, 0, 2, 3].map(|i| [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y][i])
        );
        assert!(read_obj(b"v 0 0 0\nf 1 2 3\n").is_err());
        assert!(read_obj(b"").is_err());
    }

    #[test]
    fn base64() {
        assert_eq!(base64_decode("aGVsbG8=").unwrap(), b"hello");
        assert_eq!(base64_decode("aGk=").unwrap(), b"hi");
        assert!(base64_decode("a").is_none());
    }
}
