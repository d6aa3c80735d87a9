//! The B × B block grid of the histogram pass: which pixels form which block, and
//! where each block's entries start in the sorted list.

use crate::types::{BLOCK_SIZES, HistogramParams};
use thiserror::Error;

/// An image cut into B × B blocks; edge blocks are partial when B does not divide the
/// size. The grid may be shifted (paper §5.3, "block shifting"): with shift (sx, sy) the
/// block boundaries lie at x ≡ -sx and y ≡ -sy (mod B), so the first row and column of
/// blocks are partial too; shifting the grid every frame keeps block edges from staying
/// visible as seams over time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BlockGrid {
    /// Image width in pixels (> 0).
    pub width: u32,
    /// Image height in pixels (> 0).
    pub height: u32,
    /// B, one of [`BLOCK_SIZES`].
    pub block_size: u32,
    /// Horizontal grid shift sx in 0..B (0: blocks start at column 0).
    pub shift_x: u32,
    /// Vertical grid shift sy in 0..B (0: blocks start at row 0).
    pub shift_y: u32,
}

/// An image size or block size the histogram pass cannot take.
#[derive(Clone, Debug, Error, PartialEq, Eq)]
pub enum GridError {
    /// Width or height is zero.
    #[error("image size {width}x{height}: width and height must be at least 1")]
    EmptyImage {
        /// Requested width.
        width: u32,
        /// Requested height.
        height: u32,
    },
    /// The block size is not one of 4, 8, 16, 32.
    #[error("block size {0}: must be a power of two from 4 to 32 (4, 8, 16 or 32)")]
    BlockSize(u32),
    /// A grid shift of B or more.
    #[error("block grid shift ({x}, {y}): each must be below the block size {block_size}")]
    Shift {
        /// Requested horizontal shift.
        x: u32,
        /// Requested vertical shift.
        y: u32,
        /// B.
        block_size: u32,
    },
    /// More pixels than a u32 index can address.
    #[error("image size {width}x{height}: more than 2^32 - 1 pixels")]
    TooLarge {
        /// Requested width.
        width: u32,
        /// Requested height.
        height: u32,
    },
}

/// One block's pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BlockRect {
    /// Left pixel column.
    pub x: u32,
    /// Top pixel row.
    pub y: u32,
    /// Width (B, or less at the right edge).
    pub width: u32,
    /// Height (B, or less at the bottom edge).
    pub height: u32,
    /// Index of the block's first entry in the sorted list.
    pub base: u32,
}

impl BlockRect {
    /// Pixels in the block.
    pub fn len(&self) -> u32 {
        self.width * self.height
    }

    /// Whether the block has no pixels (never, for a valid grid).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Row-major image index of the block's `local`-th pixel (row-major inside the block).
    pub fn pixel(&self, image_width: u32, local: u32) -> u32 {
        (self.y + local / self.width) * image_width + self.x + local % self.width
    }
}

impl BlockGrid {
    /// Checks the sizes.
    pub fn new(width: u32, height: u32, block_size: u32) -> Result<Self, GridError> {
        if width == 0 || height == 0 {
            return Err(GridError::EmptyImage { width, height });
        }
        Self::check_block_size(block_size)?;
        if u64::from(width) * u64::from(height) > u64::from(u32::MAX) {
            return Err(GridError::TooLarge { width, height });
        }
        Ok(Self { width, height, block_size, shift_x: 0, shift_y: 0 })
    }

    /// Whether the histogram pass can take blocks of `block_size` × `block_size`: one of
    /// [`BLOCK_SIZES`] (the one check of a block size, wherever it comes from).
    pub fn check_block_size(block_size: u32) -> Result<(), GridError> {
        if BLOCK_SIZES.contains(&block_size) { Ok(()) } else { Err(GridError::BlockSize(block_size)) }
    }

    /// The same grid shifted by (sx, sy), each in 0..B.
    pub fn with_shift(self, shift_x: u32, shift_y: u32) -> Result<Self, GridError> {
        if shift_x >= self.block_size || shift_y >= self.block_size {
            return Err(GridError::Shift { x: shift_x, y: shift_y, block_size: self.block_size });
        }
        Ok(Self { shift_x, shift_y, ..self })
    }

    /// Blocks of the largest grid any shift gives (a shifted grid has up to one more
    /// row and column): what per-block buffers must hold when the shift changes per frame.
    pub fn max_shifted_block_count(&self) -> u32 {
        let extra = self.block_size - 1;
        (self.width + extra).div_ceil(self.block_size) * (self.height + extra).div_ceil(self.block_size)
    }

    /// Workgroups of the histogram dispatch over this grid: `1024 / B²` whole blocks per
    /// workgroup, laid out in rows of at most `max_workgroups` (the device's
    /// per-dimension limit; 0 counts as 1). The one statement of this formula: the
    /// renderer's pass, the embeddable pass and (in C) the export's `strata_frame.h` give
    /// the same numbers.
    pub fn histogram_workgroups(&self, max_workgroups: u32) -> [u32; 3] {
        let blocks_per_workgroup = crate::types::HISTOGRAM_SLOTS_PER_WORKGROUP / (self.block_size * self.block_size);
        let total = self.block_count().div_ceil(blocks_per_workgroup);
        let x = total.min(max_workgroups.max(1));
        [x, total.div_ceil(x), 1]
    }

    /// The `HistogramParams` of a dispatch over this grid with `workgroups_x` workgroups
    /// per row of the dispatch grid; `masking` false puts every candidate with an object id
    /// in one cluster per block (paper §4.3 without object masking).
    pub fn histogram_params(&self, workgroups_x: u32, masking: bool) -> HistogramParams {
        HistogramParams {
            width: self.width,
            height: self.height,
            block_size: self.block_size,
            log2_block_size: self.block_size.trailing_zeros(),
            blocks_x: self.blocks_x(),
            blocks_y: self.blocks_y(),
            workgroups_x,
            shift_x: self.shift_x,
            shift_y: self.shift_y,
            masking: u32::from(masking),
            _pad0: 0,
            _pad1: 0,
        }
    }

    /// Pixels in the image.
    pub fn pixel_count(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// Blocks per row.
    pub fn blocks_x(&self) -> u32 {
        (self.width + self.shift_x).div_ceil(self.block_size)
    }

    /// Blocks per column.
    pub fn blocks_y(&self) -> u32 {
        (self.height + self.shift_y).div_ceil(self.block_size)
    }

    /// Blocks in the image.
    pub fn block_count(&self) -> u32 {
        self.blocks_x() * self.blocks_y()
    }

    /// The block with row-major index `block`.
    pub fn block(&self, block: u32) -> BlockRect {
        let b = self.block_size;
        // Virtual (unshifted) edges of the block, clipped to the image.
        let (vx, vy) = (block % self.blocks_x() * b, block / self.blocks_x() * b);
        let x = vx.saturating_sub(self.shift_x);
        let y = vy.saturating_sub(self.shift_y);
        let width = (vx + b - self.shift_x).min(self.width) - x;
        let height = (vy + b - self.shift_y).min(self.height) - y;
        BlockRect { x, y, width, height, base: y * self.width + x * height }
    }

    /// The block containing pixel (x, y).
    pub fn block_of(&self, x: u32, y: u32) -> u32 {
        (y + self.shift_y) / self.block_size * self.blocks_x() + (x + self.shift_x) / self.block_size
    }
}

/// The block-grid shift of frame `frame` of render `seed` when the grid moves every frame
/// (the paper's limitations section): a hash of both, in 0..B per axis.
pub fn frame_shift(block_size: u32, frame: u32, seed: u32) -> (u32, u32) {
    let h = crate::hash::selection_hash(frame ^ crate::hash::selection_hash(seed ^ 0xb10c));
    (h % block_size, (h >> 16) % block_size)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_tile_the_sorted_list_without_gaps() {
        for (w, h, b, sx, sy) in [
            (1, 1, 4, 0, 0),
            (17, 33, 8, 0, 0),
            (33, 17, 16, 5, 15),
            (64, 64, 32, 31, 1),
            (5, 70, 4, 3, 2),
            (1, 1, 4, 3, 3),
        ] {
            let grid = BlockGrid::new(w, h, b).unwrap().with_shift(sx, sy).unwrap();
            let mut covered = vec![false; grid.pixel_count()];
            let mut entries = vec![false; grid.pixel_count()];
            for block in 0..grid.block_count() {
                let rect = grid.block(block);
                for local in 0..rect.len() {
                    let pixel = rect.pixel(w, local) as usize;
                    assert!(!covered[pixel]);
                    covered[pixel] = true;
                    assert_eq!(grid.block_of(pixel as u32 % w, pixel as u32 / w), block);
                    let entry = (rect.base + local) as usize;
                    assert!(!entries[entry]);
                    entries[entry] = true;
                }
            }
            assert!(covered.iter().all(|&c| c) && entries.iter().all(|&e| e));
        }
    }

    #[test]
    fn bad_sizes_are_named() {
        assert_eq!(BlockGrid::new(0, 5, 16), Err(GridError::EmptyImage { width: 0, height: 5 }));
        assert_eq!(BlockGrid::new(5, 5, 12), Err(GridError::BlockSize(12)));
        assert_eq!(BlockGrid::new(5, 5, 64), Err(GridError::BlockSize(64)));
        assert!(BlockGrid::new(1 << 20, 1 << 20, 16).is_err());
        assert!(BlockGrid::new(5, 5, 12).unwrap_err().to_string().contains("block size 12"));
    }
}
