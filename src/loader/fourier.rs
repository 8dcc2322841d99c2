//! The reader of pbrt-v3's tabulated BSDF files (`.bsdf`, written by
//! layerlab and Mitsuba's layered-material tools), for the `fourier`
//! material's `bsdffile`.
//!
//! Layout (little-endian): a 64-byte header — `SCATFUN`, a version byte (1),
//! then 32-bit `flags`, `nMu`, `nCoeffs`, `mMax`, `nChannels`, `nBases`,
//! `nMetadataBytes`, `nParameters`, `nParameterValues`, the float `eta`,
//! two roughness floats and two unused words — then `nMu` zenith nodes,
//! `nMu²` CDF values, `nMu²` (offset, order) pairs and `nCoeffs`
//! coefficients; metadata text may follow and is ignored. pbrt-v3 reads only
//! files with flags 1 (a BSDF without harmonic extrapolation), 1 or 3
//! channels and one basis (no textured parameters); so does this reader.
//!
//! Every count is checked against the file's length before anything is
//! allocated; the structural checks are [`FourierTable::new`]'s.

use super::Ctx;
use crate::lang::Loc;
use crate::scene::{FourierTable, FourierTableData, MAX_FOURIER_ORDER};
use std::sync::Arc;

const HEADER_BYTES: u64 = 64;

/// Parses a `.bsdf` file; `source` names it in the table's `Debug` text.
/// The error says what is wrong (without the file name).
pub fn read_bsdf(bytes: &[u8], source: &str) -> Result<FourierTable, String> {
    let len = bytes.len() as u64;
    if bytes.len() < 8 || &bytes[..7] != b"SCATFUN" {
        return Err("not a tabulated BSDF file (it does not start with \"SCATFUN\")".into());
    }
    if bytes[7] != 1 {
        return Err(format!(
            "format version {}: pbrt-v3 reads version 1",
            bytes[7]
        ));
    }
    if len < HEADER_BYTES {
        return Err(format!(
            "truncated header: {HEADER_BYTES} bytes are needed, the file has {len}"
        ));
    }
    let word = |i: usize| {
        let at = 8 + 4 * i;
        [bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]
    };
    let int = |i: usize| i32::from_le_bytes(word(i));
    let (flags, n_mu, n_coeffs, m_max, n_channels, n_bases) =
        (int(0), int(1), int(2), int(3), int(4), int(5));
    let eta = f32::from_le_bytes(word(9));
    if flags != 1 {
        return Err(format!(
            "flags {flags:#x}: pbrt-v3 reads only flags 1 (a BSDF{})",
            if flags & 2 != 0 {
                "; harmonic extrapolation is not implemented"
            } else {
                ""
            }
        ));
    }
    if n_channels != 1 && n_channels != 3 {
        return Err(format!(
            "{n_channels} colour channels: pbrt-v3 reads 1 or 3"
        ));
    }
    if n_bases != 1 {
        return Err(format!(
            "{n_bases} basis functions: pbrt-v3 reads only untextured BSDFs (1 basis)"
        ));
    }
    for (what, v) in [("nMu", n_mu), ("nCoeffs", n_coeffs), ("mMax", m_max)] {
        if v < 0 {
            return Err(format!("negative count {what} {v}"));
        }
    }
    if m_max as usize > MAX_FOURIER_ORDER {
        return Err(format!(
            "maximum Fourier order (mMax) {m_max} is above pbrs's limit of {MAX_FOURIER_ORDER}"
        ));
    }
    // Where each array ends, in bytes (u128: 12·nMu² overflows u64 for
    // i32 counts; every end is checked against the file's length below).
    let n = n_mu as u128;
    let mu_end = HEADER_BYTES as u128 + 4 * n;
    let cdf_end = mu_end + 4 * n * n;
    let offsets_end = cdf_end + 8 * n * n;
    let a_end = offsets_end + 4 * n_coeffs as u128;
    for (what, end) in [
        ("zenith nodes", mu_end),
        ("CDF table", cdf_end),
        ("offset and order table", offsets_end),
        ("Fourier coefficients", a_end),
    ] {
        if end > len as u128 {
            return Err(format!(
                "truncated: the {what} end at byte {end} (nMu {n_mu}, nCoeffs {n_coeffs}), the file has {len} bytes"
            ));
        }
    }
    let floats = |from: u128, to: u128| -> Vec<f32> {
        bytes[from as usize..to as usize]
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect()
    };
    let offset_and_length = bytes[cdf_end as usize..offsets_end as usize]
        .chunks_exact(8)
        .map(|c| {
            (
                i32::from_le_bytes([c[0], c[1], c[2], c[3]]),
                i32::from_le_bytes([c[4], c[5], c[6], c[7]]),
            )
        })
        .collect();
    FourierTable::new(FourierTableData {
        source: source.to_string(),
        eta,
        m_max: m_max as usize,
        n_channels: n_channels as usize,
        mu: floats(HEADER_BYTES as u128, mu_end),
        cdf: floats(mu_end, cdf_end),
        offset_and_length,
        a: floats(offsets_end, a_end),
    })
}

/// The table of `bsdffile` `name` (resolved against the scene's directory),
/// read once per scene and shared. A file that cannot be read gets one
/// located warning, and `None`: the material then has no lobe, as pbrt-v3's
/// `FourierMaterial` when its table failed to load (it reports an error and
/// renders the surface black).
pub fn fourier_table(ctx: &mut Ctx, name: &str, loc: Loc) -> Option<Arc<FourierTable>> {
    let path = ctx.resolve(loc, name);
    if let Some(t) = ctx.fourier_tables.get(&path) {
        return t.clone();
    }
    let shown = path.display().to_string();
    let table = match ctx.loader.load(&path) {
        Err(e) => Err(format!("cannot read tabulated BSDF file \"{shown}\": {e}")),
        Ok(bytes) => {
            read_bsdf(&bytes, &shown).map_err(|e| format!("tabulated BSDF file \"{shown}\": {e}"))
        }
    };
    let table = match table {
        Ok(t) => Some(Arc::new(t)),
        Err(e) => {
            ctx.warn(
                loc,
                format!("{e}: the material does not scatter light (black, as pbrt-v3 renders it)"),
                "this file",
            );
            None
        }
    };
    ctx.fourier_tables.insert(path, table.clone());
    table
}
