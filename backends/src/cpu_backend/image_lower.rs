//! Lowering naga's image expressions and `ImageStore` to [`Insn::Image`]: operand
//! registers resolved and the texture's shape read from the IR once; what the built-ins
//! do at run time is in [`super::image`].

use super::compiler::{Compiler, Scope};
use super::insn::{ImageInsn, ImageOp, Insn};
use crate::error::BackendError;
use naga::{Expression, Handle, SampleLevel, TypeInner};

impl Compiler<'_> {
    /// Lowers an `ImageLoad`, `ImageSample` or `ImageQuery` expression; `Ok(false)` for
    /// any other expression.
    pub(super) fn image_expression(
        &mut self,
        scope: &mut Scope,
        handle: Handle<Expression>,
    ) -> Result<bool, BackendError> {
        let line = self.line;
        let result = self.reg(scope, handle);
        let insn = match scope.function.expressions[handle] {
            Expression::ImageLoad { image, coordinate, array_index, sample, level } => {
                if sample.is_some() {
                    self.fail("textureLoad of a multisampled texture".into(), line);
                    return Ok(true);
                }
                self.image_insn(scope, ImageOp::Load, image, Some(coordinate), array_index, level, result)
            }
            Expression::ImageSample {
                image,
                sampler,
                gather,
                coordinate,
                array_index,
                offset,
                level,
                depth_ref,
                clamp_to_edge,
            } => {
                if depth_ref.is_some() || clamp_to_edge {
                    let what = if clamp_to_edge { "textureSampleBaseClampToEdge" } else { "depth comparison sampling" };
                    self.fail(what.into(), line);
                    return Ok(true);
                }
                let (op, level) = match (gather, level) {
                    (Some(component), SampleLevel::Zero) => (ImageOp::Gather(component as u8), None),
                    (None, SampleLevel::Zero) => (ImageOp::SampleLevel, None),
                    (None, SampleLevel::Exact(level)) => (ImageOp::SampleLevel, Some(level)),
                    (_, other) => {
                        let what = match other {
                            SampleLevel::Bias(_) => "textureSampleBias",
                            SampleLevel::Gradient { .. } => "textureSampleGrad",
                            _ => "implicit-derivative sampling (not in compute shaders)",
                        };
                        self.fail(what.into(), line);
                        return Ok(true);
                    }
                };
                let mut insn = self.image_insn(scope, op, image, Some(coordinate), array_index, level, result);
                insn.sampler = self.reg(scope, sampler);
                if let Some(offset) = offset {
                    match self.constant_words(scope, offset) {
                        Some(words) => {
                            for (i, word) in words.iter().enumerate().take(3) {
                                insn.offset[i] = *word as i32;
                            }
                        }
                        None => {
                            self.fail("a sampling offset that is not a constant".into(), line);
                            return Ok(true);
                        }
                    }
                }
                insn
            }
            Expression::ImageQuery { image, query } => {
                let (op, level) = match query {
                    naga::ImageQuery::Size { level } => (ImageOp::Size, level),
                    naga::ImageQuery::NumLevels => (ImageOp::NumLevels, None),
                    naga::ImageQuery::NumLayers => (ImageOp::NumLayers, None),
                    naga::ImageQuery::NumSamples => {
                        self.fail("textureNumSamples (multisampled textures)".into(), line);
                        return Ok(true);
                    }
                };
                self.image_insn(scope, op, image, None, None, level, result)
            }
            _ => return Ok(false),
        };
        self.line = line;
        self.push(Insn::Image(Box::new(insn)));
        Ok(true)
    }

    /// Lowers `textureStore(image, coordinate[, array_index], value)`.
    pub(super) fn image_store(
        &mut self,
        scope: &mut Scope,
        image: Handle<Expression>,
        coordinate: Handle<Expression>,
        array_index: Option<Handle<Expression>>,
        value: Handle<Expression>,
    ) -> Result<(), BackendError> {
        let line = self.line;
        let mut insn = self.image_insn(scope, ImageOp::Store, image, Some(coordinate), array_index, None, 0);
        insn.value = self.reg(scope, value);
        self.line = line;
        self.push(Insn::Image(Box::new(insn)));
        Ok(())
    }

    #[allow(clippy::too_many_arguments)]
    fn image_insn(
        &mut self,
        scope: &mut Scope,
        op: ImageOp,
        image: Handle<Expression>,
        coordinate: Option<Handle<Expression>>,
        array_index: Option<Handle<Expression>>,
        level: Option<Handle<Expression>>,
        result: u32,
    ) -> ImageInsn {
        let coordinates = coordinate.map_or(0, |c| match self.ty(scope, c) {
            TypeInner::Vector { size, .. } => *size as u8,
            _ => 1,
        });
        ImageInsn {
            op,
            image: self.reg(scope, image),
            sampler: 0,
            coordinate: coordinate.map_or(0, |c| self.reg(scope, c)),
            coordinates,
            layer: array_index.map(|a| self.reg(scope, a)),
            level: level.map(|l| self.reg(scope, l)),
            value: 0,
            offset: [0; 3],
            result,
        }
    }

    /// The words of a constant expression of `scope` (in the register template).
    fn constant_words(&mut self, scope: &mut Scope, handle: Handle<Expression>) -> Option<Vec<u32>> {
        if !scope.constant[handle.index()] {
            return None;
        }
        let reg = self.reg(scope, handle) as usize;
        Some(self.template[reg..reg + scope.lens[handle.index()] as usize].to_vec())
    }
}
