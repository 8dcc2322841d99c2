//! A tabulated BSDF in pbrt-v3's Fourier representation: the data of a
//! `.bsdf` file, laid out as pbrt-v3's `FourierBSDFTable` (μ nodes, per
//! (μo, μi) pair an offset into the coefficients and a Fourier order, the
//! coefficients channel-major within a pair, the a0 terms and their CDF over
//! μi, and the reciprocals 1/k the azimuthal sampler integrates with).
//!
//! [`FourierTable::new`] is the only way to make one, and it checks every
//! invariant the evaluation relies on (sizes, offsets and orders inside the
//! coefficient array, μ non-decreasing, finite values, an order bound),
//! so that the render core can index without checks and never panics on a
//! table read from an untrusted file.

use std::fmt;

/// The largest Fourier order pbrs evaluates: the per-call coefficient
/// accumulators are fixed arrays of this size (pbrt-v3 uses `alloca` with the
/// file's `mMax`). The collection's tables use orders up to a few hundred.
pub const MAX_FOURIER_ORDER: usize = 1024;

/// The table of one `.bsdf` file (see the module documentation).
#[derive(Clone)]
pub struct FourierTable {
    source: String,
    eta: f32,
    m_max: usize,
    n_channels: usize,
    n_mu: usize,
    mu: Vec<f32>,
    m: Vec<u32>,
    a_offset: Vec<u32>,
    a: Vec<f32>,
    a0: Vec<f32>,
    cdf: Vec<f32>,
    recip: Vec<f32>,
}

/// The arrays of a `.bsdf` file as read, before checking.
pub struct FourierTableData {
    /// The file it came from (for diagnostics and `Debug`).
    pub source: String,
    pub eta: f32,
    pub m_max: usize,
    pub n_channels: usize,
    pub mu: Vec<f32>,
    /// nMu × nMu values, μo-major.
    pub cdf: Vec<f32>,
    /// Per pair (μo-major): offset into `a`, then Fourier order.
    pub offset_and_length: Vec<(i32, i32)>,
    pub a: Vec<f32>,
}

impl FourierTable {
    /// Checks the data and derives `a0` and `recip` as pbrt-v3's reader does.
    pub fn new(d: FourierTableData) -> Result<FourierTable, String> {
        let n_mu = d.mu.len();
        if n_mu < 2 {
            return Err(format!(
                "{n_mu} zenith nodes (nMu): at least 2 are needed to interpolate"
            ));
        }
        if d.n_channels != 1 && d.n_channels != 3 {
            return Err(format!(
                "{} colour channels: pbrt-v3 reads 1 (luminance) or 3 (Y, R, B)",
                d.n_channels
            ));
        }
        if d.m_max > MAX_FOURIER_ORDER {
            return Err(format!(
                "maximum Fourier order (mMax) {} is above pbrs's limit of {MAX_FOURIER_ORDER}",
                d.m_max
            ));
        }
        if !d.eta.is_finite() || d.eta <= 0.0 {
            return Err(format!(
                "relative index of refraction {} is not positive",
                d.eta
            ));
        }
        let pairs = n_mu * n_mu;
        if d.cdf.len() != pairs || d.offset_and_length.len() != pairs {
            return Err(format!(
                "{} CDF values and {} (offset, order) pairs for {n_mu} zenith nodes ({pairs} expected)",
                d.cdf.len(),
                d.offset_and_length.len()
            ));
        }
        if let Some(i) = d.mu.iter().position(|v| !v.is_finite()) {
            return Err(format!("zenith node {i} is {}", d.mu[i]));
        }
        // Real files repeat μ = 0 (the horizon between the reflection and
        // the transmission halves): the spline weights never pick such an
        // empty interval, but the last one must not be empty (μ = the last
        // node is looked up in it).
        if let Some(i) = (1..n_mu).find(|&i| d.mu[i] < d.mu[i - 1]) {
            return Err(format!(
                "zenith nodes decrease: node {} is {} after {}",
                i,
                d.mu[i],
                d.mu[i - 1]
            ));
        }
        if d.mu[n_mu - 1] == d.mu[n_mu - 2] {
            return Err(format!(
                "the last two zenith nodes are both {}",
                d.mu[n_mu - 1]
            ));
        }
        if let Some(i) = d.cdf.iter().position(|v| !v.is_finite()) {
            return Err(format!("CDF value {i} is {}", d.cdf[i]));
        }
        if let Some(i) = d.a.iter().position(|v| !v.is_finite()) {
            return Err(format!("Fourier coefficient {i} is {}", d.a[i]));
        }
        let n_coeffs = d.a.len() as u64;
        let mut m = Vec::with_capacity(pairs);
        let mut a_offset = Vec::with_capacity(pairs);
        let mut a0 = Vec::with_capacity(pairs);
        for (i, &(offset, length)) in d.offset_and_length.iter().enumerate() {
            let (o, k) = (i / n_mu, i % n_mu);
            if offset < 0 || length < 0 {
                return Err(format!(
                    "pair (μo {o}, μi {k}) has offset {offset} and order {length}: negative"
                ));
            }
            if length as usize > d.m_max {
                return Err(format!(
                    "pair (μo {o}, μi {k}) has order {length}, above the file's mMax {}",
                    d.m_max
                ));
            }
            let end = offset as u64 + length as u64 * d.n_channels as u64;
            if end > n_coeffs {
                return Err(format!(
                    "pair (μo {o}, μi {k}) has coefficients {offset}..{end}, outside the {n_coeffs} in the file"
                ));
            }
            m.push(length as u32);
            a_offset.push(offset as u32);
            a0.push(if length > 0 {
                d.a[offset as usize]
            } else {
                0.0
            });
        }
        // recip[0] is 1/0 as in pbrt-v3; the sampler only reads k ≥ 1.
        let recip = (0..d.m_max).map(|i| 1.0 / i as f32).collect();
        Ok(FourierTable {
            source: d.source,
            eta: d.eta,
            m_max: d.m_max,
            n_channels: d.n_channels,
            n_mu,
            mu: d.mu,
            m,
            a_offset,
            a: d.a,
            a0,
            cdf: d.cdf,
            recip,
        })
    }

    /// The file the table was read from.
    pub fn source(&self) -> &str {
        &self.source
    }
    /// Relative index of refraction, bottom over top (1: no refraction).
    #[inline]
    pub fn eta(&self) -> f32 {
        self.eta
    }
    /// The longest Fourier series in the file (pbrt-v3's `mMax`).
    #[inline]
    pub fn m_max(&self) -> usize {
        self.m_max
    }
    /// 1 (luminance) or 3 (luminance, red, blue).
    #[inline]
    pub fn n_channels(&self) -> usize {
        self.n_channels
    }
    #[inline]
    pub fn n_mu(&self) -> usize {
        self.n_mu
    }
    /// Zenith cosine nodes, non-decreasing (μ = 0 may appear twice).
    #[inline]
    pub fn mu(&self) -> &[f32] {
        &self.mu
    }
    /// Fourier order per (μo, μi) pair, μo-major.
    #[inline]
    pub fn m(&self) -> &[u32] {
        &self.m
    }
    #[inline]
    pub fn a_offset(&self) -> &[u32] {
        &self.a_offset
    }
    /// Every coefficient of the file.
    #[inline]
    pub fn a(&self) -> &[f32] {
        &self.a
    }
    /// The constant term of the luminance series per pair (μo-major).
    #[inline]
    pub fn a0(&self) -> &[f32] {
        &self.a0
    }
    /// Per μo row, the running integral of `a0` over μi.
    #[inline]
    pub fn cdf(&self) -> &[f32] {
        &self.cdf
    }
    /// 1/k for k < mMax.
    #[inline]
    pub fn recip(&self) -> &[f32] {
        &self.recip
    }

    /// The coefficients of pair (μo node `offset_o`, μi node `offset_i`):
    /// `n_channels` series of the returned order, one after the other
    /// (pbrt-v3's `GetAk`). Node indices must be below `n_mu`.
    #[inline]
    pub fn ak(&self, offset_i: usize, offset_o: usize) -> (&[f32], usize) {
        let pair = offset_o * self.n_mu + offset_i;
        let m = self.m[pair] as usize;
        let start = self.a_offset[pair] as usize;
        (&self.a[start..start + m * self.n_channels], m)
    }
}

/// Only the source and the sizes: materials are told apart by their `Debug`
/// text, and the tables are megabytes.
impl fmt::Debug for FourierTable {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "FourierTable {{ source: {:?}, eta: {}, m_max: {}, n_channels: {}, n_mu: {}, coefficients: {} }}",
            self.source,
            self.eta,
            self.m_max,
            self.n_channels,
            self.n_mu,
            self.a.len()
        )
    }
}

/// Cheap: the same file with the same sizes. A scene reads each file once
/// and shares the table, so equal sources are the same data.
impl PartialEq for FourierTable {
    fn eq(&self, o: &FourierTable) -> bool {
        self.source == o.source
            && self.eta.to_bits() == o.eta.to_bits()
            && self.m_max == o.m_max
            && self.n_channels == o.n_channels
            && self.n_mu == o.n_mu
            && self.a.len() == o.a.len()
    }
}
