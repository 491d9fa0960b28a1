//! What the round curves made of segments ([`super::LinearCurve`], [`super::BSplineCurve`])
//! answer as shapes, written once: each segment is a primitive of the hierarchy, and, as in
//! Mitsuba, a curve has no area and no sampling, so it cannot be an area light.

use glam::Vec3;

use super::{Segments, ShapeGeometry};
use crate::geometry::interaction::SurfaceInteraction;
use crate::geometry::triangle::TriangleHit;
use crate::math::Ray;

/// A hit on one segment: the distance along the ray and the segment's parameter s in [0, 1] at
/// the point (the sweep parameter of a linear segment, the cross section's of a B-spline one).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SegmentHit {
    pub t: f32,
    pub s: f32,
}

/// The nearest hit in (0, t_max) over segments 0..count, with its segment: each segment is
/// searched by `hit_on(i, limit)` below the nearest hit found so far.
pub(super) fn nearest_hit(
    count: usize,
    t_max: f32,
    hit_on: impl Fn(usize, f32) -> Option<SegmentHit>,
) -> Option<(usize, SegmentHit)> {
    let mut best: Option<(usize, SegmentHit)> = None;
    for i in 0..count {
        let limit = best.map_or(t_max, |(_, h)| h.t);
        if let Some(hit) = hit_on(i, limit) {
            best = Some((i, hit));
        }
    }
    best
}

/// A set of round curves made of segments.
pub trait Curve {
    /// The curve's segments.
    fn segments(&self) -> Segments<'_>;

    /// The surface interaction of `ray`'s hit at distance `t` on segment `segment`, recorded as
    /// shape `index`. A structure that intersects the curve as a whole (Embree's, through
    /// [`ShapeGeometry::intersect_analytic`]) does not name the segment, so the curve finds it
    /// again where `segment` was not hit.
    fn hit_interaction(&self, ray: &Ray, segment: u32, t: f32, index: u32) -> SurfaceInteraction;

    /// Bytes of heap memory of the control points and the segments' tables.
    fn storage_bytes(&self) -> usize;
}

impl<C: Curve> ShapeGeometry for C {
    fn area(&self) -> f32 {
        0.0
    }

    /// The bounds of all segments.
    fn object_bounds(&self) -> (Vec3, Vec3) {
        let segments = self.segments();
        (0..segments.count() as u32)
            .map(|i| segments.bounds(i))
            .fold(
                (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
                |(lo, hi), (l, h)| (lo.min(l), hi.max(h)),
            )
    }

    fn as_segments(&self) -> Option<Segments<'_>> {
        Some(self.segments())
    }

    /// The nearest hit over all segments, each searched below the nearest found so far.
    fn intersect_analytic(&self, ray: &Ray, t_max: f32) -> Option<f32> {
        let segments = self.segments();
        (0..segments.count() as u32).fold(None, |best, i| {
            segments.intersect(i, ray, best.unwrap_or(t_max)).or(best)
        })
    }

    fn interaction(
        &self,
        ray: &Ray,
        segment: u32,
        hit: &TriangleHit,
        index: u32,
    ) -> SurfaceInteraction {
        self.hit_interaction(ray, segment, hit.t, index)
    }

    fn heap_bytes(&self) -> usize {
        self.storage_bytes()
    }
}
