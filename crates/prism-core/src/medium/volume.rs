//! Volumes: quantities that vary through space, read by heterogeneous media (Mitsuba 3's
//! `constvolume` and `gridvolume`), and Mitsuba's binary `.vol` grid format.

use glam::Vec3;

use crate::math::{Ray, Transform};
use crate::spectrum::{SampledSpectrum, SampledWavelengths, Spectrum};

/// A quantity over space.
#[derive(Clone, Debug)]
pub enum Volume {
    /// The same spectrum everywhere (`constvolume`, or a plain value given for a volume).
    Constant(Spectrum),
    /// A grid of numbers over a box (`gridvolume`), boxed to keep media small.
    Grid(Box<GridVolume>),
}

impl Volume {
    /// The value at `p` (world space) for the wavelengths `lambda`.
    #[inline]
    pub fn eval(&self, p: Vec3, lambda: &SampledWavelengths) -> SampledSpectrum {
        match self {
            Volume::Constant(spectrum) => spectrum.sample(lambda),
            Volume::Grid(grid) => SampledSpectrum::splat(grid.eval(p)),
        }
    }

    /// The largest value the volume takes at any point and wavelength.
    pub fn max_value(&self) -> f32 {
        match self {
            Volume::Constant(spectrum) => spectrum.max_value(),
            Volume::Grid(grid) => grid.max_value,
        }
    }

    /// The parameter interval of `ray` (unit direction) inside the volume's box, clipped to
    /// [0, t_max]; a constant volume fills all space.
    #[inline]
    pub fn ray_extent(&self, ray: &Ray, t_max: f32) -> Option<(f32, f32)> {
        match self {
            Volume::Constant(_) => Some((0.0, t_max)),
            Volume::Grid(grid) => grid.ray_extent(ray, t_max),
        }
    }
}

/// How a grid is interpolated between voxel centres (Mitsuba's `filter_type`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GridFilter {
    /// Trilinear interpolation (Mitsuba calls it `bilinear`).
    Trilinear,
    /// The value of the voxel containing the point.
    Nearest,
}

/// A single-channel grid of `resolution` voxels over the unit cube, placed in the world by
/// `to_world`. Voxel (x, y, z) covers [x, x+1)/res_x × … and its value sits at its centre;
/// lookups clamp to the outermost voxels (Mitsuba's default `wrap_mode`, `clamp`).
#[derive(Clone)]
pub struct GridVolume {
    resolution: [usize; 3],
    /// Values with x varying fastest, then y, then z.
    data: Vec<f32>,
    to_world: Transform,
    filter: GridFilter,
    max_value: f32,
}

impl std::fmt::Debug for GridVolume {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GridVolume")
            .field("resolution", &self.resolution)
            .field("filter", &self.filter)
            .field("max_value", &self.max_value)
            .finish()
    }
}

impl GridVolume {
    /// A grid from its values (x fastest); None when `data` does not hold
    /// res_x · res_y · res_z finite values.
    pub fn new(
        resolution: [usize; 3],
        data: Vec<f32>,
        to_world: Transform,
        filter: GridFilter,
    ) -> Option<GridVolume> {
        let count = resolution
            .iter()
            .try_fold(1usize, |n, &r| if r == 0 { None } else { n.checked_mul(r) })?;
        if data.len() != count || !data.iter().all(|v| v.is_finite()) {
            return None;
        }
        let max_value = data.iter().copied().fold(f32::MIN, f32::max);
        Some(GridVolume {
            resolution,
            data,
            to_world,
            filter,
            max_value,
        })
    }

    #[inline]
    fn voxel(&self, x: usize, y: usize, z: usize) -> f32 {
        let [rx, ry, _] = self.resolution;
        self.data[(z * ry + y) * rx + x]
    }

    /// The value at `p` (world space).
    #[inline]
    pub fn eval(&self, p: Vec3) -> f32 {
        let local = self.to_world.inverse_point(p);
        self.eval_local(local)
    }

    /// The value at `p` in the unit cube's coordinates.
    pub fn eval_local(&self, p: Vec3) -> f32 {
        let res = self.resolution;
        let clamp_index = |v: f32, r: usize| (v.max(0.0) as usize).min(r - 1);
        match self.filter {
            GridFilter::Nearest => self.voxel(
                clamp_index(p.x * res[0] as f32, res[0]),
                clamp_index(p.y * res[1] as f32, res[1]),
                clamp_index(p.z * res[2] as f32, res[2]),
            ),
            GridFilter::Trilinear => {
                // Positions in voxel-centre units, clamped so that the outermost half voxels
                // take the border values.
                let axis = |v: f32, r: usize| {
                    let x = (v * r as f32 - 0.5).clamp(0.0, (r - 1) as f32);
                    let i = (x as usize).min(r.saturating_sub(2));
                    let f = x - i as f32;
                    (i, (i + 1).min(r - 1), f)
                };
                let (x0, x1, fx) = axis(p.x, res[0]);
                let (y0, y1, fy) = axis(p.y, res[1]);
                let (z0, z1, fz) = axis(p.z, res[2]);
                let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
                let plane = |z: usize| {
                    lerp(
                        lerp(self.voxel(x0, y0, z), self.voxel(x1, y0, z), fx),
                        lerp(self.voxel(x0, y1, z), self.voxel(x1, y1, z), fx),
                        fy,
                    )
                };
                lerp(plane(z0), plane(z1), fz)
            }
        }
    }

    /// The parameter interval of `ray` inside the grid's box, clipped to [0, t_max]. The box
    /// is the unit cube in the grid's frame; an affine map keeps ray parameters, so the slab
    /// test runs there.
    pub fn ray_extent(&self, ray: &Ray, t_max: f32) -> Option<(f32, f32)> {
        let o = self.to_world.inverse_point(ray.o);
        let d = self.to_world.inverse_vector(ray.d);
        let (mut t0, mut t1) = (0.0f32, t_max);
        for axis in 0..3 {
            let inv = 1.0 / d[axis];
            let (mut near, mut far) = ((0.0 - o[axis]) * inv, (1.0 - o[axis]) * inv);
            if near > far {
                std::mem::swap(&mut near, &mut far);
            }
            // NaN (a ray in the slab's plane) leaves the interval as it is.
            if near > t0 {
                t0 = near;
            }
            if far < t1 {
                t1 = far;
            }
        }
        (t0 < t1).then_some((t0, t1))
    }

    /// The largest voxel value.
    pub fn max_value(&self) -> f32 {
        self.max_value
    }

    pub fn resolution(&self) -> [usize; 3] {
        self.resolution
    }
}

/// The contents of a Mitsuba `.vol` file (binary, little-endian): the bytes `VOL`, version 3,
/// an encoding (1: 32-bit floats, the only one Mitsuba 3 reads), the resolution x, y, z and the
/// channel count as 32-bit integers, the bounding box (six floats: min x, y, z, max x, y, z),
/// then the values with the channel varying fastest, then x, y and z.
#[derive(Clone, Debug, PartialEq)]
pub struct VolFile {
    pub resolution: [usize; 3],
    pub channels: usize,
    pub bbox_min: Vec3,
    pub bbox_max: Vec3,
    pub data: Vec<f32>,
}

/// Bytes before the values.
const VOL_HEADER_BYTES: usize = 48;

/// Reads a `.vol` file's bytes; the error says what is wrong. Sizes are checked against the
/// file's length before anything is allocated.
pub fn parse_vol(bytes: &[u8]) -> Result<VolFile, String> {
    if bytes.len() < 4 || &bytes[0..3] != b"VOL" {
        return Err("not a Mitsuba volume file (it does not start with \"VOL\")".into());
    }
    if bytes[3] != 3 {
        return Err(format!(
            "unsupported .vol version {} (Mitsuba's grids are version 3)",
            bytes[3]
        ));
    }
    if bytes.len() < VOL_HEADER_BYTES {
        return Err(format!(
            "the file is truncated: {} bytes, shorter than the {VOL_HEADER_BYTES}-byte header",
            bytes.len()
        ));
    }
    let int = |i: usize| i32::from_le_bytes(bytes[i..i + 4].try_into().expect("4 bytes"));
    let float = |i: usize| f32::from_le_bytes(bytes[i..i + 4].try_into().expect("4 bytes"));
    let encoding = int(4);
    if encoding != 1 {
        return Err(format!(
            "unsupported .vol encoding {encoding} (only 1, 32-bit floats, is read, as in Mitsuba 3)"
        ));
    }
    let dims = [int(8), int(12), int(16), int(20)];
    if dims.iter().any(|&d| d <= 0) {
        return Err(format!(
            "invalid resolution {} × {} × {} with {} channels: every size must be positive",
            dims[0], dims[1], dims[2], dims[3]
        ));
    }
    let [x, y, z, channels] = dims.map(|d| d as usize);
    let payload = bytes.len() - VOL_HEADER_BYTES;
    let expected = x
        .checked_mul(y)
        .and_then(|n| n.checked_mul(z))
        .and_then(|n| n.checked_mul(channels))
        .and_then(|n| n.checked_mul(4));
    let grid = format!("the grid is {x} × {y} × {z} voxels of {channels} channel(s)");
    match expected {
        Some(expected) if expected == payload => {}
        Some(expected) if expected < payload => {
            return Err(format!(
                "{grid}, but the file has {} bytes more than that",
                payload - expected
            ));
        }
        _ => {
            return Err(format!(
                "{grid}, but the file is truncated: it holds {} values",
                payload / 4
            ));
        }
    }
    let data: Vec<f32> = bytes[VOL_HEADER_BYTES..]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().expect("4 bytes")))
        .collect();
    Ok(VolFile {
        resolution: [x, y, z],
        channels,
        bbox_min: Vec3::new(float(24), float(28), float(32)),
        bbox_max: Vec3::new(float(36), float(40), float(44)),
        data,
    })
}
