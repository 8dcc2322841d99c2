use glam::{IVec2, Vec3};

/// Integer 2D bounds, half-open: `min` inclusive, `max` exclusive (pbrt's Bounds2i).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Bounds2i {
    pub min: IVec2,
    pub max: IVec2,
}

impl Bounds2i {
    pub fn new(min: IVec2, max: IVec2) -> Self {
        Self { min, max }
    }
    pub fn width(&self) -> i32 {
        (self.max.x - self.min.x).max(0)
    }
    pub fn height(&self) -> i32 {
        (self.max.y - self.min.y).max(0)
    }
    pub fn area(&self) -> i64 {
        self.width() as i64 * self.height() as i64
    }
    pub fn is_empty(&self) -> bool {
        self.width() == 0 || self.height() == 0
    }
    pub fn intersect(&self, o: &Bounds2i) -> Bounds2i {
        Bounds2i::new(self.min.max(o.min), self.max.min(o.max))
    }
    pub fn contains(&self, p: IVec2) -> bool {
        p.x >= self.min.x && p.x < self.max.x && p.y >= self.min.y && p.y < self.max.y
    }
    /// Pixels in row-major order.
    pub fn iter(&self) -> impl Iterator<Item = IVec2> + '_ {
        let b = *self;
        (b.min.y..b.max.y).flat_map(move |y| (b.min.x..b.max.x).map(move |x| IVec2::new(x, y)))
    }
}

/// Axis-aligned 3D bounds (closed). Empty bounds have min > max.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds3 {
    pub min: Vec3,
    pub max: Vec3,
}

impl Default for Bounds3 {
    fn default() -> Self {
        Self::EMPTY
    }
}

impl Bounds3 {
    pub const EMPTY: Bounds3 = Bounds3 {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };
    pub fn from_point(p: Vec3) -> Self {
        Self { min: p, max: p }
    }
    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x || self.min.y > self.max.y || self.min.z > self.max.z
    }
    pub fn union_point(&self, p: Vec3) -> Self {
        Self {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }
    pub fn union(&self, b: &Bounds3) -> Self {
        Self {
            min: self.min.min(b.min),
            max: self.max.max(b.max),
        }
    }
    pub fn diagonal(&self) -> Vec3 {
        self.max - self.min
    }
    pub fn center(&self) -> Vec3 {
        0.5 * (self.min + self.max)
    }
    /// Position of `p` relative to the box: 0 at min, 1 at max per axis.
    pub fn offset(&self, p: Vec3) -> Vec3 {
        let mut o = p - self.min;
        let d = self.diagonal();
        for i in 0..3 {
            if d[i] > 0.0 {
                o[i] /= d[i];
            }
        }
        o
    }
    pub fn lerp(&self, t: Vec3) -> Vec3 {
        self.min + (self.max - self.min) * t
    }
    /// Bounding sphere (centre, radius).
    pub fn bounding_sphere(&self) -> (Vec3, f32) {
        if self.is_empty() {
            return (Vec3::ZERO, 0.0);
        }
        let c = self.center();
        (c, (self.max - c).length())
    }
}
