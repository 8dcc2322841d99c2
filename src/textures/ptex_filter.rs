//! The Ptex library's separable filter for quad-mesh Ptex files, with the
//! bicubic kernel family (pbrt-v3 asks for the B-spline, sharpness 0):
//! the kernel is built at the resolution whose texels match the filter
//! width (1/4 to 1/8 of the kernel's width), split where it crosses a
//! face's edges and applied to the neighbours across them (rotated into
//! their frame, through main-face/subface transitions) and to the faces
//! around a corner (valence 4 as such, higher valences with a symmetric
//! kernel on each, lower ones by dropping the corner's weight), or folded
//! back onto the face at a border (black borders drop it), then
//! normalised by the kernel's whole weight.

use super::ptex_file::{BorderMode, FaceDataRef, FaceInfo, PtexFile, Res};

/// Room for a kernel's weights (the library's kernels are at most 10 wide;
/// moving to a subface can double a width).
const KBUF: usize = 24;
/// The deepest chain of subface transitions followed.
const MAX_DEPTH: u32 = 8;
const E_BOTTOM: usize = 0;
const E_RIGHT: usize = 1;
const E_TOP: usize = 2;
const E_LEFT: usize = 3;

/// pbrt-v3's lookups return at most 3 channels.
pub const MAX_CHANNELS: usize = 3;

/// A separable kernel over a face's texels at `res`: weights `ku` for
/// texels `u..u + uw` and `kv` for `v..v + vw`; `rot` the rotation
/// applied so far (quarter turns).
#[derive(Clone, Copy, Debug)]
struct Kernel {
    res: Res,
    u: i32,
    v: i32,
    uw: i32,
    vw: i32,
    ku: [f32; KBUF],
    ku0: usize,
    kv: [f32; KBUF],
    kv0: usize,
    rot: i32,
}

fn sum(w: &[f32]) -> f32 {
    let mut s = 0.0;
    for &x in w {
        s += x;
    }
    s
}

impl Kernel {
    fn empty(res: Res) -> Kernel {
        Kernel {
            res,
            u: 0,
            v: 0,
            uw: 0,
            vw: 0,
            ku: [0.0; KBUF],
            ku0: 0,
            kv: [0.0; KBUF],
            kv0: 0,
            rot: 0,
        }
    }
    fn ku(&self) -> &[f32] {
        let n = (self.uw.max(0) as usize).min(KBUF - self.ku0);
        &self.ku[self.ku0..self.ku0 + n]
    }
    fn kv(&self) -> &[f32] {
        let n = (self.vw.max(0) as usize).min(KBUF - self.kv0);
        &self.kv[self.kv0..self.kv0 + n]
    }
    fn is_empty(&self) -> bool {
        self.uw <= 0 || self.vw <= 0
    }
    /// A kernel of the given extent and weights (rotation 0).
    #[allow(clippy::too_many_arguments)]
    fn with(res: Res, u: i32, v: i32, ku: &[f32], kv: &[f32]) -> Kernel {
        let mut k = Kernel::empty(res);
        k.u = u;
        k.v = v;
        k.uw = ku.len() as i32;
        k.vw = kv.len() as i32;
        k.ku[..ku.len()].copy_from_slice(ku);
        k.kv[..kv.len()].copy_from_slice(kv);
        k
    }
    /// Weights moved to the start of their buffers.
    fn compact(&mut self) {
        let (a, b) = (self.ku().len(), self.kv().len());
        self.ku.copy_within(self.ku0..self.ku0 + a, 0);
        self.kv.copy_within(self.kv0..self.kv0 + b, 0);
        self.ku0 = 0;
        self.kv0 = 0;
    }
    fn strip_zeros(&mut self) {
        while self.uw > 0 && self.ku[self.ku0] == 0.0 {
            self.ku0 += 1;
            self.u += 1;
            self.uw -= 1;
        }
        while self.uw > 0 && self.ku[self.ku0 + self.uw as usize - 1] == 0.0 {
            self.uw -= 1;
        }
        while self.vw > 0 && self.kv[self.kv0] == 0.0 {
            self.kv0 += 1;
            self.v += 1;
            self.vw -= 1;
        }
        while self.vw > 0 && self.kv[self.kv0 + self.vw as usize - 1] == 0.0 {
            self.vw -= 1;
        }
    }
    fn weight(&self) -> f32 {
        sum(self.ku()) * sum(self.kv())
    }
    /// The part left of the face folded onto its first column (dropped
    /// for a black border).
    fn merge_l(&mut self, mode: BorderMode) {
        let w = -self.u;
        if w <= 0 {
            return;
        }
        if mode != BorderMode::Black && w < self.uw {
            let s = sum(&self.ku[self.ku0..self.ku0 + w as usize]);
            self.ku[self.ku0 + w as usize] += s;
        }
        self.ku0 = (self.ku0 + w as usize).min(KBUF);
        self.uw -= w;
        self.u = 0;
    }
    fn merge_r(&mut self, mode: BorderMode) {
        let w = self.uw + self.u - self.res.u();
        if w <= 0 {
            return;
        }
        if mode != BorderMode::Black && w < self.uw {
            let p = self.ku0 + (self.uw - w) as usize;
            let s = sum(&self.ku[p..p + w as usize]);
            self.ku[p - 1] += s;
        }
        self.uw -= w;
    }
    fn merge_b(&mut self, mode: BorderMode) {
        let w = -self.v;
        if w <= 0 {
            return;
        }
        if mode != BorderMode::Black && w < self.vw {
            let s = sum(&self.kv[self.kv0..self.kv0 + w as usize]);
            self.kv[self.kv0 + w as usize] += s;
        }
        self.kv0 = (self.kv0 + w as usize).min(KBUF);
        self.vw -= w;
        self.v = 0;
    }
    fn merge_t(&mut self, mode: BorderMode) {
        let w = self.vw + self.v - self.res.v();
        if w <= 0 {
            return;
        }
        if mode != BorderMode::Black && w < self.vw {
            let p = self.kv0 + (self.vw - w) as usize;
            let s = sum(&self.kv[p..p + w as usize]);
            self.kv[p - 1] += s;
        }
        self.vw -= w;
    }
    /// Splits off the part left of the face, in the left neighbour's
    /// coordinates (before rotation).
    fn split_l(&mut self) -> Kernel {
        let w = -self.u;
        if w < self.uw {
            let k = Kernel::with(
                self.res,
                self.res.u() - w,
                self.v,
                &self.ku[self.ku0..self.ku0 + w as usize],
                self.kv(),
            );
            self.u = 0;
            self.uw -= w;
            self.ku0 += w as usize;
            k
        } else {
            let mut k = *self;
            k.u += self.res.u();
            self.u = 0;
            self.uw = 0;
            k
        }
    }
    fn split_r(&mut self) -> Kernel {
        let w = self.u + self.uw - self.res.u();
        if w < self.uw {
            let p = self.ku0 + (self.uw - w) as usize;
            let k = Kernel::with(self.res, 0, self.v, &self.ku[p..p + w as usize], self.kv());
            self.uw -= w;
            k
        } else {
            let mut k = *self;
            k.u -= self.res.u();
            self.u = 0;
            self.uw = 0;
            k
        }
    }
    fn split_b(&mut self) -> Kernel {
        let w = -self.v;
        if w < self.vw {
            let k = Kernel::with(
                self.res,
                self.u,
                self.res.v() - w,
                self.ku(),
                &self.kv[self.kv0..self.kv0 + w as usize],
            );
            self.v = 0;
            self.vw -= w;
            self.kv0 += w as usize;
            k
        } else {
            let mut k = *self;
            k.v += self.res.v();
            self.v = 0;
            self.vw = 0;
            k
        }
    }
    fn split_t(&mut self) -> Kernel {
        let w = self.v + self.vw - self.res.v();
        if w < self.vw {
            let p = self.kv0 + (self.vw - w) as usize;
            let k = Kernel::with(self.res, self.u, 0, self.ku(), &self.kv[p..p + w as usize]);
            self.vw -= w;
            k
        } else {
            let mut k = *self;
            k.v -= self.res.v();
            self.v = 0;
            self.vw = 0;
            k
        }
    }
    fn flip_u(&mut self) {
        self.u = self.res.u() - self.u - self.uw;
        let n = self.ku().len();
        self.ku[self.ku0..self.ku0 + n].reverse();
    }
    fn flip_v(&mut self) {
        self.v = self.res.v() - self.v - self.vw;
        let n = self.kv().len();
        self.kv[self.kv0..self.kv0 + n].reverse();
    }
    fn swap_uv(&mut self) {
        self.res = Res::new(self.res.vlog2, self.res.ulog2);
        std::mem::swap(&mut self.u, &mut self.v);
        std::mem::swap(&mut self.uw, &mut self.vw);
        std::mem::swap(&mut self.ku, &mut self.kv);
        std::mem::swap(&mut self.ku0, &mut self.kv0);
    }
    fn rotate(&mut self, r: i32) {
        match r & 3 {
            1 => {
                self.flip_u();
                self.swap_uv();
            }
            2 => {
                self.flip_u();
                self.flip_v();
            }
            3 => {
                self.flip_v();
                self.swap_uv();
            }
            _ => return,
        }
        self.rot = (self.rot + r) & 3;
    }
    /// Into a subface's frame across edge `eid` of a main face; true if
    /// the kernel lands on the primary subface (the one the edge names).
    fn main_to_subface(&mut self, eid: usize) -> bool {
        if self.res.ulog2 == 0 {
            self.upres_u();
        }
        if self.res.vlog2 == 0 {
            self.upres_v();
        }
        if self.res.ulog2 > 0 {
            self.res.ulog2 -= 1;
        }
        if self.res.vlog2 > 0 {
            self.res.vlog2 -= 1;
        }
        let (ru, rv) = (self.res.u(), self.res.v());
        match eid & 3 {
            E_BOTTOM => {
                let primary = self.u < ru;
                self.v -= rv;
                if !primary {
                    self.u -= ru;
                }
                primary
            }
            E_RIGHT => {
                let primary = self.v < rv;
                if !primary {
                    self.v -= rv;
                }
                primary
            }
            E_TOP => {
                let primary = self.u >= ru;
                if primary {
                    self.u -= ru;
                }
                primary
            }
            _ => {
                let primary = self.v >= rv;
                self.u -= ru;
                if primary {
                    self.v -= rv;
                }
                primary
            }
        }
    }
    fn subface_to_main(&mut self, eid: usize) {
        match eid & 3 {
            E_BOTTOM => self.v += self.res.v(),
            E_RIGHT => {}
            E_TOP => self.u += self.res.u(),
            _ => {
                self.u += self.res.u();
                self.v += self.res.v();
            }
        }
        self.res.ulog2 += 1;
        self.res.vlog2 += 1;
    }
    fn downres_u(&mut self) {
        let (mut src, mut dst) = (self.ku0, self.ku0);
        let mut uw = self.uw.max(0) as usize;
        if self.u & 1 != 0 && uw > 0 {
            src += 1;
            dst += 1;
            uw -= 1;
        }
        for _ in 0..uw / 2 {
            self.ku[dst] = self.ku[src] + self.ku[src + 1];
            dst += 1;
            src += 2;
        }
        if uw & 1 != 0 {
            self.ku[dst] = self.ku[src];
            dst += 1;
        }
        self.u /= 2;
        self.uw = (dst - self.ku0) as i32;
        self.res.ulog2 -= 1;
    }
    fn downres_v(&mut self) {
        self.swap_uv();
        self.downres_u();
        self.swap_uv();
    }
    fn upres_u(&mut self) {
        self.compact();
        let uw = (self.uw.max(0) as usize).min(KBUF / 2);
        for i in (0..uw).rev() {
            let h = self.ku[i] / 2.0;
            self.ku[2 * i] = h;
            self.ku[2 * i + 1] = h;
        }
        self.uw = 2 * uw as i32;
        self.u *= 2;
        self.res.ulog2 += 1;
    }
    fn upres_v(&mut self) {
        self.swap_uv();
        self.upres_u();
        self.swap_uv();
    }
    /// The kernel made square and symmetric for a corner of valence 5 or
    /// more (its weight returned), scaled to keep the corner's weight.
    fn make_symmetric(&mut self, initial: f32) -> f32 {
        while self.res.ulog2 > self.res.vlog2 {
            self.downres_u();
        }
        while self.res.vlog2 > self.res.ulog2 {
            self.downres_v();
        }
        self.compact();
        let n = self.uw.min(self.vw).max(0);
        self.uw = n;
        self.vw = n;
        let mut w = 0.0;
        for i in 0..n as usize {
            let s = self.ku[i] + self.kv[i];
            self.ku[i] = s;
            self.kv[i] = s;
            w += s;
        }
        w *= w;
        let scale = if w == 0.0 { 1.0 } else { initial / w };
        if scale >= 1.0 {
            return w;
        }
        if scale < -1.0 {
            for x in &mut self.ku[..n as usize] {
                *x = -*x;
            }
            -w
        } else {
            for x in &mut self.ku[..n as usize] {
                *x *= scale;
            }
            initial
        }
    }
}

/// The bicubic kernel's coefficients for a sharpness (B = 1 − sharpness,
/// C = (1 − B)/2): 0 is the B-spline.
fn coefficients(sharpness: f32) -> [f32; 7] {
    let b = 1.0 - sharpness;
    [
        1.5 - b,
        1.5 * b - 2.5,
        1.0 - (1.0f64 / 3.0) as f32 * b,
        (1.0f64 / 3.0) as f32 * b - 0.5,
        2.5 - 1.5 * b,
        2.0 * b - 4.0,
        2.0 - (2.0f64 / 3.0) as f32 * b,
    ]
}

fn cubic(x: f32, c: &[f32; 7]) -> f32 {
    let x = x.abs();
    if x < 1.0 {
        (c[0] * x + c[1]) * x * x + c[2]
    } else if x < 2.0 {
        ((c[3] * x + c[4]) * x + c[5]) * x + c[6]
    } else {
        0.0
    }
}

/// The 2-unit cubic Hermite kernel for wide filters.
fn blur(x: f32) -> f32 {
    let x = x.abs();
    if x < 1.0 {
        (2.0 * x - 3.0) * x * x + 1.0
    } else {
        0.0
    }
}

/// `ceil(log2(1/w))` from the float's exponent, as the library computes it.
fn res_from_width(w: f32) -> i32 {
    127 - ((w.to_bits() >> 23) & 0xff) as i32
}

/// One axis of the kernel: resolution log2, first texel and weights for a
/// filter of width `uw` at `u` on a face of `face_log2` texels a side.
fn build_axis(u: f32, uw: f32, face_log2: i8, c: &[f32; 7]) -> (i8, i32, Vec<f32>) {
    let uw = uw.max(f32::from_bits(((127 - face_log2 as i32) as u32) << 23));
    let log2 = res_from_width(uw);
    let (lerp1, lerp2) = (1.0f32, 0.0f32);
    if uw >= 0.25 {
        if uw < 0.5 {
            let upix = u * 4.0 - 0.5;
            let u1 = ((upix - 2.0).ceil() as i32) & !1;
            let u2 = ((upix + 2.0).ceil() as i32 + 1) & !1;
            let x1 = u1 as f32 - upix;
            let s = 1.0 / (uw + 0.75);
            let mut k = Vec::with_capacity((u2 - u1).max(0) as usize);
            let mut i = 0;
            while i < u2 - u1 {
                let xa = x1 + i as f32;
                let xb = xa + 1.0;
                let xc = (xa + xb) * 0.25;
                let kc = blur(xc * s);
                k.push(cubic(xa, c) * lerp1 + kc * lerp2);
                k.push(cubic(xb, c) * lerp1 + kc * lerp2);
                i += 2;
            }
            return (2, u1, k);
        } else if uw < 1.0 {
            let upix = u * 2.0 - 0.5;
            let ku = (u - 0.5).floor() as i32 * 2;
            let x1 = ku as f32 - upix;
            let s = 1.0 / (uw * 1.5 + 0.5);
            let mut k = Vec::with_capacity(4);
            for i in [0, 2] {
                let xa = x1 + i as f32;
                let xb = xa + 1.0;
                let xc = (xa + xb) * 0.5;
                let kc = blur(xc * s);
                k.push(blur(xa * s) * lerp1 + kc * lerp2);
                k.push(blur(xb * s) * lerp1 + kc * lerp2);
            }
            return (1, ku, k);
        } else {
            let upix = u - 0.5;
            let ui = upix.floor();
            let k0 = blur(upix - ui);
            return (0, ui as i32, vec![k0, 1.0 - k0]);
        }
    }
    let res = (1i64 << log2.clamp(0, 30)) as f32;
    let upix = u * res - 0.5;
    let uwpix = uw * res;
    let dupix = 2.0 * uwpix;
    let u1 = (upix - dupix).ceil() as i32;
    let u2 = (upix + dupix).ceil() as i32;
    let x1 = (u1 as f32 - upix) / uwpix;
    let step = 1.0 / uwpix;
    let k = (0..(u2 - u1).clamp(0, 10))
        .map(|i| cubic(x1 + i as f32 * step, c))
        .collect();
    (log2 as i8, u1, k)
}

/// A lookup's state: the texture, the running sum and weight.
struct Eval<'a> {
    tx: &'a PtexFile,
    nchan: usize,
    result: [f32; MAX_CHANNELS],
    weight: f32,
}

/// The separable bicubic filter of a Ptex file (quad meshes).
pub struct BicubicFilter {
    c: [f32; 7],
}

impl BicubicFilter {
    pub fn new(sharpness: f32) -> BicubicFilter {
        BicubicFilter {
            c: coefficients(sharpness),
        }
    }

    fn kernel(&self, u: f32, v: f32, uw: f32, vw: f32, res: Res) -> Kernel {
        let (ul, u0, ku) = build_axis(u, uw, res.ulog2, &self.c);
        let (vl, v0, kv) = build_axis(v, vw, res.vlog2, &self.c);
        Kernel::with(Res::new(ul, vl), u0, v0, &ku, &kv)
    }

    /// The filtered value of `face` at (u, v) for a footprint spanned by
    /// (du1, dv1) and (du2, dv2), in [0, 1] units (the library's `eval`
    /// with width 1 and no blur); zeros for a face out of range.
    #[allow(clippy::too_many_arguments)]
    pub fn eval(
        &self,
        tx: &PtexFile,
        face: i32,
        mut u: f32,
        mut v: f32,
        du1: f32,
        dv1: f32,
        du2: f32,
        dv2: f32,
    ) -> [f32; MAX_CHANNELS] {
        let mut out = [0.0; MAX_CHANNELS];
        let nchan = tx.nchannels.min(MAX_CHANNELS);
        if face < 0 || face as usize >= tx.faces.len() || !u.is_finite() || !v.is_finite() {
            return out;
        }
        let f = tx.faces[face as usize];
        let one = tx.data_type.one();
        if f.is_neighborhood_constant() {
            let p = tx.constant_pixel(face);
            for c in 0..nchan {
                out[c] = p[c] * (1.0 / one);
            }
            return out;
        }
        let mut uw = du1.abs() + du2.abs();
        let mut vw = dv1.abs() + dv2.abs();
        if !uw.is_finite() {
            uw = 1.0;
        }
        if !vw.is_finite() {
            vw = 1.0;
        }
        let mut black = false;
        match tx.u_border {
            BorderMode::Clamp => u = u.clamp(0.0, 1.0),
            BorderMode::Periodic => u -= u.floor(),
            BorderMode::Black => black |= u <= -1.0 || u >= 2.0,
        }
        match tx.v_border {
            BorderMode::Clamp => v = v.clamp(0.0, 1.0),
            BorderMode::Periodic => v -= v.floor(),
            BorderMode::Black => black |= v <= -1.0 || v >= 2.0,
        }
        if black {
            return out;
        }
        let mut k = if f.is_subface() {
            let mut k = self.kernel(
                u * 0.5,
                v * 0.5,
                uw * 0.5,
                vw * 0.5,
                Res::new(f.res.ulog2 + 1, f.res.vlog2 + 1),
            );
            if k.res.ulog2 == 0 {
                k.upres_u();
            }
            if k.res.vlog2 == 0 {
                k.upres_v();
            }
            k.res.ulog2 -= 1;
            k.res.vlog2 -= 1;
            k
        } else {
            self.kernel(u, v, uw, vw, f.res)
        };
        k.strip_zeros();
        if k.is_empty() {
            return out;
        }
        let mut e = Eval {
            tx,
            nchan,
            result: [0.0; MAX_CHANNELS],
            weight: k.weight(),
        };
        e.split_and_apply(k, face, f, 0);
        let scale = 1.0 / (e.weight * one);
        for (o, r) in out.iter_mut().zip(e.result).take(nchan) {
            *o = r * scale;
        }
        out
    }
}

impl Eval<'_> {
    fn info(&self, face: i32) -> FaceInfo {
        self.tx.face_info(face)
    }

    fn split_and_apply(&mut self, mut k: Kernel, face: i32, f: FaceInfo, depth: u32) {
        if depth > MAX_DEPTH {
            return;
        }
        let split_r = k.u + k.uw > k.res.u();
        let split_l = k.u < 0;
        let split_t = k.v + k.vw > k.res.v();
        let split_b = k.v < 0;
        let (um, vm) = (self.tx.u_border, self.tx.v_border);
        if split_r {
            if f.adjface(E_RIGHT) >= 0 {
                let mut ka = k.split_r();
                if split_t {
                    if f.adjface(E_TOP) >= 0 {
                        let kc = ka.split_t();
                        self.corner(kc, face, f, E_TOP, depth);
                    } else {
                        ka.merge_t(vm);
                    }
                }
                if split_b {
                    if f.adjface(E_BOTTOM) >= 0 {
                        let kc = ka.split_b();
                        self.corner(kc, face, f, E_RIGHT, depth);
                    } else {
                        ka.merge_b(vm);
                    }
                }
                self.across_edge(ka, face, f, E_RIGHT, depth);
            } else {
                k.merge_r(um);
            }
        }
        if split_l {
            if f.adjface(E_LEFT) >= 0 {
                let mut ka = k.split_l();
                if split_t {
                    if f.adjface(E_TOP) >= 0 {
                        let kc = ka.split_t();
                        self.corner(kc, face, f, E_LEFT, depth);
                    } else {
                        ka.merge_t(vm);
                    }
                }
                if split_b {
                    if f.adjface(E_BOTTOM) >= 0 {
                        let kc = ka.split_b();
                        self.corner(kc, face, f, E_BOTTOM, depth);
                    } else {
                        ka.merge_b(vm);
                    }
                }
                self.across_edge(ka, face, f, E_LEFT, depth);
            } else {
                k.merge_l(um);
            }
        }
        if split_t {
            if f.adjface(E_TOP) >= 0 {
                let ka = k.split_t();
                self.across_edge(ka, face, f, E_TOP, depth);
            } else {
                k.merge_t(vm);
            }
        }
        if split_b {
            if f.adjface(E_BOTTOM) >= 0 {
                let ka = k.split_b();
                self.across_edge(ka, face, f, E_BOTTOM, depth);
            } else {
                k.merge_b(vm);
            }
        }
        self.apply(k, face, f);
    }

    fn across_edge(&mut self, mut k: Kernel, face: i32, f: FaceInfo, eid: usize, depth: u32) {
        let mut afid = f.adjface(eid);
        let mut aeid = f.adjedge(eid);
        let mut af = self.info(afid);
        let mut rot = eid as i32 - aeid as i32 + 2;
        if f.is_subface() != af.is_subface() {
            if af.is_subface() {
                if !k.main_to_subface(eid) {
                    let neid = (aeid + 3) % 4;
                    afid = af.adjface(neid);
                    aeid = af.adjedge(neid);
                    af = self.info(afid);
                    rot += neid as i32 - aeid as i32 + 2;
                }
            } else {
                let primary = af.adjface(aeid) == face;
                k.subface_to_main((eid + 4 - primary as usize) % 4);
            }
        }
        k.rotate(rot);
        if af.is_subface() {
            self.split_and_apply(k, afid, af, depth + 1);
        } else {
            self.apply(k, afid, af);
        }
    }

    fn corner(&mut self, mut k: Kernel, face: i32, f: FaceInfo, eid: usize, depth: u32) {
        const MAX_VALENCE: usize = 10;
        let (mut afid, mut aeid, mut af) = (face, eid, f);
        let mut prev_sub = af.is_subface();
        let mut cfaces = [(0i32, 0usize, FaceInfo::NONE); MAX_VALENCE];
        let mut ncorners = 0i32;
        for (i, slot) in cfaces.iter_mut().enumerate() {
            let prev = afid;
            afid = af.adjface(aeid);
            aeid = (af.adjedge(aeid) + 1) % 4;
            if afid < 0 || (afid == face && aeid == eid) {
                ncorners = i as i32 - 2;
                break;
            }
            af = self.info(afid);
            *slot = (afid, aeid, af);
            let sub = af.is_subface();
            if prev_sub && !sub && af.adjface((aeid + 3) % 4) == prev {
                let primary = i == 1;
                k.subface_to_main(eid + 2 * primary as usize);
                k.rotate(eid as i32 - aeid as i32 + 3 - primary as i32);
                self.split_and_apply(k, afid, af, depth + 1);
                return;
            }
            prev_sub = sub;
        }
        if ncorners == 1 {
            let (cf, ce, ci) = cfaces[1];
            self.corner_face(k, f, eid, cf, ci, ce, depth);
        } else if ncorners > 1 {
            k.rotate(eid as i32 + 2);
            let initial = k.weight();
            let new_weight = k.make_symmetric(initial);
            for &(cf, ce, ci) in &cfaces[1..=(ncorners as usize).min(MAX_VALENCE - 1)] {
                self.corner_face(k, f, 2, cf, ci, ce, depth);
            }
            self.weight += new_weight * ncorners as f32 - initial;
        } else {
            self.weight -= k.weight();
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn corner_face(
        &mut self,
        mut k: Kernel,
        f: FaceInfo,
        eid: usize,
        cfid: i32,
        cf: FaceInfo,
        ceid: usize,
        depth: u32,
    ) {
        if f.is_subface() != cf.is_subface() {
            if cf.is_subface() {
                k.main_to_subface(eid + 3);
            } else {
                k.subface_to_main(eid + 3);
            }
        }
        k.rotate(eid as i32 - ceid as i32 + 2);
        if cf.is_subface() {
            self.split_and_apply(k, cfid, cf, depth + 1);
        } else {
            self.apply(k, cfid, cf);
        }
    }

    /// The kernel applied to a face's texels (at a lower resolution when
    /// the face has fewer texels than the kernel's).
    fn apply(&mut self, mut k: Kernel, face: i32, f: FaceInfo) {
        if k.is_empty() {
            return;
        }
        if k.u < 0 || k.v < 0 || k.u + k.uw > k.res.u() || k.v + k.vw > k.res.v() {
            return;
        }
        while k.res.ulog2 > f.res.ulog2 {
            k.downres_u();
        }
        while k.res.vlog2 > f.res.vlog2 {
            k.downres_v();
        }
        let n = self.nchan;
        let nt = self.tx.nchannels;
        let tanvec = self.tx.tanvec && n >= 2 && k.rot > 0;
        let mut r = [0.0f32; MAX_CHANNELS];
        match self.tx.data(face, k.res) {
            None => return,
            Some(FaceDataRef::Constant(p)) => {
                let w = k.weight();
                let acc = if tanvec { &mut r } else { &mut self.result };
                for c in 0..n {
                    acc[c] += p[c] * w;
                }
            }
            Some(FaceDataRef::Packed(res, t)) => {
                if res != k.res {
                    return;
                }
                let ru = res.u() as usize;
                let acc = if tanvec { &mut r } else { &mut self.result };
                for (j, &wv) in k.kv().iter().enumerate() {
                    let mut row = [0.0f32; MAX_CHANNELS];
                    let base = (k.v as usize + j) * ru + k.u as usize;
                    for (i, &wu) in k.ku().iter().enumerate() {
                        let p = &t[(base + i) * nt..(base + i) * nt + n];
                        for c in 0..n {
                            if i == 0 {
                                row[c] = p[c] * wu;
                            } else {
                                row[c] += p[c] * wu;
                            }
                        }
                    }
                    for c in 0..n {
                        acc[c] += row[c] * wv;
                    }
                }
            }
        }
        if tanvec {
            let s = &mut self.result;
            match k.rot {
                1 => {
                    s[0] -= r[1];
                    s[1] += r[0];
                }
                2 => {
                    s[0] -= r[0];
                    s[1] -= r[1];
                }
                _ => {
                    s[0] += r[1];
                    s[1] -= r[0];
                }
            }
            for c in 2..n {
                s[c] += r[c];
            }
        }
    }
}
