use glam::IVec2;

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
