//! Lookups in a grid of voxels over the unit cube, as Dr.Jit's `Texture` (which Mitsuba 3's
//! `gridvolume` uses) does them: which voxels a point reads and with which weights, for each
//! filter (`filter_type`) and each treatment of points outside the cube (`wrap_mode`).
//!
//! Voxel (x, y, z) of a grid of resolution (r_x, r_y, r_z) covers [x, x+1)/r_x × … and its value
//! sits at its centre. Along an axis, a point at v (unit-cube coordinate) lies at
//! u = v·r − ½ in voxel-centre units: trilinear interpolation reads voxels ⌊u⌋ and ⌊u⌋ + 1 with
//! weights 1 − f and f, f = u − ⌊u⌋, and nearest lookup reads voxel ⌊v·r⌋. An index outside
//! [0, r) is brought back by the wrap mode: clamped to the border voxel, repeated (i mod r) or
//! mirrored (every other period reflected, so that the border voxel repeats).

/// How a grid is interpolated between voxel centres (Mitsuba's `filter_type`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GridFilter {
    /// Trilinear interpolation (`trilinear`, or `bilinear` as Prism also reads it).
    Trilinear,
    /// The value of the voxel containing the point.
    Nearest,
}

/// How a grid answers outside the unit cube (Mitsuba's `wrap_mode`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GridWrap {
    /// The outermost voxels extend indefinitely.
    Clamp,
    /// The grid tiles space.
    Repeat,
    /// The grid tiles space, every other copy mirrored.
    Mirror,
}

impl GridWrap {
    /// The voxel index that stands for `i` along an axis of `r` voxels.
    #[inline]
    fn index(self, i: i64, r: usize) -> usize {
        let r = r as i64;
        let index = match self {
            GridWrap::Clamp => i.clamp(0, r - 1),
            GridWrap::Repeat => i.rem_euclid(r),
            GridWrap::Mirror => {
                let period = i.div_euclid(r);
                let m = i.rem_euclid(r);
                if period % 2 == 0 { m } else { r - 1 - m }
            }
        };
        index as usize
    }
}

/// The voxel grid's shape and lookup rules.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Lattice {
    pub resolution: [usize; 3],
    pub filter: GridFilter,
    pub wrap: GridWrap,
}

impl Lattice {
    /// The index in the voxel array (x fastest, then y, then z) of voxel (x, y, z).
    #[inline]
    fn offset(&self, x: usize, y: usize, z: usize) -> usize {
        let [rx, ry, _] = self.resolution;
        (z * ry + y) * rx + x
    }

    /// Along one axis of `r` voxels at unit-cube coordinate `v`: the two voxels trilinear
    /// interpolation reads and the weight of the second.
    #[inline]
    fn axis(self, v: f32, r: usize) -> (usize, usize, f32) {
        if self.wrap == GridWrap::Clamp {
            // Clamping the position itself gives the outermost half voxels the border value.
            let x = (v * r as f32 - 0.5).clamp(0.0, (r - 1) as f32);
            let i = (x as usize).min(r.saturating_sub(2));
            return (i, (i + 1).min(r - 1), x - i as f32);
        }
        let u = v * r as f32 - 0.5;
        let floor = u.floor();
        let i = floor as i64;
        (self.wrap.index(i, r), self.wrap.index(i + 1, r), u - floor)
    }

    /// The voxel that nearest lookup reads along an axis of `r` voxels at coordinate `v`.
    #[inline]
    fn nearest(self, v: f32, r: usize) -> usize {
        if self.wrap == GridWrap::Clamp {
            return ((v * r as f32).max(0.0) as usize).min(r - 1);
        }
        self.wrap.index((v * r as f32).floor() as i64, r)
    }

    /// The grid's value at `p` (unit-cube coordinates): `voxel` gives the value stored at an
    /// index of the voxel array, `lerp(a, b, t)` blends two values (a at t = 0, b at t = 1).
    /// Trilinear interpolation blends along x, then y, then z.
    #[inline]
    pub fn interpolate<T: Copy>(
        &self,
        p: glam::Vec3,
        voxel: impl Fn(usize) -> T,
        lerp: impl Fn(T, T, f32) -> T,
    ) -> T {
        let res = self.resolution;
        match self.filter {
            GridFilter::Nearest => voxel(self.offset(
                self.nearest(p.x, res[0]),
                self.nearest(p.y, res[1]),
                self.nearest(p.z, res[2]),
            )),
            GridFilter::Trilinear => {
                let (x0, x1, fx) = self.axis(p.x, res[0]);
                let (y0, y1, fy) = self.axis(p.y, res[1]);
                let (z0, z1, fz) = self.axis(p.z, res[2]);
                let at = |x: usize, y: usize, z: usize| voxel(self.offset(x, y, z));
                let plane = |z: usize| {
                    lerp(
                        lerp(at(x0, y0, z), at(x1, y0, z), fx),
                        lerp(at(x0, y1, z), at(x1, y1, z), fx),
                        fy,
                    )
                };
                lerp(plane(z0), plane(z1), fz)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_modes_bring_indices_back_as_dr_jit_does() {
        let indices = |wrap: GridWrap| (-5..9).map(|i| wrap.index(i, 4)).collect::<Vec<_>>();
        assert_eq!(
            indices(GridWrap::Clamp),
            [0, 0, 0, 0, 0, 0, 1, 2, 3, 3, 3, 3, 3, 3]
        );
        assert_eq!(
            indices(GridWrap::Repeat),
            [3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0]
        );
        assert_eq!(
            indices(GridWrap::Mirror),
            [3, 3, 2, 1, 0, 0, 1, 2, 3, 3, 2, 1, 0, 0]
        );
    }

    /// A grid of 2 × 1 × 1 voxels holding 1 and 3, read at x.
    fn line(filter: GridFilter, wrap: GridWrap, x: f32) -> f32 {
        let lattice = Lattice {
            resolution: [2, 1, 1],
            filter,
            wrap,
        };
        let values = [1.0f32, 3.0];
        lattice.interpolate(
            glam::Vec3::new(x, 0.5, 0.5),
            |i| values[i],
            |a, b, t| a + (b - a) * t,
        )
    }

    #[test]
    fn trilinear_weights_follow_the_voxel_centres() {
        // Centres at x = 0.25 and 0.75: linear between them, by the wrap mode outside.
        for wrap in [GridWrap::Clamp, GridWrap::Repeat, GridWrap::Mirror] {
            assert_eq!(line(GridFilter::Trilinear, wrap, 0.25), 1.0);
            assert_eq!(line(GridFilter::Trilinear, wrap, 0.5), 2.0);
            assert_eq!(line(GridFilter::Trilinear, wrap, 0.625), 2.5);
        }
        assert_eq!(line(GridFilter::Trilinear, GridWrap::Clamp, 0.0), 1.0);
        assert_eq!(line(GridFilter::Trilinear, GridWrap::Clamp, 1.2), 3.0);
        // Repeat: between voxel 1 (x = −0.25) and voxel 0 (x = 0.25).
        assert_eq!(line(GridFilter::Trilinear, GridWrap::Repeat, 0.0), 2.0);
        assert_eq!(line(GridFilter::Trilinear, GridWrap::Repeat, 1.125), 1.5);
        // Mirror: the copy beyond x = 1 reads 3, 1, so x = 1 lies between two 3s.
        assert_eq!(line(GridFilter::Trilinear, GridWrap::Mirror, 1.0), 3.0);
        assert_eq!(line(GridFilter::Trilinear, GridWrap::Mirror, 1.5), 2.0);
    }

    #[test]
    fn nearest_reads_the_voxel_containing_the_point() {
        assert_eq!(line(GridFilter::Nearest, GridWrap::Clamp, 0.49), 1.0);
        assert_eq!(line(GridFilter::Nearest, GridWrap::Clamp, 0.51), 3.0);
        assert_eq!(line(GridFilter::Nearest, GridWrap::Clamp, -0.3), 1.0);
        assert_eq!(line(GridFilter::Nearest, GridWrap::Repeat, -0.3), 3.0);
        assert_eq!(line(GridFilter::Nearest, GridWrap::Mirror, -0.3), 1.0);
        assert_eq!(line(GridFilter::Nearest, GridWrap::Mirror, 1.3), 3.0);
    }
}
