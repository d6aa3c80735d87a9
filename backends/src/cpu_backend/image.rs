//! Textures and samplers in the interpreter, written from the WGSL and Vulkan specs (not
//! from a GPU's output).
//!
//! A bound texture is a slot of words like a buffer: a header of [`HEADER_WORDS`]
//! (format, dimension, mip levels, width, height, depth or layers), then every mip level's
//! texels in the byte layout of [`crate::texture`]. A bound sampler's slot holds its six
//! modes. An image value in a register is a pointer-shaped pair whose first word names
//! the slot, so textures pass through function arguments like any value.
//!
//! Semantics, per built-in:
//! * `textureLoad`: the texel, converted as Vulkan's texel input conversion says
//!   (unorm `c / 255` correctly rounded, f16 exactly, missing components 0 and alpha 1).
//!   A device may compute `c × (1/255)`, one f32 ULP away (lavapipe does). Out-of-range
//!   coordinates, layers or levels (negative ones included) read (0, 0, 0, 0), as naga's
//!   `ReadZeroSkipWrite` policy (which the ash paths are compiled with) and Vulkan's
//!   robust image access give; WGSL allows this among other answers.
//! * `textureStore`: Vulkan's texel output conversion: unorm clamps to [0, 1] and rounds
//!   to nearest, f16 rounds to nearest even, integer formats keep the low bits (Vulkan
//!   leaves out-of-range integers undefined); out-of-range stores are dropped.
//! * `textureDimensions`, `textureNumLevels`, `textureNumLayers`: exact (a level beyond
//!   the last is clamped).
//! * `textureSampleLevel` and `textureGather`: Vulkan's filtering with exact f32 weights.
//!   A device quantises the weights to its `subTexelPrecisionBits` (lavapipe: 8) and the
//!   mip blend to its `mipmapPrecisionBits`, so filtered values agree within
//!   2^-bits of the blended texels' range per filtered axis, not bit for bit; that is the
//!   bound the tests declare.
//!
//! Where: this file is the run-time side (the slots' words, bound by [`super`]'s
//! backend, and the built-ins run for one invocation by [`super::execute`]). The
//! instruction ([`ImageInsn`]) is defined with the others in [`super::insn`], and
//! lowered from naga's IR in [`super::image_lower`].

use super::arith::{f16_to_f32, f32_to_f16};
use super::insn::{ImageInsn, ImageOp, Reg};
use super::lanes::LaneRegs;
use crate::texture::{AddressMode, FilterMode, SamplerDesc, TextureDesc};
use std::sync::atomic::{AtomicU32, Ordering};
use strata_kernels::{TexelFormat, TextureDimension};

/// Words before a bound texture's texels.
pub(super) const HEADER_WORDS: usize = 6;
/// Words of a bound sampler.
pub(super) const SAMPLER_WORDS: usize = 6;

/// A bound texture's header followed by `texels` (every level, in order); an error
/// where the machine cannot give the memory (a texture's size comes from the caller).
pub(super) fn bind_texture(desc: &TextureDesc, texels: &[u32]) -> Result<Vec<u32>, std::collections::TryReserveError> {
    let format = TexelFormat::ALL.iter().position(|f| *f == desc.format).expect("a format of ALL") as u32;
    let dimension = DIMENSIONS.iter().position(|d| *d == desc.dimension).expect("a dimension") as u32;
    let mut words = Vec::new();
    words.try_reserve_exact(HEADER_WORDS.saturating_add(texels.len()))?;
    words.extend_from_slice(&[format, dimension, desc.mip_levels, desc.size[0], desc.size[1], desc.size[2]]);
    words.extend_from_slice(texels);
    Ok(words)
}

/// A bound sampler's words.
pub(super) fn bind_sampler(desc: &SamplerDesc) -> Vec<u32> {
    let address = |mode: AddressMode| match mode {
        AddressMode::ClampToEdge => 0,
        AddressMode::Repeat => 1,
        AddressMode::MirrorRepeat => 2,
    };
    let filter = |mode: FilterMode| u32::from(mode == FilterMode::Linear);
    vec![
        address(desc.address[0]),
        address(desc.address[1]),
        address(desc.address[2]),
        filter(desc.mag_filter),
        filter(desc.min_filter),
        filter(desc.mipmap_filter),
    ]
}

const DIMENSIONS: [TextureDimension; 4] =
    [TextureDimension::D1, TextureDimension::D2, TextureDimension::D2Array, TextureDimension::D3];

/// A bound texture as its header describes it.
struct Texture<'a> {
    words: &'a [AtomicU32],
    format: TexelFormat,
    dimension: TextureDimension,
    levels: u32,
    size: [u32; 3],
}

impl<'a> Texture<'a> {
    fn of(words: &'a [AtomicU32]) -> Option<Self> {
        // Read into an array: this runs for every image instruction of every invocation.
        let header: [u32; HEADER_WORDS] =
            std::array::from_fn(|i| words.get(i).map_or(0, |w| w.load(Ordering::Relaxed)));
        words.get(HEADER_WORDS - 1)?;
        Some(Self {
            words,
            format: *TexelFormat::ALL.get(header[0] as usize)?,
            dimension: *DIMENSIONS.get(header[1] as usize)?,
            levels: header[2].max(1),
            size: [header[3], header[4], header[5]],
        })
    }

    fn desc(&self) -> TextureDesc {
        TextureDesc {
            label: String::new(),
            dimension: self.dimension,
            size: self.size,
            mip_levels: self.levels,
            format: self.format,
        }
    }

    /// Size of `level` (its x, y, and z or layers).
    fn level_size(&self, level: u32) -> [u32; 3] {
        self.desc().level_size(level)
    }

    /// Word index of texel `[x, y, z]` of `level` (all in range).
    fn texel_at(&self, level: u32, [x, y, z]: [u32; 3]) -> usize {
        let desc = self.desc();
        let before: u64 = (0..level).map(|l| desc.level_bytes(l)).sum::<u64>() / 4;
        let [w, h, _] = desc.level_size(level);
        let per_texel = self.format.bytes_per_texel() as usize / 4;
        HEADER_WORDS + before as usize + ((z as usize * h as usize + y as usize) * w as usize + x as usize) * per_texel
    }

    /// Texel `at` of `level`, as the four 32-bit components WGSL reads.
    fn read(&self, level: u32, at: [u32; 3]) -> [u32; 4] {
        let start = self.texel_at(level, at);
        let word = |i: usize| self.words.get(start + i).map_or(0, |w| w.load(Ordering::Relaxed));
        let one_f = 1.0f32.to_bits();
        match self.format {
            TexelFormat::Rgba8Unorm => {
                let bytes = word(0).to_le_bytes();
                bytes.map(|c| (f32::from(c) / 255.0).to_bits())
            }
            TexelFormat::Rgba8Uint => word(0).to_le_bytes().map(u32::from),
            TexelFormat::Rgba16Float => {
                let (a, b) = (word(0), word(1));
                [a & 0xffff, a >> 16, b & 0xffff, b >> 16].map(f16_to_f32)
            }
            TexelFormat::Rgba32Float => [word(0), word(1), word(2), word(3)],
            TexelFormat::R32Float => [word(0), 0, 0, one_f],
            TexelFormat::R32Uint | TexelFormat::R32Sint => [word(0), 0, 0, 1],
        }
    }

    /// Writes `value` (four components of the format's kind) to texel `at` of level 0.
    fn write(&self, at: [u32; 3], value: [u32; 4]) {
        let start = self.texel_at(0, at);
        let put = |i: usize, word: u32| {
            if let Some(w) = self.words.get(start + i) {
                w.store(word, Ordering::Relaxed);
            }
        };
        match self.format {
            TexelFormat::Rgba8Unorm => put(0, u32::from_le_bytes(value.map(unorm8))),
            TexelFormat::Rgba8Uint => put(0, u32::from_le_bytes(value.map(|c| c as u8))),
            TexelFormat::Rgba16Float => {
                let h = value.map(f32_to_f16);
                put(0, h[0] | h[1] << 16);
                put(1, h[2] | h[3] << 16);
            }
            TexelFormat::Rgba32Float => (0..4).for_each(|i| put(i, value[i])),
            TexelFormat::R32Float | TexelFormat::R32Uint | TexelFormat::R32Sint => put(0, value[0]),
        }
    }
}

/// Vulkan's float → 8-bit unorm: clamp to [0, 1] (NaN to 0), scale, round to nearest,
/// ties to even (Vulkan allows either neighbour and prefers the nearest; lavapipe
/// rounds ties to even, and so does every GPU path measured here).
fn unorm8(bits: u32) -> u8 {
    let f = f32::from_bits(bits);
    let f = if f.is_nan() { 0.0 } else { f.clamp(0.0, 1.0) };
    (f * 255.0).round_ties_even() as u8
}

/// Executes an image instruction for one invocation.
pub(super) fn execute(insn: &ImageInsn, regs: &mut LaneRegs, buffers: &[Vec<AtomicU32>]) {
    let slot = |reg: Reg| (regs[reg as usize] & 0x00ff_ffff) as usize;
    let Some(texture) = buffers.get(slot(insn.image)).and_then(|words| Texture::of(words)) else {
        return;
    };
    let result = insn.result as usize;
    let n = insn.coordinates as usize;
    let layered = texture.dimension == TextureDimension::D2Array;
    // Integer coordinates `[x, y, z-or-layer]` of `level`, if the level and all of them
    // are in range (compared unsigned: a negative value is out of range).
    let in_range = |regs: &LaneRegs, level: u32| -> Option<[u32; 3]> {
        if level >= texture.levels {
            return None;
        }
        let size = texture.level_size(level);
        let mut at = [0u32; 3];
        for (i, a) in at.iter_mut().enumerate().take(n) {
            *a = regs[insn.coordinate as usize + i];
        }
        if let Some(layer) = insn.layer {
            at[2] = regs[layer as usize];
        }
        at.iter().zip(size).all(|(&a, s)| a < s).then_some(at)
    };
    match insn.op {
        ImageOp::Load => {
            let level = insn.level.map_or(0, |l| regs[l as usize]);
            let texel = in_range(regs, level).map_or([0; 4], |at| texture.read(level, at));
            regs.write(result, &texel);
        }
        ImageOp::Store => {
            if let Some(at) = in_range(regs, 0) {
                let v = insn.value as usize;
                texture.write(at, [regs[v], regs[v + 1], regs[v + 2], regs[v + 3]]);
            }
        }
        ImageOp::Size => {
            let level = insn.level.map_or(0, |l| regs[l as usize].min(texture.levels - 1));
            let size = texture.level_size(level);
            let axes = texture.dimension.coordinates() as usize;
            regs.write(result, &size[..axes]);
        }
        ImageOp::NumLevels => regs[result] = texture.levels,
        ImageOp::NumLayers => regs[result] = if layered { texture.size[2] } else { 1 },
        ImageOp::SampleLevel | ImageOp::Gather(_) => {
            let Some(words) = buffers.get(slot(insn.sampler)).filter(|w| w.len() >= SAMPLER_WORDS) else {
                return;
            };
            let sampler: [u32; SAMPLER_WORDS] = std::array::from_fn(|i| words[i].load(Ordering::Relaxed));
            let coordinate: [f32; 3] =
                std::array::from_fn(|i| if i < n { f32::from_bits(regs[insn.coordinate as usize + i]) } else { 0.0 });
            let layer = insn.layer.map(|l| regs[l as usize].min(texture.size[2] - 1));
            let sample =
                Sample { texture: &texture, sampler: &sampler, coordinate: &coordinate, layer, offset: insn.offset };
            let value = match insn.op {
                ImageOp::Gather(component) => sample.gather(component as usize),
                _ => {
                    let level = insn.level.map_or(0.0, |l| f32::from_bits(regs[l as usize]));
                    sample.level(level)
                }
            };
            regs.write(result, &value.map(f32::to_bits));
        }
    }
}

/// One `textureSampleLevel` or `textureGather`.
struct Sample<'a> {
    texture: &'a Texture<'a>,
    sampler: &'a [u32],
    coordinate: &'a [f32],
    layer: Option<u32>,
    offset: [i32; 3],
}

impl Sample<'_> {
    /// Texel `i` along `axis` of a level `size` texels wide, wrapped by the sampler's
    /// address mode (Vulkan's wrapping of integer texel coordinates).
    fn wrap(&self, axis: usize, i: i64, size: u32) -> u32 {
        let size = i64::from(size);
        let wrapped = match self.sampler[axis] {
            1 => i.rem_euclid(size),
            2 => {
                let t = i.rem_euclid(2 * size);
                if t >= size { 2 * size - 1 - t } else { t }
            }
            _ => i.clamp(0, size - 1),
        };
        wrapped as u32
    }

    /// The texels and weights of the footprint of `level` (1, 2, 4 or 8 of them).
    fn footprint(&self, level: u32, linear: bool) -> Vec<([u32; 3], f32)> {
        let size = self.texture.level_size(level);
        let axes = self.texture.dimension.coordinates() as usize;
        // Per axis: the texels and their weights.
        let mut per_axis: Vec<Vec<(u32, f32)>> = Vec::with_capacity(axes);
        for (axis, &extent) in size.iter().enumerate().take(axes) {
            let u = self.coordinate[axis] * extent as f32 + self.offset[axis] as f32;
            if linear {
                let shifted = u - 0.5;
                let i0 = shifted.floor();
                let alpha = shifted - i0;
                let i0 = i0 as i64;
                per_axis
                    .push(vec![(self.wrap(axis, i0, extent), 1.0 - alpha), (self.wrap(axis, i0 + 1, extent), alpha)]);
            } else {
                per_axis.push(vec![(self.wrap(axis, u.floor() as i64, extent), 1.0)]);
            }
        }
        let mut texels = vec![([0u32, 0, self.layer.unwrap_or(0)], 1.0f32)];
        for (axis, choices) in per_axis.iter().enumerate() {
            texels = texels
                .iter()
                .flat_map(|(at, w)| {
                    choices.iter().map(move |&(i, wi)| {
                        let mut at = *at;
                        at[axis] = i;
                        (at, w * wi)
                    })
                })
                .collect();
        }
        texels
    }

    /// The filtered value of one mip level.
    fn filter(&self, level: u32, linear: bool) -> [f32; 4] {
        let mut sum = [0.0f32; 4];
        for (at, weight) in self.footprint(level, linear) {
            let texel = self.texture.read(level, at).map(f32::from_bits);
            for c in 0..4 {
                sum[c] += weight * texel[c];
            }
        }
        sum
    }

    /// `textureSampleLevel` at explicit level `lambda`.
    fn level(&self, lambda: f32) -> [f32; 4] {
        let last = (self.texture.levels - 1) as f32;
        let lambda = if lambda.is_nan() { 0.0 } else { lambda };
        // Vulkan: magnification at a level of detail of 0 or less, minification above.
        let linear = if lambda <= 0.0 { self.sampler[3] == 1 } else { self.sampler[4] == 1 };
        let d = lambda.clamp(0.0, last);
        if self.sampler[5] == 1 && d.fract() > 0.0 {
            let low = d.floor();
            let t = d - low;
            let (a, b) = (self.filter(low as u32, linear), self.filter(low as u32 + 1, linear));
            [0, 1, 2, 3].map(|c| a[c] * (1.0 - t) + b[c] * t)
        } else {
            // Nearest level: Vulkan's ceil(d + 0.5) - 1, rounding halves down.
            let nearest = ((d + 0.5).ceil() - 1.0).clamp(0.0, last);
            self.filter(nearest as u32, linear)
        }
    }

    /// `textureGather`: component `component` of the four texels of level 0's bilinear
    /// footprint, in Vulkan's order (i0 j1, i1 j1, i1 j0, i0 j0).
    fn gather(&self, component: usize) -> [f32; 4] {
        let texels = self.footprint(0, true);
        // footprint order: (i0 j0), (i0 j1), (i1 j0), (i1 j1) (x outer, y inner).
        let value = |k: usize| f32::from_bits(self.texture.read(0, texels[k].0)[component]);
        [value(1), value(3), value(2), value(0)]
    }
}
