//! The image's tiles: the squares of pixels a worker renders at a time, and the pixel sums
//! kept per tile between passes.

use glam::UVec2;

use super::resume::InitialState;
use crate::error::{Error, Result};
use crate::film::{PixelSums, ValueSum};

/// Edge length of the square tiles the image is divided into.
const TILE_SIZE: u32 = 16;

/// A rectangle of pixels, in crop-window coordinates.
#[derive(Clone, Copy, Debug)]
pub(super) struct Tile {
    pub(super) origin: UVec2,
    pub(super) size: UVec2,
}

pub(super) fn tiles(size: UVec2) -> Vec<Tile> {
    let mut tiles = Vec::new();
    for y in (0..size.y).step_by(TILE_SIZE as usize) {
        for x in (0..size.x).step_by(TILE_SIZE as usize) {
            let origin = UVec2::new(x, y);
            tiles.push(Tile {
                origin,
                size: (size - origin).min(UVec2::splat(TILE_SIZE)),
            });
        }
    }
    tiles
}

/// The sums of a tile's pixels, row-major within the tile: the image's and the extra channels'
/// (2K per pixel).
#[derive(Debug, Default)]
pub(super) struct TileSums {
    pub(super) pixels: Vec<PixelSums>,
    pub(super) aovs: Vec<ValueSum>,
}

impl Clone for TileSums {
    fn clone(&self) -> Self {
        TileSums {
            pixels: self.pixels.clone(),
            aovs: self.aovs.clone(),
        }
    }

    /// Copies into the allocations `self` has: a pass writes into the sums of the pass before
    /// the last without allocating (and faulting in) a film's worth of memory.
    fn clone_from(&mut self, source: &Self) {
        self.pixels.clone_from(&source.pixels);
        self.aovs.clone_from(&source.aovs);
    }
}

/// Pixel sums regrouped by tile (each tile's pixels row-major), from row-major sums with `k`
/// extra channels per pixel, or empty.
pub(super) fn tile_major(
    tiles: &[Tile],
    size: UVec2,
    k: usize,
    initial: Option<&InitialState>,
) -> Result<Vec<TileSums>> {
    let pixel_count = (size.x * size.y) as usize;
    if let Some(InitialState { pixels, aovs, .. }) = initial
        && (pixels.len() != pixel_count || aovs.len() != pixel_count * k)
    {
        return Err(Error::usage(
            "the initial state does not match the crop window and the integrator's channels",
        ));
    }
    Ok(tiles
        .iter()
        .map(|t| {
            let tile_pixels = (t.size.x * t.size.y) as usize;
            let mut sums = TileSums {
                pixels: Vec::with_capacity(tile_pixels),
                aovs: Vec::with_capacity(tile_pixels * k),
            };
            for y in 0..t.size.y {
                for x in 0..t.size.x {
                    let index = ((t.origin.y + y) * size.x + t.origin.x + x) as usize;
                    match initial {
                        Some(InitialState { pixels, aovs, .. }) => {
                            sums.pixels.push(pixels[index]);
                            sums.aovs
                                .extend_from_slice(&aovs[index * k..(index + 1) * k]);
                        }
                        None => {
                            sums.pixels.push(PixelSums::default());
                            sums.aovs.resize(sums.aovs.len() + k, ValueSum::default());
                        }
                    }
                }
            }
            sums
        })
        .collect())
}

/// Row-major pixel sums and extra channels' sums (`k` per pixel) from tile-major ones.
pub(super) fn row_major(
    tiles: &[Tile],
    size: UVec2,
    k: usize,
    sums: &[TileSums],
) -> (Vec<PixelSums>, Vec<ValueSum>) {
    let pixel_count = (size.x * size.y) as usize;
    let mut pixels = vec![PixelSums::default(); pixel_count];
    let mut aovs = vec![ValueSum::default(); pixel_count * k];
    for (tile, tile_sums) in tiles.iter().zip(sums) {
        for y in 0..tile.size.y {
            for x in 0..tile.size.x {
                let index = ((tile.origin.y + y) * size.x + tile.origin.x + x) as usize;
                let i = (y * tile.size.x + x) as usize;
                pixels[index] = tile_sums.pixels[i];
                aovs[index * k..(index + 1) * k]
                    .copy_from_slice(&tile_sums.aovs[i * k..(i + 1) * k]);
            }
        }
    }
    (pixels, aovs)
}
