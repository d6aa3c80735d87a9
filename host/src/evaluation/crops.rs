//! Close-ups for the report page, as in the paper's Figs. 1, 5, 10 and 12: rectangles of
//! the image chosen where the methods' errors differ most (or given with `--crop`), and
//! each method's RelMSE inside them.
//!
//! "Differ most" is measured on the per-pixel RelMSE maps of the images the page shows
//! (seed 1): a window's score is the spread, largest minus smallest, of the methods'
//! mean error in it, relative to their average (an absolute spread always lands on the
//! aliased edges of emitters, where every method is equally bad). Windows are scanned at a quarter of their side with summed-area
//! tables, and the best ones that do not overlap are kept, so two close-ups never show
//! the same pixels.

use anyhow::{Result, bail};

/// A rectangle of the image in pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Crop {
    /// Left column.
    pub x: u32,
    /// Top row.
    pub y: u32,
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
}

impl Crop {
    /// Whether two crops share a pixel.
    pub fn overlaps(&self, other: &Crop) -> bool {
        self.x < other.x + other.width
            && other.x < self.x + self.width
            && self.y < other.y + other.height
            && other.y < self.y + self.height
    }

    /// The mean of `map` (row-major, `image_width` wide) inside the crop.
    pub fn mean_of(&self, map: &[f64], image_width: u32) -> f64 {
        let mut sum = 0.0;
        for y in self.y..self.y + self.height {
            let row = (y * image_width) as usize;
            sum += map[row + self.x as usize..row + (self.x + self.width) as usize].iter().sum::<f64>();
        }
        sum / f64::from(self.width * self.height)
    }
}

impl std::fmt::Display for Crop {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{},{},{},{}", self.x, self.y, self.width, self.height)
    }
}

impl std::str::FromStr for Crop {
    type Err = String;

    /// `x,y,w,h` in pixels.
    fn from_str(text: &str) -> Result<Crop, String> {
        let parts: Vec<&str> = text.split(',').map(str::trim).collect();
        let numbers: Vec<u32> = parts
            .iter()
            .map(|p| p.parse::<u32>())
            .collect::<Result<_, _>>()
            .map_err(|_| format!("`{text}`: expected x,y,w,h in whole pixels"))?;
        match numbers[..] {
            [x, y, width, height] if width > 0 && height > 0 => Ok(Crop { x, y, width, height }),
            [_, _, _, _] => Err(format!("`{text}`: the width and height must be at least 1")),
            _ => Err(format!("`{text}`: expected four numbers x,y,w,h")),
        }
    }
}

/// Checks that `crop` lies inside a `width` × `height` image.
pub fn check_inside(crop: &Crop, width: u32, height: u32) -> Result<()> {
    if u64::from(crop.x) + u64::from(crop.width) > u64::from(width)
        || u64::from(crop.y) + u64::from(crop.height) > u64::from(height)
    {
        bail!("--crop {crop}: outside the {width}x{height} image");
    }
    Ok(())
}

/// The side of an automatic crop: a quarter of the smaller image side, 8 to 64 pixels
/// (at most the image).
pub fn automatic_side(width: u32, height: u32) -> u32 {
    (width.min(height) / 4).clamp(8, 64).min(width.min(height))
}

/// Up to `count` square crops of [`automatic_side`] where the error maps (one per
/// method, row-major, `width` × `height`) differ most, best first, each at least half a
/// side away from the others and from every crop of `taken`.
pub fn where_methods_differ(maps: &[Vec<f64>], width: u32, height: u32, count: usize, taken: &[Crop]) -> Vec<Crop> {
    if maps.len() < 2 || width == 0 || height == 0 {
        return Vec::new();
    }
    let side = automatic_side(width, height);
    let tables: Vec<SummedArea> = maps.iter().map(|m| SummedArea::new(m, width, height)).collect();
    let step = (side / 4).max(1);
    let mut scored = Vec::new();
    let positions = |extent: u32| (0..=extent - side).step_by(step as usize).chain(std::iter::once(extent - side));
    for y in positions(height) {
        for x in positions(width) {
            let sums: Vec<f64> = tables.iter().map(|t| t.sum(x, y, side, side)).collect();
            let (low, high) = sums.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| (l.min(v), h.max(v)));
            let mean = sums.iter().sum::<f64>() / sums.len() as f64;
            // Relative: where every method is bad alike (an emitter's aliased edge) the
            // spread is large but tells nothing about the methods.
            let score = (high - low) / mean;
            if score.is_finite() && score > 0.0 {
                scored.push((score, Crop { x, y, width: side, height: side }));
            }
        }
    }
    scored.sort_by(|a, b| b.0.total_cmp(&a.0));
    let mut chosen: Vec<Crop> = Vec::new();
    for (_, crop) in scored {
        if chosen.len() == count {
            break;
        }
        // Kept half a side apart, so the next close-up is not the same spot again.
        let margin = side / 2;
        let grown = Crop {
            x: crop.x.saturating_sub(margin),
            y: crop.y.saturating_sub(margin),
            width: crop.width + 2 * margin,
            height: crop.height + 2 * margin,
        };
        if !chosen.iter().chain(taken).any(|c| c.overlaps(&grown)) {
            chosen.push(crop);
        }
    }
    chosen
}

/// Sums over rectangles of a map in constant time.
struct SummedArea {
    width: u32,
    /// (width + 1) × (height + 1) prefix sums, non-finite values counted as 0.
    sums: Vec<f64>,
}

impl SummedArea {
    fn new(map: &[f64], width: u32, height: u32) -> SummedArea {
        let stride = width as usize + 1;
        let mut sums = vec![0.0; stride * (height as usize + 1)];
        for y in 0..height as usize {
            let mut row = 0.0;
            for x in 0..width as usize {
                let v = map[y * width as usize + x];
                row += if v.is_finite() { v } else { 0.0 };
                sums[(y + 1) * stride + x + 1] = sums[y * stride + x + 1] + row;
            }
        }
        SummedArea { width, sums }
    }

    fn sum(&self, x: u32, y: u32, w: u32, h: u32) -> f64 {
        let stride = self.width as usize + 1;
        let at = |x: u32, y: u32| self.sums[y as usize * stride + x as usize];
        at(x + w, y + h) - at(x, y + h) - at(x + w, y) + at(x, y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crops_parse_and_bad_ones_are_named() {
        assert_eq!("4,5,16,8".parse::<Crop>(), Ok(Crop { x: 4, y: 5, width: 16, height: 8 }));
        assert!("4,5,16".parse::<Crop>().unwrap_err().contains("four numbers"));
        assert!("4,5,0,8".parse::<Crop>().unwrap_err().contains("at least 1"));
        assert!("a,5,1,8".parse::<Crop>().unwrap_err().contains("`a,5,1,8`"));
        let crop = Crop { x: 60, y: 0, width: 8, height: 8 };
        assert!(check_inside(&crop, 64, 64).unwrap_err().to_string().contains("outside the 64x64 image"));
        assert!(check_inside(&crop, 68, 8).is_ok());
    }

    #[test]
    fn the_crop_lands_where_the_maps_differ_and_crops_do_not_overlap() {
        let (width, height) = (64u32, 48u32);
        let flat = vec![0.1; (width * height) as usize];
        let mut different = flat.clone();
        // A 16×16 patch at (40, 20) where one method is much worse, and a weaker one at (4, 4).
        for y in 20..36 {
            for x in 40..56 {
                different[(y * width + x) as usize] = 5.0;
            }
        }
        for y in 4..10 {
            for x in 4..10 {
                different[(y * width + x) as usize] = 2.0;
            }
        }
        let crops = where_methods_differ(&[flat.clone(), different.clone()], width, height, 2, &[]);
        assert_eq!(crops.len(), 2);
        assert_eq!(automatic_side(width, height), 12);
        let patch = Crop { x: 40, y: 20, width: 16, height: 16 };
        assert!(patch.overlaps(&crops[0]) && !patch.overlaps(&crops[1]), "{crops:?}");
        assert!(!crops[0].overlaps(&crops[1]));
        assert!(crops[1].overlaps(&Crop { x: 4, y: 4, width: 6, height: 6 }), "{crops:?}");
        // A crop the user gave is avoided; identical maps give no crop at all.
        let avoided = where_methods_differ(&[flat.clone(), different], width, height, 1, &[patch]);
        assert!(!avoided[0].overlaps(&patch));
        assert!(where_methods_differ(&[flat.clone(), flat], width, height, 2, &[]).is_empty());
    }

    #[test]
    fn a_crop_mean_is_the_mean_of_its_pixels() {
        let map: Vec<f64> = (0..16).map(f64::from).collect();
        let crop = Crop { x: 1, y: 1, width: 2, height: 2 };
        assert_eq!(crop.mean_of(&map, 4), (5.0 + 6.0 + 9.0 + 10.0) / 4.0);
        let table = SummedArea::new(&map, 4, 4);
        assert_eq!(table.sum(1, 1, 2, 2), 30.0);
    }
}
