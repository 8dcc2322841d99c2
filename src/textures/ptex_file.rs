//! A reader of Ptex files (per-face textures, Walt Disney Animation
//! Studios' format), written from the format's public description.
//!
//! Layout, little-endian: a 64-byte header (magic `Ptex`, version 1, mesh
//! type, data type, alpha channel, channel count, level count, face count,
//! the sizes of the blocks that follow), an extended header (border modes,
//! edge filter mode, large meta data and edit sizes), then the blocks in
//! order: face info (zlib: per face its resolution as two log2 bytes,
//! adjacent edges 2 bits each, flags, four adjacent face ids), constant
//! data (zlib: one pixel per face, the face's average), level info (per
//! level its data size, header size and face count), the levels' data, the
//! meta data. A level starts with a zlib block of one header per face (a
//! size in 30 bits and an encoding in 2: constant, zipped, difference-
//! zipped, tiled) followed by each face's data: a pixel (constant), or
//! channel planes zlib-compressed (8- and 16-bit integers optionally as
//! differences of consecutive values), or a tile resolution, a zlib block of
//! tile headers and each tile as a face. Level 0 holds every face at its
//! resolution; level `l` the faces whose smaller side is at least `l`
//! (sorted by it, largest first, the "reduction face ids") reduced `l`
//! times in both directions.
//!
//! Everything is read and checked when the file is opened: every count is
//! bounded before anything is allocated for it, and decompression stops at
//! the size the header promises (and at [`MAX_BYTES`] for the file in all),
//! so a malformed file is an error, never a panic or an unbounded
//! allocation. Texels are kept as `f32` in the file's scale (0–255 for
//! 8-bit data); reductions the file does not hold (anisotropic ones) are
//! made on first use as the Ptex library makes them, in the file's data
//! type, and kept.

use std::sync::OnceLock;

/// The most bytes a file may decode to (texels as `f32`, headers).
pub const MAX_BYTES: u64 = 1 << 31;
/// The largest face side, as a log2.
const MAX_RES_LOG2: i8 = 15;
const MAGIC: u32 = u32::from_le_bytes(*b"Ptex");
const HEADER_SIZE: usize = 64;
const EXT_HEADER_SIZE: usize = 40;
const FACE_INFO_SIZE: usize = 20;
const LEVEL_INFO_SIZE: usize = 16;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DataType {
    U8,
    U16,
    Half,
    F32,
}

impl DataType {
    fn size(self) -> usize {
        match self {
            DataType::U8 => 1,
            DataType::U16 | DataType::Half => 2,
            DataType::F32 => 4,
        }
    }
    /// The stored value of 1.0.
    pub fn one(self) -> f32 {
        match self {
            DataType::U8 => 255.0,
            DataType::U16 => 65535.0,
            DataType::Half | DataType::F32 => 1.0,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BorderMode {
    Clamp,
    Black,
    Periodic,
}

/// A face's resolution as log2 of its sides.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Res {
    pub ulog2: i8,
    pub vlog2: i8,
}

impl Res {
    pub fn new(ulog2: i8, vlog2: i8) -> Res {
        Res { ulog2, vlog2 }
    }
    pub fn u(self) -> i32 {
        1 << self.ulog2.clamp(0, 30)
    }
    pub fn v(self) -> i32 {
        1 << self.vlog2.clamp(0, 30)
    }
    fn texels(self) -> usize {
        (self.u() as usize) * (self.v() as usize)
    }
}

/// A face's header: resolution, neighbours and flags.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FaceInfo {
    pub res: Res,
    adjedges: u8,
    flags: u8,
    pub adjfaces: [i32; 4],
}

impl FaceInfo {
    /// What the Ptex library answers for a face id out of range.
    pub const NONE: FaceInfo = FaceInfo {
        res: Res { ulog2: 0, vlog2: 0 },
        adjedges: 0,
        flags: 0,
        adjfaces: [-1; 4],
    };
    pub fn adjface(&self, e: usize) -> i32 {
        self.adjfaces[e & 3]
    }
    pub fn adjedge(&self, e: usize) -> usize {
        ((self.adjedges >> (2 * (e & 3))) & 3) as usize
    }
    pub fn is_constant(&self) -> bool {
        self.flags & 1 != 0
    }
    pub fn is_neighborhood_constant(&self) -> bool {
        self.flags & 4 != 0
    }
    pub fn is_subface(&self) -> bool {
        self.flags & 8 != 0
    }
}

/// A face's texels at one resolution: one pixel, or `u × v` pixels row by
/// row (v rows of u), channels interleaved.
#[derive(Debug, Clone)]
pub enum FaceData {
    Constant(Vec<f32>),
    Packed { res: Res, texels: Vec<f32> },
}

/// A face's texels at every resolution up to its own (index
/// `ulog2 · (V + 1) + vlog2`), set when read or on first use.
#[derive(Debug, Default)]
struct FaceLevels {
    levels: Vec<OnceLock<FaceData>>,
}

/// An open Ptex file.
#[derive(Debug)]
pub struct PtexFile {
    pub triangles: bool,
    pub data_type: DataType,
    pub nchannels: usize,
    pub alpha_channel: i32,
    pub u_border: BorderMode,
    pub v_border: BorderMode,
    /// Tangent-vector edge filtering (channels 0 and 1 rotate with faces).
    pub tanvec: bool,
    pub faces: Vec<FaceInfo>,
    /// One pixel per face.
    constant: Vec<f32>,
    levels: Vec<FaceLevels>,
}

/// Reads little-endian values from a byte slice, every read checked.
struct Cursor<'a> {
    b: &'a [u8],
    pos: usize,
}

impl<'a> Cursor<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        let end = self.pos.checked_add(n).filter(|&e| e <= self.b.len());
        match end {
            Some(e) => {
                let s = &self.b[self.pos..e];
                self.pos = e;
                Ok(s)
            }
            None => Err(format!(
                "the file ends early ({} bytes, {n} more wanted at byte {})",
                self.b.len(),
                self.pos
            )),
        }
    }
    fn u16(&mut self) -> Result<u16, String> {
        Ok(u16::from_le_bytes(self.take(2)?.try_into().unwrap()))
    }
    fn u32(&mut self) -> Result<u32, String> {
        Ok(u32::from_le_bytes(self.take(4)?.try_into().unwrap()))
    }
    fn u64(&mut self) -> Result<u64, String> {
        Ok(u64::from_le_bytes(self.take(8)?.try_into().unwrap()))
    }
}

/// Keeps the total decoded size under [`MAX_BYTES`].
struct Budget(u64);

impl Budget {
    fn spend(&mut self, bytes: u64, what: &str) -> Result<(), String> {
        match self.0.checked_add(bytes).filter(|&t| t <= MAX_BYTES) {
            Some(t) => {
                self.0 = t;
                Ok(())
            }
            None => Err(format!(
                "{what} would take the file past {} MB decoded",
                MAX_BYTES >> 20
            )),
        }
    }
}

/// A zlib block of `zipped` bytes at the cursor that must inflate to
/// exactly `size` bytes.
fn unzip(
    c: &mut Cursor,
    zipped: u64,
    size: u64,
    b: &mut Budget,
    what: &str,
) -> Result<Vec<u8>, String> {
    b.spend(size, what)?;
    let zipped = usize::try_from(zipped).map_err(|_| format!("{what}: size out of range"))?;
    let data = c.take(zipped)?;
    let out = miniz_oxide::inflate::decompress_to_vec_zlib_with_limit(data, size as usize)
        .map_err(|e| format!("{what}: corrupt compressed data ({:?})", e.status))?;
    if out.len() as u64 != size {
        return Err(format!(
            "{what}: {} bytes decompressed where {size} are expected",
            out.len()
        ));
    }
    Ok(out)
}

/// pbrt's and the Ptex library's half to float.
pub fn half_to_f32(h: u16) -> f32 {
    let s = ((h as u32) & 0x8000) << 16;
    let e = ((h >> 10) & 0x1f) as u32;
    let m = (h & 0x3ff) as u32;
    let bits = if e == 0 {
        if m == 0 {
            s
        } else {
            // Subnormal: m · 2^-24.
            return f32::from_bits(s)
                + (if s != 0 { -1.0 } else { 1.0 }) * m as f32 * (1.0 / 16_777_216.0);
        }
    } else if e == 31 {
        s | 0x7f80_0000 | (m << 13)
    } else {
        s | ((e + 112) << 23) | (m << 13)
    };
    f32::from_bits(bits)
}

/// The Ptex library's float to half: mantissa rounded half up, subnormals
/// rounded to nearest, overflow to infinity.
pub fn f32_to_half(v: f32) -> u16 {
    if v == 0.0 {
        return 0;
    }
    let i = v.to_bits();
    let s = ((i >> 16) & 0x8000) as u16;
    let e = ((i >> 23) & 0xff) as i32 - 127 + 15;
    if (1..31).contains(&e) {
        let h = ((e as u32) << 10) + (((i & 0x7f_ffff) + 0x1000) >> 13);
        return s | h as u16;
    }
    if e <= 0 {
        return s | (v.abs() * 1.677_721_6e7 + 0.5) as u16;
    }
    if (i >> 23) & 0xff == 0xff {
        s | 0x7c00 | ((i & 0x7f_ffff) >> 13) as u16
    } else {
        s | 0x7c00
    }
}

/// Decodes `n` values of type `dt` from little-endian bytes.
fn values(bytes: &[u8], dt: DataType) -> Vec<f32> {
    match dt {
        DataType::U8 => bytes.iter().map(|&v| v as f32).collect(),
        DataType::U16 => bytes
            .chunks_exact(2)
            .map(|c| u16::from_le_bytes([c[0], c[1]]) as f32)
            .collect(),
        DataType::Half => bytes
            .chunks_exact(2)
            .map(|c| half_to_f32(u16::from_le_bytes([c[0], c[1]])))
            .collect(),
        DataType::F32 => bytes
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect(),
    }
}

/// The file's header fields this reader uses.
struct Header {
    meshtype: u32,
    datatype: DataType,
    alphachan: i32,
    nchannels: usize,
    nlevels: usize,
    nfaces: usize,
    extheadersize: u64,
    faceinfosize: u64,
    constdatasize: u64,
    levelinfosize: u64,
    leveldatasize: u64,
}

fn header(c: &mut Cursor) -> Result<Header, String> {
    if c.b.len() < HEADER_SIZE {
        return Err(format!(
            "not a Ptex file ({} bytes, shorter than a header)",
            c.b.len()
        ));
    }
    if c.u32()? != MAGIC {
        return Err("not a Ptex file (no \"Ptex\" magic number)".into());
    }
    let version = c.u32()?;
    if version != 1 {
        return Err(format!("unsupported Ptex file version ({version})"));
    }
    let meshtype = c.u32()?;
    let datatype = match c.u32()? {
        0 => DataType::U8,
        1 => DataType::U16,
        2 => DataType::Half,
        3 => DataType::F32,
        d => return Err(format!("unknown data type {d}")),
    };
    let alphachan = c.u32()? as i32;
    let nchannels = c.u16()? as usize;
    let nlevels = c.u16()? as usize;
    let nfaces = c.u32()? as usize;
    let h = Header {
        meshtype,
        datatype,
        alphachan,
        nchannels,
        nlevels,
        nfaces,
        extheadersize: c.u32()? as u64,
        faceinfosize: c.u32()? as u64,
        constdatasize: c.u32()? as u64,
        levelinfosize: c.u32()? as u64,
        leveldatasize: {
            let _minorversion = c.u32()?;
            c.u64()?
        },
    };
    if meshtype > 1 {
        return Err(format!("unknown mesh type {meshtype}"));
    }
    if !(1..=64).contains(&h.nchannels) {
        return Err(format!("{} channels (1 to 64 expected)", h.nchannels));
    }
    if h.nlevels > MAX_RES_LOG2 as usize + 1 {
        return Err(format!(
            "{} resolution levels (at most {} for faces of up to 2^{MAX_RES_LOG2} texels a side)",
            h.nlevels,
            MAX_RES_LOG2 + 1
        ));
    }
    if h.nfaces == 0 || h.nlevels == 0 {
        return Err(format!("{} faces in {} levels", h.nfaces, h.nlevels));
    }
    Ok(h)
}

fn border(m: u16) -> Result<BorderMode, String> {
    match m {
        0 => Ok(BorderMode::Clamp),
        1 => Ok(BorderMode::Black),
        2 => Ok(BorderMode::Periodic),
        _ => Err(format!("unknown border mode {m}")),
    }
}

impl PtexFile {
    /// Reads a Ptex file from its bytes.
    pub fn parse(bytes: &[u8]) -> Result<PtexFile, String> {
        let mut c = Cursor { b: bytes, pos: 0 };
        let h = header(&mut c)?;
        let mut budget = Budget(0);
        // The extended header may be shorter (older files) or longer.
        let ext_len = (h.extheadersize as usize).min(EXT_HEADER_SIZE);
        let mut ext = [0u8; EXT_HEADER_SIZE];
        c.pos = HEADER_SIZE;
        ext[..ext_len].copy_from_slice(c.take(ext_len)?);
        let mut e = Cursor { b: &ext, pos: 0 };
        let u_border = border(e.u16()?)?;
        let _pad = e.u16()?;
        let v_border = border(e.u16()?)?;
        let tanvec = e.u16()? == 1;
        c.pos = HEADER_SIZE;
        c.take(h.extheadersize as usize)?;
        let pixel = h.nchannels * h.datatype.size();

        // Face info: bounded by the decompressed size the header promises.
        let info = unzip(
            &mut c,
            h.faceinfosize,
            (h.nfaces as u64) * FACE_INFO_SIZE as u64,
            &mut budget,
            "face info",
        )?;
        let faces = face_infos(&info)?;
        let mut constant = values(
            &unzip(
                &mut c,
                h.constdatasize,
                (h.nfaces * pixel) as u64,
                &mut budget,
                "constant data",
            )?,
            h.datatype,
        );
        let premultiply = |d: &mut [f32]| {
            if h.alphachan >= 0 && (h.alphachan as usize) < h.nchannels {
                multiply_alpha(d, h.nchannels, h.alphachan as usize, h.datatype);
            }
        };
        premultiply(&mut constant);
        budget.spend((constant.len() * 4) as u64, "constant data")?;

        let mut lc = Cursor {
            b: bytes,
            pos: c.pos,
        };
        if h.levelinfosize < (h.nlevels * LEVEL_INFO_SIZE) as u64 {
            return Err(format!(
                "level info of {} bytes for {} levels",
                h.levelinfosize, h.nlevels
            ));
        }
        let mut level_info = Vec::with_capacity(h.nlevels);
        for _ in 0..h.nlevels {
            let size = lc.u64()?;
            let header_size = lc.u32()? as u64;
            let nfaces = lc.u32()? as usize;
            level_info.push((size, header_size, nfaces));
        }
        let mut pos = (c.pos as u64)
            .checked_add(h.levelinfosize)
            .ok_or("level data out of range")?;
        let level_end = pos
            .checked_add(h.leveldatasize)
            .ok_or("level data out of range")?;
        if level_end > bytes.len() as u64 {
            return Err(format!(
                "the file ends early ({} bytes; its levels end at byte {level_end})",
                bytes.len()
            ));
        }

        let file = Reading {
            dt: h.datatype,
            nchan: h.nchannels,
            alpha: (h.alphachan >= 0 && (h.alphachan as usize) < h.nchannels)
                .then_some(h.alphachan as usize),
        };
        let cells: u64 = faces
            .iter()
            .map(|f| (f.res.ulog2 as u64 + 1) * (f.res.vlog2 as u64 + 1))
            .sum();
        budget.spend(
            cells * std::mem::size_of::<OnceLock<FaceData>>() as u64,
            "the faces' resolution tables",
        )?;
        let levels: Vec<FaceLevels> = faces
            .iter()
            .map(|f| FaceLevels {
                levels: (0..((f.res.ulog2 as usize + 1) * (f.res.vlog2 as usize + 1)))
                    .map(|_| OnceLock::new())
                    .collect(),
            })
            .collect();
        // Reduction face ids: faces by their smaller side, largest first
        // (a constant face counts as 2 texels a side), stable.
        let mut by_rface: Vec<usize> = (0..h.nfaces).collect();
        let min_side = |f: &FaceInfo| {
            if f.is_constant() {
                1
            } else {
                f.res.ulog2.min(f.res.vlog2)
            }
        };
        by_rface.sort_by_key(|&i| std::cmp::Reverse(min_side(&faces[i])));
        for (l, &(size, header_size, nfaces)) in level_info.iter().enumerate() {
            let start = pos;
            pos = pos
                .checked_add(size)
                .filter(|&p| p <= level_end)
                .ok_or_else(|| format!("level {l} ({size} bytes) runs past the levels' data"))?;
            if nfaces > h.nfaces || (l == 0 && nfaces != h.nfaces) {
                return Err(format!(
                    "level {l} holds {nfaces} faces (at most {} expected)",
                    h.nfaces
                ));
            }
            read_level(
                bytes,
                (l, start as usize, pos as usize, header_size, nfaces),
                &faces,
                &by_rface,
                &file,
                &levels,
                &mut budget,
            )?;
        }
        Ok(PtexFile {
            triangles: h.meshtype == 0,
            data_type: h.datatype,
            nchannels: h.nchannels,
            alpha_channel: h.alphachan,
            u_border,
            v_border,
            tanvec,
            faces,
            constant,
            levels,
        })
    }

    pub fn face_info(&self, face: i32) -> FaceInfo {
        usize::try_from(face)
            .ok()
            .and_then(|f| self.faces.get(f).copied())
            .unwrap_or(FaceInfo::NONE)
    }

    /// The face's constant pixel (its average), `nchannels` values in the
    /// file's scale; zeros for a face out of range.
    pub fn constant_pixel(&self, face: i32) -> &[f32] {
        match usize::try_from(face).ok().filter(|&f| f < self.faces.len()) {
            Some(f) => &self.constant[f * self.nchannels..(f + 1) * self.nchannels],
            None => &ZEROS[..self.nchannels.min(ZEROS.len())],
        }
    }

    /// The face's texels at `res` (at most its own resolution), as the Ptex
    /// library's `getData`: the constant pixel for a constant face or 1×1,
    /// the file's data, or a reduction made from the next larger one.
    /// `None` for a face out of range or a resolution above the face's.
    pub fn data(&self, face: i32, res: Res) -> Option<FaceDataRef<'_>> {
        let f = usize::try_from(face)
            .ok()
            .filter(|&f| f < self.faces.len())?;
        let info = self.faces[f];
        if info.is_constant() || (res.ulog2 == 0 && res.vlog2 == 0) {
            return Some(FaceDataRef::Constant(self.constant_pixel(face)));
        }
        let (redu, redv) = (info.res.ulog2 - res.ulog2, info.res.vlog2 - res.vlog2);
        if redu < 0 || redv < 0 || res.ulog2 < 0 || res.vlog2 < 0 {
            return None;
        }
        let idx = res.ulog2 as usize * (info.res.vlog2 as usize + 1) + res.vlog2 as usize;
        let cell = &self.levels[f].levels[idx];
        let d = cell.get_or_init(|| self.reduce(face, res, redu, redv));
        Some(match d {
            FaceData::Constant(p) => FaceDataRef::Constant(p),
            FaceData::Packed { res, texels } => FaceDataRef::Packed(*res, texels),
        })
    }

    /// A reduction the file does not hold: halving the next larger
    /// resolution in u or in v (alternating for square steps, as the Ptex
    /// library does), in the file's data type.
    fn reduce(&self, face: i32, res: Res, redu: i8, redv: i8) -> FaceData {
        let blend_u = if redu == redv {
            res.ulog2 & 1 != 0
        } else {
            redu > redv
        };
        let src = if blend_u {
            Res::new(res.ulog2 + 1, res.vlog2)
        } else {
            Res::new(res.ulog2, res.vlog2 + 1)
        };
        let n = self.nchannels;
        match self.data(face, src) {
            Some(FaceDataRef::Packed(sres, t)) => {
                let (su, sv) = (sres.u() as usize, sres.v() as usize);
                let mut out = Vec::with_capacity(res.texels() * n);
                let dt = self.data_type;
                if blend_u {
                    for y in 0..sv {
                        for x in (0..su).step_by(2) {
                            for c in 0..n {
                                out.push(halve(
                                    t[(y * su + x) * n + c],
                                    t[(y * su + x + 1) * n + c],
                                    dt,
                                ));
                            }
                        }
                    }
                } else {
                    for y in (0..sv).step_by(2) {
                        for x in 0..su {
                            for c in 0..n {
                                out.push(halve(
                                    t[(y * su + x) * n + c],
                                    t[((y + 1) * su + x) * n + c],
                                    dt,
                                ));
                            }
                        }
                    }
                }
                FaceData::Packed { res, texels: out }
            }
            Some(FaceDataRef::Constant(p)) => FaceData::Constant(p.to_vec()),
            None => FaceData::Constant(vec![0.0; n]),
        }
    }
}

/// One level's face headers and faces (`at` = level, start and end in the
/// file, header size, face count), stored into `levels`.
#[allow(clippy::too_many_arguments)]
fn read_level(
    bytes: &[u8],
    at: (usize, usize, usize, u64, usize),
    faces: &[FaceInfo],
    by_rface: &[usize],
    file: &Reading,
    levels: &[FaceLevels],
    budget: &mut Budget,
) -> Result<(), String> {
    let (l, start, pos, header_size, nfaces) = at;
    let mut lc = Cursor {
        b: &bytes[..pos],
        pos: start,
    };
    let fdh = unzip(
        &mut lc,
        header_size,
        (nfaces * 4) as u64,
        budget,
        "a level's face headers",
    )?;
    for (r, hd) in fdh.chunks_exact(4).enumerate() {
        let hd = u32::from_le_bytes([hd[0], hd[1], hd[2], hd[3]]);
        let block = (hd & 0x3fff_ffff) as usize;
        let next = lc.pos.checked_add(block).ok_or("face data out of range")?;
        let face = if l == 0 { r } else { by_rface[r] };
        let f = faces[face];
        if f.is_constant() {
            lc.take(block)?;
            continue;
        }
        let (ul, vl) = (f.res.ulog2 - l as i8, f.res.vlog2 - l as i8);
        if ul < 0 || vl < 0 {
            return Err(format!(
                "level {l} holds face {face} of resolution 2^{} × 2^{}",
                f.res.ulog2, f.res.vlog2
            ));
        }
        let mut fc = Cursor {
            b: lc
                .b
                .get(..next)
                .ok_or_else(|| format!("face {face} of level {l} runs past its level's data"))?,
            pos: lc.pos,
        };
        let data = file
            .face(&mut fc, hd >> 30, block, Res::new(ul, vl), l == 0, budget)
            .map_err(|e| format!("face {face} of level {l}: {e}"))?;
        lc.pos = next;
        let idx = ul as usize * (f.res.vlog2 as usize + 1) + vl as usize;
        let _ = levels[face].levels[idx].set(data);
    }
    Ok(())
}

/// The face info block, decompressed: each face's resolution (checked),
/// adjacent edges, flags and adjacent faces.
fn face_infos(info: &[u8]) -> Result<Vec<FaceInfo>, String> {
    let mut faces = Vec::with_capacity(info.len() / FACE_INFO_SIZE);
    for (id, f) in info.chunks_exact(FACE_INFO_SIZE).enumerate() {
        let res = Res::new(f[0] as i8, f[1] as i8);
        if !(0..=MAX_RES_LOG2).contains(&res.ulog2) || !(0..=MAX_RES_LOG2).contains(&res.vlog2) {
            return Err(format!(
                "face {id} has resolution 2^{} × 2^{} (sides of 1 to 2^{MAX_RES_LOG2} expected)",
                res.ulog2, res.vlog2
            ));
        }
        let mut adjfaces = [0i32; 4];
        for (k, a) in adjfaces.iter_mut().enumerate() {
            let o = 4 + 4 * k;
            *a = i32::from_le_bytes([f[o], f[o + 1], f[o + 2], f[o + 3]]);
        }
        faces.push(FaceInfo {
            res,
            adjedges: f[2],
            flags: f[3],
            adjfaces,
        });
    }
    Ok(faces)
}

static ZEROS: [f32; 64] = [0.0; 64];

/// A face's texels at one resolution, borrowed.
#[derive(Clone, Copy, Debug)]
pub enum FaceDataRef<'a> {
    Constant(&'a [f32]),
    Packed(Res, &'a [f32]),
}

/// The mean of two values as the Ptex library's reductions take it:
/// integer halving for 8- and 16-bit data, in half precision for half.
fn halve(a: f32, b: f32, dt: DataType) -> f32 {
    match dt {
        DataType::U8 | DataType::U16 => ((a as u32 + b as u32) >> 1) as f32,
        DataType::Half => half_to_f32(f32_to_half(0.5 * (a + b))),
        DataType::F32 => 0.5 * (a + b),
    }
}

/// Colour channels multiplied by alpha (the Ptex cache's premultiplied
/// mode, which pbrt-v3 asks for): the channels before the alpha channel,
/// or those after it when it is channel 0.
fn multiply_alpha(d: &mut [f32], nchan: usize, alpha: usize, dt: DataType) {
    let scale = 1.0 / dt.one();
    for px in d.chunks_exact_mut(nchan) {
        let a = px[alpha] * scale;
        let range = if alpha == 0 { 1..nchan } else { 0..alpha };
        for v in &mut px[range] {
            *v = match dt {
                DataType::U8 | DataType::U16 => ((*v * a) as u32) as f32,
                DataType::Half => half_to_f32(f32_to_half(*v * a)),
                DataType::F32 => *v * a,
            };
        }
    }
}

/// What decoding a face needs of the header.
struct Reading {
    dt: DataType,
    nchan: usize,
    alpha: Option<usize>,
}

impl Reading {
    /// A face's data block at the cursor: `encoding` and `block` from its
    /// header, `res` its resolution at this level.
    fn face(
        &self,
        c: &mut Cursor,
        encoding: u32,
        block: usize,
        res: Res,
        level0: bool,
        b: &mut Budget,
    ) -> Result<FaceData, String> {
        let pixel = self.nchan * self.dt.size();
        let mut d = match encoding {
            0 => {
                if block != pixel {
                    return Err(format!(
                        "a constant block of {block} bytes (one pixel is {pixel})"
                    ));
                }
                FaceData::Constant(values(c.take(pixel)?, self.dt))
            }
            1 | 2 => {
                let texels = res.texels();
                b.spend((texels * self.nchan * 4) as u64, "a face's texels")?;
                let mut raw = unzip(
                    c,
                    block as u64,
                    (texels * pixel) as u64,
                    b,
                    "a face's texels",
                )?;
                if encoding == 2 {
                    undo_differences(&mut raw, self.dt);
                }
                let planes = values(&raw, self.dt);
                let mut t = vec![0.0f32; texels * self.nchan];
                for (ch, plane) in planes.chunks_exact(texels).enumerate() {
                    for (i, &v) in plane.iter().enumerate() {
                        t[i * self.nchan + ch] = v;
                    }
                }
                FaceData::Packed { res, texels: t }
            }
            _ => self.tiled(c, block, res, b)?,
        };
        if let (true, Some(a)) = (level0, self.alpha) {
            match &mut d {
                FaceData::Constant(p) => multiply_alpha(p, self.nchan, a, self.dt),
                FaceData::Packed { texels, .. } => multiply_alpha(texels, self.nchan, a, self.dt),
            }
        }
        Ok(d)
    }

    /// A tiled face: its tile resolution, the tiles' headers (zlib) and the
    /// tiles, assembled into one image.
    fn tiled(
        &self,
        c: &mut Cursor,
        block: usize,
        res: Res,
        b: &mut Budget,
    ) -> Result<FaceData, String> {
        let end = c
            .pos
            .checked_add(block)
            .filter(|&e| e <= c.b.len())
            .ok_or("a tiled face runs past its level")?;
        let tr = c.take(2)?;
        let tres = Res::new(tr[0] as i8, tr[1] as i8);
        if !(0..=res.ulog2).contains(&tres.ulog2) || !(0..=res.vlog2).contains(&tres.vlog2) {
            return Err(format!(
                "tiles of 2^{} × 2^{} in a face of 2^{} × 2^{}",
                tres.ulog2, tres.vlog2, res.ulog2, res.vlog2
            ));
        }
        let header_size = c.u32()? as u64;
        let (ntu, ntv) = ((res.u() / tres.u()) as usize, (res.v() / tres.v()) as usize);
        let ntiles = ntu * ntv;
        b.spend(
            (res.texels() * self.nchan * 4) as u64,
            "a tiled face's texels",
        )?;
        let fdh = unzip(
            c,
            header_size,
            (ntiles * 4) as u64,
            b,
            "a tiled face's tile headers",
        )?;
        let (tu, tv) = (tres.u() as usize, tres.v() as usize);
        let (fu, n) = (res.u() as usize, self.nchan);
        let mut t = vec![0.0f32; res.texels() * n];
        let mut tc = Cursor {
            b: &c.b[..end],
            pos: c.pos,
        };
        for (i, hd) in fdh.chunks_exact(4).enumerate() {
            let hd = u32::from_le_bytes([hd[0], hd[1], hd[2], hd[3]]);
            let (enc, size) = (hd >> 30, (hd & 0x3fff_ffff) as usize);
            if enc == 3 {
                return Err("a tile that is itself tiled".into());
            }
            let next = tc.pos.checked_add(size).ok_or("tile out of range")?;
            let tile = self.face(&mut tc, enc, size, tres, false, b)?;
            tc.pos = next;
            let (x0, y0) = ((i % ntu) * tu, (i / ntu) * tv);
            for y in 0..tv {
                for x in 0..tu {
                    let o = ((y0 + y) * fu + x0 + x) * n;
                    let px = match &tile {
                        FaceData::Constant(p) => &p[..],
                        FaceData::Packed { texels, .. } => {
                            &texels[(y * tu + x) * n..(y * tu + x + 1) * n]
                        }
                    };
                    t[o..o + n].copy_from_slice(px);
                }
            }
        }
        c.pos = end;
        Ok(FaceData::Packed { res, texels: t })
    }
}

/// Integer data stored as differences of consecutive values (wrapping).
fn undo_differences(raw: &mut [u8], dt: DataType) {
    match dt {
        DataType::U8 => {
            let mut prev = 0u8;
            for v in raw.iter_mut() {
                *v = v.wrapping_add(prev);
                prev = *v;
            }
        }
        DataType::U16 => {
            let mut prev = 0u16;
            for c in raw.chunks_exact_mut(2) {
                let v = u16::from_le_bytes([c[0], c[1]]).wrapping_add(prev);
                c.copy_from_slice(&v.to_le_bytes());
                prev = v;
            }
        }
        DataType::Half | DataType::F32 => {}
    }
}
