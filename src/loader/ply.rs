//! A small PLY reader for `plymesh` (pbrt-v3 shapes/plymesh.cpp): ascii, binary
//! little and big endian; vertex `x y z`, optional `nx ny nz`, uv from `u v` |
//! `s t` | `texture_u texture_v` | `texture_s texture_t`; faces from
//! `vertex_indices` or `vertex_index` lists of any integer type. Quads are split
//! (0,1,2),(0,2,3); other polygons are skipped with a note.
//!
//! It never trusts a count: every element count is checked against the bytes
//! left before anything is allocated, so a corrupt header is an error, not a
//! huge allocation or a panic.

use crate::scene::MeshData;
use glam::{Vec2, Vec3};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Ascii,
    BinaryLe,
    BinaryBe,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(s: &str) -> Option<Scalar> {
        Some(match s {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }
    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }
    fn is_integer(self) -> bool {
        !matches!(self, Scalar::F32 | Scalar::F64)
    }
}

#[derive(Clone, Debug)]
struct Property {
    name: String,
    /// `Some(count type)` for a list.
    list: Option<Scalar>,
    ty: Scalar,
}

#[derive(Clone, Debug)]
struct Element {
    name: String,
    count: usize,
    props: Vec<Property>,
}

/// What reading a PLY file gave: the mesh and notes worth a warning.
#[derive(Debug)]
pub struct PlyMesh {
    pub mesh: MeshData,
    pub notes: Vec<String>,
}

struct Reader<'a> {
    data: &'a [u8],
    pos: usize,
    format: Format,
}

impl Reader<'_> {
    fn left(&self) -> usize {
        self.data.len() - self.pos
    }

    fn ascii_token(&mut self) -> Result<&str, String> {
        let d = self.data;
        while self.pos < d.len() && d[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        let start = self.pos;
        while self.pos < d.len() && !d[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        if start == self.pos {
            return Err("the file ends before all elements were read (truncated)".into());
        }
        std::str::from_utf8(&d[start..self.pos])
            .map_err(|_| "non-ASCII data in an ascii PLY body".to_string())
    }

    fn read(&mut self, ty: Scalar) -> Result<f64, String> {
        if self.format == Format::Ascii {
            let pos = self.pos;
            let t = self.ascii_token()?;
            let v: f64 = t
                .parse()
                .map_err(|_| format!("bad number `{t}` at byte {pos}"))?;
            if !v.is_finite() {
                return Err(format!("number `{t}` at byte {pos} is not finite"));
            }
            return Ok(v);
        }
        let n = ty.size();
        if self.left() < n {
            return Err("the file ends before all elements were read (truncated)".into());
        }
        let v = scalar(ty, &self.data[self.pos..], self.format == Format::BinaryLe);
        self.pos += n;
        Ok(v)
    }
}

fn parse_header(data: &[u8]) -> Result<(Format, Vec<Element>, usize), String> {
    if !data.starts_with(b"ply") {
        return Err("not a PLY file (it does not start with `ply`)".into());
    }
    let limit = data.len().min(1 << 20);
    let mut end = None;
    let mut i = 0;
    while i < limit {
        if data[i..].starts_with(b"end_header") {
            let mut j = i + b"end_header".len();
            if data.get(j) == Some(&b'\r') {
                j += 1;
            }
            if data.get(j) == Some(&b'\n') {
                end = Some((i, j + 1));
                break;
            }
        }
        i += 1;
    }
    let (hend, body) = end.ok_or("no `end_header` line in the PLY header")?;
    let header = std::str::from_utf8(&data[..hend]).map_err(|_| "the PLY header is not text")?;
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    for (n, line) in header.lines().enumerate().skip(1) {
        let w: Vec<&str> = line.split_whitespace().collect();
        let bad = || format!("bad PLY header line {}: `{}`", n + 1, line.trim());
        match w.first().copied() {
            None | Some("comment") | Some("obj_info") => {}
            Some("format") => {
                format = Some(match w.get(1).copied() {
                    Some("ascii") => Format::Ascii,
                    Some("binary_little_endian") => Format::BinaryLe,
                    Some("binary_big_endian") => Format::BinaryBe,
                    _ => return Err(bad()),
                })
            }
            Some("element") => {
                let (Some(name), Some(count)) = (w.get(1), w.get(2)) else {
                    return Err(bad());
                };
                let count: usize = count.parse().map_err(|_| bad())?;
                elements.push(Element {
                    name: name.to_string(),
                    count,
                    props: Vec::new(),
                });
            }
            Some("property") => {
                let el = elements.last_mut().ok_or_else(bad)?;
                let p = if w.get(1) == Some(&"list") {
                    let (Some(ct), Some(it), Some(name)) = (w.get(2), w.get(3), w.get(4)) else {
                        return Err(bad());
                    };
                    let ct = Scalar::parse(ct)
                        .filter(|s| s.is_integer())
                        .ok_or_else(bad)?;
                    Property {
                        name: name.to_string(),
                        list: Some(ct),
                        ty: Scalar::parse(it).ok_or_else(bad)?,
                    }
                } else {
                    let (Some(t), Some(name)) = (w.get(1), w.get(2)) else {
                        return Err(bad());
                    };
                    Property {
                        name: name.to_string(),
                        list: None,
                        ty: Scalar::parse(t).ok_or_else(bad)?,
                    }
                };
                el.props.push(p);
            }
            Some(_) => return Err(bad()),
        }
    }
    Ok((
        format.ok_or("no `format` line in the PLY header")?,
        elements,
        body,
    ))
}

/// Reads a PLY mesh from bytes.
pub fn read_ply(data: &[u8]) -> Result<PlyMesh, String> {
    let (format, elements, body) = parse_header(data)?;
    let mut r = Reader {
        data,
        pos: body,
        format,
    };
    let mut mesh = MeshData::default();
    let mut notes = Vec::new();
    let mut have_vertices = false;
    let mut skipped_polys = 0usize;
    let mut faces_seen = false;
    for el in &elements {
        // Each element occupies at least one byte per property (binary) or two
        // (ascii: a digit and a separator), so a count larger than that is corrupt.
        let min = el
            .props
            .iter()
            .map(|p| {
                if format == Format::Ascii {
                    2
                } else {
                    p.list.unwrap_or(p.ty).size()
                }
            })
            .sum::<usize>();
        if min > 0 && el.count > r.left() / min {
            return Err(format!("element `{}` claims {} entries, more than the {} bytes left can hold (truncated or corrupt file)", el.name, el.count, r.left()));
        }
        if el.name == "vertex" {
            read_vertices(&mut r, el, &mut mesh)?;
            have_vertices = true;
        } else if el.name == "face" {
            faces_seen = true;
            skipped_polys += read_faces(&mut r, el, have_vertices, &mut mesh)?;
        } else if !el.props.is_empty() {
            for _ in 0..el.count {
                for p in &el.props {
                    read_prop(&mut r, p)?;
                }
            }
        }
    }
    if !have_vertices {
        return Err("the PLY file has no vertex element".into());
    }
    if !faces_seen {
        notes.push("the PLY file has no face element: no triangles".into());
    }
    if skipped_polys > 0 {
        notes.push(format!(
            "{skipped_polys} faces with neither 3 nor 4 vertices were skipped (as pbrt-v3)"
        ));
    }
    Ok(PlyMesh { mesh, notes })
}

/// The vertex element: positions, and normals and uvs where the element has
/// them (pbrt-v3's property names).
fn read_vertices(r: &mut Reader, el: &Element, mesh: &mut MeshData) -> Result<(), String> {
    let idx = |n: &str| {
        el.props
            .iter()
            .position(|p| p.name == n && p.list.is_none())
    };
    let (Some(x), Some(y), Some(z)) = (idx("x"), idx("y"), idx("z")) else {
        return Err("the vertex element has no x, y, z properties".into());
    };
    let normal = match (idx("nx"), idx("ny"), idx("nz")) {
        (Some(a), Some(b), Some(c)) => Some([a, b, c]),
        _ => None,
    };
    let uv = [
        ("u", "v"),
        ("s", "t"),
        ("texture_u", "texture_v"),
        ("texture_s", "texture_t"),
    ]
    .iter()
    .find_map(|(a, b)| Some([idx(a)?, idx(b)?]));
    // Positions as read (f32 ×3), then the render's copy, normals and uvs.
    let per = 24 + if normal.is_some() { 24 } else { 0 } + if uv.is_some() { 16 } else { 0 };
    crate::scene::memory::check_budget(
        &format!("the mesh's {} vertices", el.count),
        (el.count as u64).saturating_mul(per),
    )?;
    let positions = std::sync::Arc::make_mut(&mut mesh.positions);
    positions.reserve(el.count);
    let mut normals = Vec::with_capacity(if normal.is_some() { el.count } else { 0 });
    let mut uvs = Vec::with_capacity(if uv.is_some() { el.count } else { 0 });
    if r.format != Format::Ascii && el.props.iter().all(|p| p.list.is_none()) {
        // Binary records of a fixed size (the common case): decoded in
        // place, without the per-scalar reader.
        let offsets: Vec<usize> = el
            .props
            .iter()
            .scan(0, |at, p| {
                let o = *at;
                *at += p.ty.size();
                Some(o)
            })
            .collect();
        let stride: usize = el.props.iter().map(|p| p.ty.size()).sum();
        let bytes = el.count * stride;
        if r.left() < bytes {
            return Err("the file ends before all elements were read (truncated)".into());
        }
        let le = r.format == Format::BinaryLe;
        let field = |rec: &[u8], k: usize| scalar(el.props[k].ty, &rec[offsets[k]..], le) as f32;
        for rec in r.data[r.pos..r.pos + bytes].chunks_exact(stride.max(1)) {
            positions.push(Vec3::new(field(rec, x), field(rec, y), field(rec, z)));
            if let Some([a, b, c]) = normal {
                normals.push(Vec3::new(field(rec, a), field(rec, b), field(rec, c)));
            }
            if let Some([a, b]) = uv {
                uvs.push(Vec2::new(field(rec, a), field(rec, b)));
            }
        }
        r.pos += bytes;
        if normal.is_some() {
            mesh.normals = Some(normals);
        }
        if uv.is_some() {
            mesh.uvs = Some(uvs);
        }
        return Ok(());
    }
    let mut vals = vec![0.0f64; el.props.len()];
    for _ in 0..el.count {
        for (k, p) in el.props.iter().enumerate() {
            vals[k] = read_prop(r, p)?.unwrap_or(0.0);
        }
        positions.push(Vec3::new(vals[x] as f32, vals[y] as f32, vals[z] as f32));
        if let Some([a, b, c]) = normal {
            normals.push(Vec3::new(vals[a] as f32, vals[b] as f32, vals[c] as f32));
        }
        if let Some([a, b]) = uv {
            uvs.push(Vec2::new(vals[a] as f32, vals[b] as f32));
        }
    }
    if normal.is_some() {
        mesh.normals = Some(normals);
    }
    if uv.is_some() {
        mesh.uvs = Some(uvs);
    }
    Ok(())
}

/// The face element: triangles, and quads split in two (as pbrt-v3); the
/// number of other polygons, skipped.
fn read_faces(
    r: &mut Reader,
    el: &Element,
    have_vertices: bool,
    mesh: &mut MeshData,
) -> Result<usize, String> {
    let mut skipped = 0;
    let li = el
        .props
        .iter()
        .position(|p| p.list.is_some() && (p.name == "vertex_indices" || p.name == "vertex_index"));
    if li.is_none() {
        return Err("the face element has no `vertex_indices` list".into());
    }
    if li.is_some_and(|i| !el.props[i].ty.is_integer()) {
        return Err("`vertex_indices` is not a list of integers".into());
    }
    let nverts = mesh.positions.len();
    let indices = std::sync::Arc::make_mut(&mut mesh.indices);
    indices.reserve(el.count.saturating_mul(3).min(r.left()));
    // pbrt-v3's `face_indices`: a Ptex face per face (both triangles of a
    // quad get it).
    let fi = el
        .props
        .iter()
        .position(|p| p.list.is_none() && p.name == "face_indices" && p.ty.is_integer());
    let mut face_indices: Vec<i32> = Vec::new();
    if r.format != Format::Ascii && el.props.len() == 1 && have_vertices {
        // Binary faces with nothing but the index list (the common case).
        let p = &el.props[0];
        let (ct, it) = (p.list.expect("the index list"), p.ty);
        let (cs, is) = (ct.size(), it.size());
        let le = r.format == Format::BinaryLe;
        for f in 0..el.count {
            if r.left() < cs {
                return Err("the file ends before all elements were read (truncated)".into());
            }
            let n = scalar(ct, &r.data[r.pos..], le);
            r.pos += cs;
            // The general path's checks and messages: more indices than
            // bytes left is a bad count, fewer bytes than they need a
            // truncated file.
            if n < 0.0 || n > r.left() as f64 {
                return Err(format!("face {f} has a bad vertex count {n}"));
            }
            if n * is as f64 > r.left() as f64 {
                return Err("the file ends before all elements were read (truncated)".into());
            }
            if n == 0.0 {
                return Err(format!("face {f} has no vertex indices"));
            }
            let n = n as usize;
            let mut poly = [0u32; 4];
            let list = &r.data[r.pos..r.pos + n * is];
            for (k, b) in list.chunks_exact(is).enumerate() {
                let v = scalar(it, b, le);
                if v < 0.0 || v >= nverts as f64 {
                    return Err(format!(
                        "face {f} has vertex index {v}, out of range (the file has {nverts} vertices)"
                    ));
                }
                if let Some(slot) = poly.get_mut(k) {
                    *slot = v as u32;
                }
            }
            r.pos += n * is;
            match n {
                3 => indices.extend_from_slice(&poly[..3]),
                4 => indices
                    .extend_from_slice(&[poly[0], poly[1], poly[2], poly[0], poly[2], poly[3]]),
                _ => skipped += 1,
            }
        }
        return Ok(skipped);
    }
    let mut face_index = 0;
    let mut poly: Vec<f64> = Vec::with_capacity(8);
    for f in 0..el.count {
        for (k, p) in el.props.iter().enumerate() {
            if Some(k) == fi {
                face_index = r.read(p.ty)?.clamp(i32::MIN as f64, i32::MAX as f64) as i32;
                continue;
            }
            if Some(k) == li {
                poly.clear();
                let n = r.read(p.list.expect("list"))?;
                if n < 0.0 || n > r.left() as f64 {
                    return Err(format!("face {f} has a bad vertex count {n}"));
                }
                if n == 0.0 {
                    return Err(format!("face {f} has no vertex indices"));
                }
                for _ in 0..n as usize {
                    poly.push(r.read(p.ty)?);
                }
            } else {
                read_prop(r, p)?;
            }
        }
        if !have_vertices {
            return Err("faces come before the vertex element".into());
        }
        for &v in &poly {
            if v < 0.0 || v >= nverts as f64 {
                return Err(format!(
                    "face {f} has vertex index {v}, out of range (the file has {nverts} vertices)"
                ));
            }
        }
        let p = |k: usize| poly[k] as u32;
        match poly.len() {
            3 => {
                indices.extend_from_slice(&[p(0), p(1), p(2)]);
                face_indices.push(face_index);
            }
            4 => {
                indices.extend_from_slice(&[p(0), p(1), p(2), p(0), p(2), p(3)]);
                face_indices.extend_from_slice(&[face_index, face_index]);
            }
            _ => skipped += 1,
        }
    }
    if fi.is_some() {
        mesh.face_indices = Some(face_indices);
    }
    Ok(skipped)
}

/// A binary scalar at the start of `b` (which holds at least its size).
#[inline(always)]
fn scalar(ty: Scalar, b: &[u8], le: bool) -> f64 {
    macro_rules! get {
        ($t:ty) => {{
            let arr: [u8; std::mem::size_of::<$t>()] = b[..std::mem::size_of::<$t>()]
                .try_into()
                .expect("size checked");
            if le {
                <$t>::from_le_bytes(arr)
            } else {
                <$t>::from_be_bytes(arr)
            }
        }};
    }
    match ty {
        Scalar::I8 => b[0] as i8 as f64,
        Scalar::U8 => b[0] as f64,
        Scalar::I16 => get!(i16) as f64,
        Scalar::U16 => get!(u16) as f64,
        Scalar::I32 => get!(i32) as f64,
        Scalar::U32 => get!(u32) as f64,
        Scalar::F32 => get!(f32) as f64,
        Scalar::F64 => get!(f64),
    }
}

/// Reads one property (a scalar, or a list whose values are discarded).
fn read_prop(r: &mut Reader, p: &Property) -> Result<Option<f64>, String> {
    match p.list {
        None => r.read(p.ty).map(Some),
        Some(ct) => {
            let n = r.read(ct)?;
            if n < 0.0 || n > r.left() as f64 {
                return Err(format!("list `{}` has a bad length {n}", p.name));
            }
            for _ in 0..n as usize {
                r.read(p.ty)?;
            }
            Ok(None)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn binary(tri: &[u32], verts: &[[f32; 3]]) -> Vec<u8> {
        let mut d = format!(
            "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n",
            verts.len()
        )
        .into_bytes();
        for v in verts {
            for c in v {
                d.extend_from_slice(&c.to_le_bytes());
            }
        }
        d.push(tri.len() as u8);
        for i in tri {
            d.extend_from_slice(&i.to_le_bytes());
        }
        d
    }

    #[test]
    fn face_indices_per_triangle() {
        let text = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 2\nproperty list uchar uint vertex_indices\nproperty int face_indices\nend_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3 7\n3 0 2 3 -2\n";
        let m = read_ply(text.as_bytes()).unwrap().mesh;
        assert_eq!(*m.indices, vec![0, 1, 2, 0, 2, 3, 0, 2, 3]);
        assert_eq!(m.face_indices, Some(vec![7, 7, -2]));
        let plain = read_ply(
            text.replace("property int face_indices\n", "")
                .replace(" 7\n", "\n")
                .replace(" -2\n", "\n")
                .as_bytes(),
        )
        .unwrap()
        .mesh;
        assert_eq!(plain.face_indices, None);
    }

    /// Binary records (decoded in place) read as the same file in ascii
    /// (read scalar by scalar): doubles, big endian, normals, uv, a quad, a
    /// pentagon skipped, a `face_indices` property (the general path).
    #[test]
    fn binary_records_match_ascii() {
        let verts = [
            [0.5f64, -1.25, 2.0, 0.0, 0.0, 1.0, 0.25, 0.75],
            [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 0.0],
            [1.0, 1.0, 3.5, 1.0, 0.0, 0.0, 1.0, 1.0],
            [0.0, 1.0, -7.0, 0.0, 0.0, -1.0, 0.0, 1.0],
            [0.1, 0.2, 0.3, 0.0, 1.0, 0.0, 0.5, 0.5],
        ];
        let faces: [&[u16]; 3] = [&[0, 1, 2, 3], &[4, 2, 1], &[0, 1, 2, 3, 4]];
        let header = |fmt: &str, extra: &str| {
            format!(
                "ply\nformat {fmt} 1.0\nelement vertex 5\nproperty double x\nproperty double y\nproperty double z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty double u\nproperty float v\nelement face 3\nproperty list uchar ushort vertex_indices\n{extra}end_header\n"
            )
        };
        let mut text = header("ascii", "");
        for v in &verts {
            let line: Vec<String> = v.iter().map(|x| x.to_string()).collect();
            text += &(line.join(" ") + "\n");
        }
        for f in faces {
            let line: Vec<String> = f.iter().map(|x| x.to_string()).collect();
            text += &format!("{} {}\n", f.len(), line.join(" "));
        }
        let ascii = read_ply(text.as_bytes()).unwrap();
        for extra in ["", "property int face_indices\n"] {
            let mut bin = header("binary_big_endian", extra).into_bytes();
            for v in &verts {
                for (k, x) in v.iter().enumerate() {
                    if k == 0 || k == 1 || k == 2 || k == 6 {
                        bin.extend_from_slice(&x.to_be_bytes());
                    } else {
                        bin.extend_from_slice(&(*x as f32).to_be_bytes());
                    }
                }
            }
            for f in faces {
                bin.push(f.len() as u8);
                for i in f {
                    bin.extend_from_slice(&i.to_be_bytes());
                }
                if !extra.is_empty() {
                    bin.extend_from_slice(&5i32.to_be_bytes());
                }
            }
            let b = read_ply(&bin).unwrap();
            assert_eq!(b.mesh.positions, ascii.mesh.positions);
            assert_eq!(b.mesh.normals, ascii.mesh.normals);
            assert_eq!(b.mesh.uvs, ascii.mesh.uvs);
            assert_eq!(*b.mesh.indices, vec![0, 1, 2, 0, 2, 3, 4, 2, 1]);
            assert_eq!(b.notes, ascii.notes);
            assert!(read_ply(&bin[..bin.len() - 1])
                .unwrap_err()
                .contains("truncated"));
        }
    }

    #[test]
    fn ascii_quad() {
        let text = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty float u\nproperty float v\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n0 0 0 0 0\n1 0 0 1 0\n1 1 0 1 1\n0 1 0 0 1\n4 0 1 2 3\n";
        let m = read_ply(text.as_bytes()).unwrap().mesh;
        assert_eq!(*m.indices, vec![0, 1, 2, 0, 2, 3]);
        assert_eq!(m.uvs.unwrap()[2], Vec2::new(1.0, 1.0));
    }

    #[test]
    fn binary_triangle_and_errors() {
        let v = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let good = binary(&[0, 1, 2], &v);
        assert_eq!(read_ply(&good).unwrap().mesh.triangle_count(), 1);
        assert!(read_ply(&binary(&[0, 1, 3], &v))
            .unwrap_err()
            .contains("out of range"));
        assert!(read_ply(&good[..good.len() - 2])
            .unwrap_err()
            .contains("truncated"));
        let huge = String::from_utf8_lossy(&good)
            .replace("element vertex 3", "element vertex 4000000000")
            .into_bytes();
        assert!(read_ply(&huge).is_err());
        assert!(read_ply(b"ply\nformat ascii 1.0\nend_header\n").is_err());
        assert!(read_ply(b"hello").is_err());
        // An element without properties and an absurd count is skipped at once.
        let at = good
            .windows(14)
            .position(|w| w == b"element face 1")
            .unwrap();
        let mut empty = good[..at].to_vec();
        empty.extend_from_slice(b"element junk 18446744073709551615\n");
        empty.extend_from_slice(&good[at..]);
        assert_eq!(read_ply(&empty).unwrap().mesh.triangle_count(), 1);
    }
}
