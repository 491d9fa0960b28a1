//! Rays.

use glam::Vec3;

/// A ray o + t·d for t in (0, t_max), at a moment `time` of the shutter interval (which decides
/// where moving shapes are). `d` is not required to be normalised: shadow rays between two
/// points use the difference vector and t_max slightly below 1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub o: Vec3,
    pub d: Vec3,
    pub t_max: f32,
    pub time: f32,
}

impl Ray {
    pub fn new(o: Vec3, d: Vec3, t_max: f32, time: f32) -> Ray {
        Ray { o, d, t_max, time }
    }

    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.o + self.d * t
    }
}
