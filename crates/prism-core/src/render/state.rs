//! The render state file: everything needed to continue a render or to merge several, written
//! atomically and checked on reading.
//!
//! Layout (little endian): the magic `PRISMRS\0`, a format version (u32), the identity of the
//! render (scene fingerprint, seed, sampler, samples per pixel of the stratification, film size
//! and crop window), the sample index ranges the pixels hold, the names of the integrator's extra
//! channels (K), the pixel count and each pixel's exact sums (264 bytes: the image's, then those
//! of filter MIS's control variate; then 32 for each extra channel, its sum over all samples and
//! over half A), and a CRC-32 of all of it. Between the channel names and the pixel count, the
//! state of a progressive integrator (see [`IntegratorState`]): its name's length (0 when there is
//! none), its name, its byte count and its bytes. Version 2 added the extra channels, version 3
//! the control variate's sums, version 4 the integrator's state; a state of another version is
//! refused with its version named. A state is written to a temporary file,
//! flushed to disk and renamed over the old one, so a crash while writing leaves the previous
//! state intact.

use std::io::Write;
use std::ops::Range;
use std::path::Path;

use glam::UVec2;

use crate::error::{Error, ErrorKind, Result};
use crate::film::CropWindow;
use crate::film::accumulation::{AOV_SUMS_PER_CHANNEL, ExactSum, PixelSums, ValueSum};

const MAGIC: &[u8; 8] = b"PRISMRS\0";
const VERSION: u32 = 4;
/// Bytes per pixel: fifteen 128-bit sums and three 64-bit counts.
const PIXEL_BYTES: usize = 15 * 16 + 3 * 8;
/// Bytes per pixel and extra channel: two 128-bit sums.
const AOV_BYTES: usize = 2 * 16;
/// At most this many separate sample ranges (a merge of many farm tasks).
const MAX_RANGES: usize = 1 << 16;
/// At most this many extra channels, each name at most this long.
const MAX_AOVS: usize = 1 << 12;
const MAX_AOV_NAME: usize = 256;
/// At most this long, an integrator's name.
const MAX_INTEGRATOR_NAME: usize = 64;

/// What a render state belongs to: two states can be continued or merged only if they agree.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RenderIdentity {
    /// Hash of the scene's description and of the files it loads.
    pub scene: u64,
    pub seed: u64,
    /// The sampler type (`independent`, `nrooks`, ...).
    pub sampler: String,
    /// Samples per pixel of the sampler's stratification.
    pub samples_per_pixel: u32,
    pub film_size: UVec2,
    pub crop: CropWindow,
}

impl RenderIdentity {
    /// Why `other` is not the same render, in words; None when it is.
    pub fn mismatch(&self, other: &RenderIdentity) -> Option<String> {
        if self.scene != other.scene {
            return Some(
                "it comes from a different scene (or the scene or a file it loads has changed)"
                    .into(),
            );
        }
        if self.seed != other.seed {
            return Some(format!(
                "it was rendered with seed {}, not {}",
                other.seed, self.seed
            ));
        }
        if self.sampler != other.sampler || self.samples_per_pixel != other.samples_per_pixel {
            return Some(format!(
                "it was rendered with the {} sampler at {} spp, not the {} sampler at {} spp",
                other.sampler, other.samples_per_pixel, self.sampler, self.samples_per_pixel
            ));
        }
        if self.film_size != other.film_size || self.crop != other.crop {
            return Some(format!(
                "it holds a {}×{} crop of a {}×{} film, not a {}×{} crop of a {}×{} film",
                other.crop.size.x,
                other.crop.size.y,
                other.film_size.x,
                other.film_size.y,
                self.crop.size.x,
                self.crop.size.y,
                self.film_size.x,
                self.film_size.y
            ));
        }
        None
    }
}

/// What a progressive integrator (`sppm`, `guided_path`) carries from pass to pass besides pixel
/// sums (per-pixel photon statistics, a learned guiding distribution): the integrator's name and
/// its own encoding, which only that integrator reads. Pixel sums can be merged by adding them;
/// such states are merged by their integrator ([`RenderState::merge`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct IntegratorState {
    /// The integrator's type name, as the scene names it.
    pub integrator: String,
    pub bytes: Vec<u8>,
}

/// The accumulated sums of a render and what they belong to.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RenderState {
    pub identity: RenderIdentity,
    /// Sample index ranges every pixel holds: sorted, disjoint, non-empty.
    pub ranges: Vec<Range<u32>>,
    /// Pixel sums, row-major over the crop window.
    pub pixels: Vec<PixelSums>,
    /// Names of the integrator's extra channels (K).
    pub aov_names: Vec<String>,
    /// Their sums, 2K per pixel in the pixels' order, as [`crate::film::Film::aovs`] holds them.
    pub aovs: Vec<ValueSum>,
    /// What a progressive integrator needs to continue besides the sums.
    pub integrator_state: Option<IntegratorState>,
}

fn corrupt(path: &Path, what: impl std::fmt::Display) -> Error {
    Error {
        kind: ErrorKind::Input,
        location: None,
        message: format!("\"{}\" is not a valid render state: {what}", path.display()),
        help: Some("use a state written by prism render --checkpoint, or render again".into()),
    }
}

/// Reads little-endian values from a byte slice, failing cleanly at its end.
struct Reader<'a> {
    bytes: &'a [u8],
    position: usize,
}

impl Reader<'_> {
    fn take(&mut self, n: usize) -> Option<&[u8]> {
        let end = self.position.checked_add(n)?;
        let slice = self.bytes.get(self.position..end)?;
        self.position = end;
        Some(slice)
    }

    fn u32(&mut self) -> Option<u32> {
        self.take(4)
            .map(|b| u32::from_le_bytes(b.try_into().unwrap_or_default()))
    }

    fn u64(&mut self) -> Option<u64> {
        self.take(8)
            .map(|b| u64::from_le_bytes(b.try_into().unwrap_or_default()))
    }

    fn i128(&mut self) -> Option<i128> {
        self.take(16)
            .map(|b| i128::from_le_bytes(b.try_into().unwrap_or_default()))
    }

    fn left(&self) -> usize {
        self.bytes.len() - self.position
    }
}

impl RenderState {
    /// Samples per pixel the state holds.
    pub fn sample_count(&self) -> u32 {
        self.ranges.iter().map(|r| r.end - r.start).sum()
    }

    /// The bytes of the state's file (the layout above); [`Self::decode`] reads them.
    pub fn encode(&self) -> Vec<u8> {
        let id = &self.identity;
        let mut out = Vec::with_capacity(128 + self.pixels.len() * PIXEL_BYTES);
        out.extend_from_slice(MAGIC);
        out.extend_from_slice(&VERSION.to_le_bytes());
        out.extend_from_slice(&id.scene.to_le_bytes());
        out.extend_from_slice(&id.seed.to_le_bytes());
        out.extend_from_slice(&(id.sampler.len() as u32).to_le_bytes());
        out.extend_from_slice(id.sampler.as_bytes());
        out.extend_from_slice(&id.samples_per_pixel.to_le_bytes());
        for v in [
            id.film_size.x,
            id.film_size.y,
            id.crop.offset.x,
            id.crop.offset.y,
            id.crop.size.x,
            id.crop.size.y,
        ] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out.extend_from_slice(&(self.ranges.len() as u32).to_le_bytes());
        for r in &self.ranges {
            out.extend_from_slice(&r.start.to_le_bytes());
            out.extend_from_slice(&r.end.to_le_bytes());
        }
        out.extend_from_slice(&(self.aov_names.len() as u32).to_le_bytes());
        for name in &self.aov_names {
            out.extend_from_slice(&(name.len() as u32).to_le_bytes());
            out.extend_from_slice(name.as_bytes());
        }
        match &self.integrator_state {
            None => out.extend_from_slice(&0u32.to_le_bytes()),
            Some(state) => {
                out.extend_from_slice(&(state.integrator.len() as u32).to_le_bytes());
                out.extend_from_slice(state.integrator.as_bytes());
                out.extend_from_slice(&(state.bytes.len() as u64).to_le_bytes());
                out.extend_from_slice(&state.bytes);
            }
        }
        let k = self.aov_names.len() * AOV_SUMS_PER_CHANNEL;
        out.extend_from_slice(&(self.pixels.len() as u64).to_le_bytes());
        for (i, p) in self.pixels.iter().enumerate() {
            let c = &p.control;
            for s in p.xyz.iter().chain(&c.xyz_first_half).chain(&c.excess) {
                out.extend_from_slice(&s.0.to_le_bytes());
            }
            for s in p
                .xyz_squared
                .iter()
                .chain(&c.xyz_excess)
                .chain([&c.excess_squared])
            {
                out.extend_from_slice(&s.0.to_le_bytes());
            }
            out.extend_from_slice(&p.samples.to_le_bytes());
            out.extend_from_slice(&p.rejected.to_le_bytes());
            out.extend_from_slice(&c.first_half_samples.to_le_bytes());
            for s in &self.aovs[i * k..(i + 1) * k] {
                out.extend_from_slice(&s.0.to_le_bytes());
            }
        }
        let checksum = crc32fast::hash(&out);
        out.extend_from_slice(&checksum.to_le_bytes());
        out
    }

    /// Parses a state; every inconsistency is an error naming `path` (for messages).
    pub fn decode(bytes: &[u8], path: &Path) -> Result<RenderState> {
        if bytes.len() < MAGIC.len() + 8 || &bytes[..MAGIC.len()] != MAGIC {
            return Err(corrupt(
                path,
                "it does not start with a Prism render state header",
            ));
        }
        let (body, stored) = bytes.split_at(bytes.len() - 4);
        let stored = u32::from_le_bytes(stored.try_into().unwrap_or_default());
        if crc32fast::hash(body) != stored {
            return Err(corrupt(
                path,
                "its checksum does not match (the file is damaged or truncated)",
            ));
        }
        let mut r = Reader {
            bytes: body,
            position: MAGIC.len(),
        };
        let truncated = || corrupt(path, "it ends too early");
        let version = r.u32().ok_or_else(truncated)?;
        if version != VERSION {
            return Err(Error {
                kind: ErrorKind::Input,
                location: None,
                message: format!(
                    "\"{}\" is a render state of format version {version}; this Prism reads \
                     version {VERSION} only (version 4 holds the state of progressive \
                     integrators)",
                    path.display()
                ),
                help: Some(
                    "render the scene again, or finish this render with the Prism that \
                     started it"
                        .into(),
                ),
            });
        }
        let scene = r.u64().ok_or_else(truncated)?;
        let seed = r.u64().ok_or_else(truncated)?;
        let name_length = r.u32().ok_or_else(truncated)? as usize;
        if name_length > 64 {
            return Err(corrupt(path, "its sampler name is too long"));
        }
        let sampler = std::str::from_utf8(r.take(name_length).ok_or_else(truncated)?)
            .map_err(|_| corrupt(path, "its sampler name is not text"))?
            .to_string();
        let samples_per_pixel = r.u32().ok_or_else(truncated)?;
        let mut v = [0u32; 6];
        for value in &mut v {
            *value = r.u32().ok_or_else(truncated)?;
        }
        let identity = RenderIdentity {
            scene,
            seed,
            sampler,
            samples_per_pixel,
            film_size: UVec2::new(v[0], v[1]),
            crop: CropWindow {
                offset: UVec2::new(v[2], v[3]),
                size: UVec2::new(v[4], v[5]),
            },
        };
        let range_count = r.u32().ok_or_else(truncated)? as usize;
        if range_count == 0 || range_count > MAX_RANGES || range_count * 8 > r.left() {
            return Err(corrupt(
                path,
                format!("it declares {range_count} sample ranges"),
            ));
        }
        let mut ranges = Vec::with_capacity(range_count);
        for _ in 0..range_count {
            let (start, end) = (
                r.u32().ok_or_else(truncated)?,
                r.u32().ok_or_else(truncated)?,
            );
            if start >= end
                || ranges
                    .last()
                    .is_some_and(|last: &Range<u32>| last.end > start)
            {
                return Err(corrupt(
                    path,
                    "its sample ranges are empty, unsorted or overlapping",
                ));
            }
            ranges.push(start..end);
        }
        let aov_count = r.u32().ok_or_else(truncated)? as usize;
        if aov_count > MAX_AOVS || aov_count * 4 > r.left() {
            return Err(corrupt(
                path,
                format!("it declares {aov_count} extra channels"),
            ));
        }
        let mut aov_names = Vec::with_capacity(aov_count);
        for _ in 0..aov_count {
            let length = r.u32().ok_or_else(truncated)? as usize;
            if length > MAX_AOV_NAME {
                return Err(corrupt(path, "an extra channel's name is too long"));
            }
            let name = std::str::from_utf8(r.take(length).ok_or_else(truncated)?)
                .map_err(|_| corrupt(path, "an extra channel's name is not text"))?;
            aov_names.push(name.to_string());
        }
        let name_length = r.u32().ok_or_else(truncated)? as usize;
        let integrator_state = if name_length == 0 {
            None
        } else {
            if name_length > MAX_INTEGRATOR_NAME {
                return Err(corrupt(path, "its integrator's name is too long"));
            }
            let integrator = std::str::from_utf8(r.take(name_length).ok_or_else(truncated)?)
                .map_err(|_| corrupt(path, "its integrator's name is not text"))?
                .to_string();
            let length = r.u64().ok_or_else(truncated)?;
            if length > r.left() as u64 {
                return Err(corrupt(
                    path,
                    format!("its integrator's state declares {length} bytes"),
                ));
            }
            let bytes = r.take(length as usize).ok_or_else(truncated)?.to_vec();
            Some(IntegratorState { integrator, bytes })
        };
        let pixel_bytes = (PIXEL_BYTES + AOV_BYTES * aov_count) as u64;
        let pixel_count = r.u64().ok_or_else(truncated)?;
        let expected = u64::from(identity.crop.size.x) * u64::from(identity.crop.size.y);
        if pixel_count != expected || pixel_count.checked_mul(pixel_bytes) != Some(r.left() as u64)
        {
            return Err(corrupt(
                path,
                format!(
                    "it declares {pixel_count} pixels for a {}×{} crop in {} bytes",
                    identity.crop.size.x,
                    identity.crop.size.y,
                    r.left()
                ),
            ));
        }
        let mut pixels = Vec::with_capacity(pixel_count as usize);
        let aov_sums = aov_count * AOV_SUMS_PER_CHANNEL;
        let mut aovs = Vec::with_capacity(pixel_count as usize * aov_sums);
        for _ in 0..pixel_count {
            let mut p = PixelSums::default();
            let c = &mut p.control;
            for s in p
                .xyz
                .iter_mut()
                .chain(&mut c.xyz_first_half)
                .chain(&mut c.excess)
            {
                *s = ExactSum(r.i128().ok_or_else(truncated)?);
            }
            for s in p
                .xyz_squared
                .iter_mut()
                .chain(&mut c.xyz_excess)
                .chain([&mut c.excess_squared])
            {
                *s = ExactSum(r.i128().ok_or_else(truncated)?);
            }
            p.samples = r.u64().ok_or_else(truncated)?;
            p.rejected = r.u64().ok_or_else(truncated)?;
            p.control.first_half_samples = r.u64().ok_or_else(truncated)?;
            if p.control.first_half_samples > p.samples {
                return Err(corrupt(
                    path,
                    "a pixel has more samples in one half than in all",
                ));
            }
            pixels.push(p);
            for _ in 0..aov_sums {
                aovs.push(ExactSum(r.i128().ok_or_else(truncated)?));
            }
        }
        Ok(RenderState {
            identity,
            ranges,
            pixels,
            aov_names,
            aovs,
            integrator_state,
        })
    }

    /// Writes the state atomically: to `path.tmp`, flushed to disk, then renamed over `path`.
    pub fn write(&self, path: &Path) -> Result<()> {
        let mut temporary = path.as_os_str().to_owned();
        temporary.push(".tmp");
        let temporary = std::path::PathBuf::from(temporary);
        let write = || -> std::io::Result<()> {
            let mut file = std::fs::File::create(&temporary)?;
            file.write_all(&self.encode())?;
            file.sync_all()?;
            std::fs::rename(&temporary, path)?;
            if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
                // Make the rename itself durable.
                std::fs::File::open(parent)?.sync_all()?;
            }
            Ok(())
        };
        write().map_err(|e| {
            let _ = std::fs::remove_file(&temporary);
            Error::io(path, &e, "write the render state")
        })
    }

    /// Reads and checks a state file.
    pub fn read(path: &Path) -> Result<RenderState> {
        let bytes = std::fs::read(path).map_err(|e| {
            let mut error = Error::io(path, &e, "read the render state");
            if e.kind() == std::io::ErrorKind::NotFound {
                error.kind = ErrorKind::Input;
            }
            error
        })?;
        RenderState::decode(&bytes, path)
    }

    /// The union of states of the same render over disjoint sample ranges: exactly the sums of
    /// one render of all their samples. States of a progressive integrator are merged by that
    /// integrator, after the same checks.
    pub fn merge(states: &[RenderState], paths: &[&Path]) -> Result<RenderState> {
        let Some(first) = states.first() else {
            return Err(Error::usage("nothing to merge"));
        };
        for (i, state) in states.iter().enumerate() {
            let integrator = |s: &RenderState| {
                s.integrator_state
                    .as_ref()
                    .map(|state| state.integrator.clone())
            };
            if integrator(state) != integrator(first) {
                return Err(Error::usage(format!(
                    "\"{}\" cannot be merged with \"{}\": they were rendered by different \
                     integrators",
                    paths[i].display(),
                    paths[0].display()
                )));
            }
        }
        let mut ranges: Vec<(Range<u32>, usize)> = Vec::new();
        for (i, state) in states.iter().enumerate() {
            if let Some(reason) = first.identity.mismatch(&state.identity) {
                return Err(Error::usage(format!(
                    "\"{}\" cannot be merged with \"{}\": {reason}",
                    paths[i].display(),
                    paths[0].display()
                )));
            }
            ranges.extend(state.ranges.iter().map(|r| (r.clone(), i)));
        }
        for (i, state) in states.iter().enumerate() {
            if state.aov_names != first.aov_names {
                return Err(Error::usage(format!(
                    "\"{}\" cannot be merged with \"{}\": their integrators write different extra channels",
                    paths[i].display(),
                    paths[0].display()
                )));
            }
        }
        ranges.sort_by_key(|(r, _)| r.start);
        for w in ranges.windows(2) {
            if w[0].0.end > w[1].0.start {
                return Err(Error::usage(format!(
                    "\"{}\" (samples {}..{}) and \"{}\" (samples {}..{}) overlap",
                    paths[w[0].1].display(),
                    w[0].0.start,
                    w[0].0.end,
                    paths[w[1].1].display(),
                    w[1].0.start,
                    w[1].0.end
                ))
                .with_help("merge renders of disjoint --sample-range values"));
            }
        }
        if let Some(state) = &first.integrator_state {
            return match state.integrator.as_str() {
                "sppm" => super::sppm::merge_states(states, paths),
                "guided_path" => super::guided::merge_states(states, paths),
                _ => Err(Error::usage(format!(
                    "the {} integrator's render states cannot be merged",
                    state.integrator
                ))),
            };
        }
        let mut pixels = first.pixels.clone();
        let mut aovs = first.aovs.clone();
        for state in &states[1..] {
            for (p, q) in pixels.iter_mut().zip(&state.pixels) {
                p.merge(q);
            }
            for (a, b) in aovs.iter_mut().zip(&state.aovs) {
                a.merge(*b);
            }
        }
        // Adjacent ranges become one.
        let mut merged: Vec<Range<u32>> = Vec::new();
        for (r, _) in ranges {
            match merged.last_mut() {
                Some(last) if last.end == r.start => last.end = r.end,
                _ => merged.push(r),
            }
        }
        Ok(RenderState {
            identity: first.identity.clone(),
            ranges: merged,
            pixels,
            aov_names: first.aov_names.clone(),
            aovs,
            integrator_state: None,
        })
    }
}

#[cfg(test)]
// Lists of sample ranges that happen to hold one range.
#[allow(clippy::single_range_in_vec_init)]
mod tests {
    use super::*;

    fn state(ranges: Vec<Range<u32>>) -> RenderState {
        let crop = CropWindow {
            offset: UVec2::new(1, 2),
            size: UVec2::new(3, 2),
        };
        let mut pixels = vec![PixelSums::default(); 6];
        let mut aovs = vec![ValueSum::default(); 24];
        for (i, p) in pixels.iter_mut().enumerate() {
            p.add([i as f32, 0.5, -1.0]);
            p.add_shared([0.25, i as f64, 2.0], 0.125 - i as f64 * 0.01, i % 2 == 1);
            aovs[4 * i].add(i as f64 * 0.25);
            aovs[4 * i + 1].add(-3.0);
            aovs[4 * i + 2].add(i as f64 * 0.125);
        }
        RenderState {
            identity: RenderIdentity {
                scene: 42,
                seed: 7,
                sampler: "nrooks".into(),
                samples_per_pixel: 64,
                film_size: UVec2::new(8, 8),
                crop,
            },
            ranges,
            pixels,
            aov_names: vec!["dd.T".into(), "m2_dd.T".into()],
            aovs,
            integrator_state: None,
        }
    }

    fn progressive(ranges: Vec<Range<u32>>) -> RenderState {
        RenderState {
            integrator_state: Some(IntegratorState {
                integrator: "sppm".into(),
                bytes: vec![1, 2, 3, 250],
            }),
            ..state(ranges)
        }
    }

    #[test]
    fn round_trip() {
        let path = Path::new("x.state");
        for s in [state(vec![0..4, 8..12]), progressive(vec![0..4])] {
            assert_eq!(RenderState::decode(&s.encode(), path).unwrap(), s);
        }
    }

    /// Every truncation and every flipped byte is detected; nothing panics.
    #[test]
    fn damage_is_detected() {
        let bytes = progressive(vec![0..4]).encode();
        let path = Path::new("x.state");
        for n in 0..bytes.len() {
            assert!(
                RenderState::decode(&bytes[..n], path).is_err(),
                "truncated to {n}"
            );
        }
        for i in 0..bytes.len() {
            let mut damaged = bytes.clone();
            damaged[i] ^= 0x10;
            assert!(
                RenderState::decode(&damaged, path).is_err(),
                "byte {i} flipped"
            );
        }
    }

    /// A state of the format before the control variate is refused, naming its version.
    #[test]
    fn an_older_version_is_refused_clearly() {
        let mut bytes = state(vec![0..4]).encode();
        bytes[8..12].copy_from_slice(&2u32.to_le_bytes());
        let body = bytes.len() - 4;
        let checksum = crc32fast::hash(&bytes[..body]);
        bytes[body..].copy_from_slice(&checksum.to_le_bytes());
        let error = RenderState::decode(&bytes, Path::new("old.state")).unwrap_err();
        assert!(error.message.contains("format version 2"), "{error}");
        assert!(error.message.contains("reads version 4 only"), "{error}");
        assert!(error.help.unwrap().contains("render the scene again"));
    }

    #[test]
    fn merge_checks_identity_and_overlap() {
        let (a, b) = (state(vec![0..4]), state(vec![4..8]));
        let paths = [Path::new("a"), Path::new("b")];
        let merged = RenderState::merge(&[a.clone(), b.clone()], &paths).unwrap();
        assert_eq!(merged.ranges, vec![0..8]);
        assert_eq!(merged.pixels[1].samples, 4);
        assert_eq!(merged.aovs[4].value(), 0.5);
        let overlapping = state(vec![2..6]);
        assert!(RenderState::merge(&[a.clone(), overlapping], &paths).is_err());
        let mut other_seed = b.clone();
        other_seed.identity.seed = 8;
        let error = RenderState::merge(&[a.clone(), other_seed], &paths).unwrap_err();
        assert!(error.message.contains("seed"), "{error}");
        let mut other_channels = b;
        other_channels.aov_names[1] = "m2_other.T".into();
        let error = RenderState::merge(&[a.clone(), other_channels], &paths).unwrap_err();
        assert!(error.message.contains("extra channels"), "{error}");
        let error = RenderState::merge(&[a, progressive(vec![4..8])], &paths).unwrap_err();
        assert!(error.message.contains("different integrators"), "{error}");
    }
}
