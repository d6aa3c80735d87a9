//! How the compiler turns a load or a store through a pointer into instructions: straight
//! to a local variable's registers, to workgroup, private or buffer memory at an address
//! known when compiling, through a pointer register otherwise, and through a conversion
//! plan where the pointee holds f16 in a buffer's layout.

use super::compiler::{Compiler, Scope};
use super::insn::{Insn, Reg, Runs};
use super::layout::{Piece, Place, byte_addressed, contains_f16, load_plan};
use naga::{Expression, Handle, TypeInner};

impl Compiler<'_> {
    /// The place an expression points to, if known when compiling.
    fn place(&self, scope: &Scope, pointer: Handle<Expression>) -> Option<Place> {
        scope.places[pointer.index()]
    }

    /// How a load or store through `pointer` converts between a buffer's layout and
    /// registers, if its type holds f16 and it points into a buffer.
    fn mixed_plan(&self, scope: &Scope, pointer: Handle<Expression>) -> Option<Box<[Piece]>> {
        let module = self.module;
        let mut plan = Vec::new();
        match *self.ty(scope, pointer) {
            TypeInner::Pointer { base, space } if byte_addressed(space) => {
                let inner = &module.types[base].inner;
                if !contains_f16(module, inner) {
                    return None;
                }
                load_plan(module, inner, 0, 0, &mut plan);
            }
            TypeInner::ValuePointer { size, scalar, space }
                if byte_addressed(space) && scalar.kind == naga::ScalarKind::Float && scalar.width == 2 =>
            {
                let inner = match size {
                    Some(size) => TypeInner::Vector { size, scalar },
                    None => TypeInner::Scalar(scalar),
                };
                load_plan(module, &inner, 0, 0, &mut plan);
            }
            _ => return None,
        }
        Some(plan.into_boxed_slice())
    }

    /// Stores `len` words of register `src` through pointer expression `pointer`.
    pub(super) fn store(&mut self, scope: &mut Scope, pointer: Handle<Expression>, src: Reg, len: u32) {
        if let Some(plan) = self.mixed_plan(scope, pointer) {
            let pointer = self.reg(scope, pointer);
            self.push(Insn::StoreMixed { pointer, src, plan });
            return;
        }
        match self.place(scope, pointer) {
            Some(Place::Local(variable)) => self.copy(variable, src, len),
            Some(Place::Workgroup(address)) => {
                self.push(Insn::StoreWorkgroup { address, src, len });
            }
            Some(Place::Private(address)) => {
                self.push(Insn::StorePrivate { address, src, len });
            }
            Some(Place::Buffer(buffer, bytes)) => {
                self.push(Insn::StoreBuffer { buffer, address: bytes / 4, src, len });
            }
            None => {
                let pointer = self.reg(scope, pointer);
                self.push(Insn::Store { pointer, src, len });
            }
        }
    }

    /// Loads `len` words through pointer expression `pointer` into register `dst`; only
    /// the words of `runs` where given and the pointer is a register (the others are
    /// never read: [`super::load_fields`]).
    pub(super) fn load(
        &mut self,
        scope: &mut Scope,
        pointer: Handle<Expression>,
        dst: Reg,
        len: u32,
        runs: Option<Runs>,
    ) {
        if let Some(plan) = self.mixed_plan(scope, pointer) {
            let pointer = self.reg(scope, pointer);
            self.push(Insn::LoadMixed { dst, pointer, plan });
            return;
        }
        match self.place(scope, pointer) {
            Some(Place::Local(variable)) => self.copy(dst, variable, len),
            Some(Place::Workgroup(address)) => {
                self.push(Insn::LoadWorkgroup { dst, address, len });
            }
            Some(Place::Private(address)) => {
                self.push(Insn::LoadPrivate { dst, address, len });
            }
            Some(Place::Buffer(buffer, bytes)) => {
                self.push(Insn::LoadBuffer { dst, buffer, address: bytes / 4, len });
            }
            None if self.fuse_element_load(scope, pointer, dst, len, &runs) => {}
            None => {
                let pointer = self.reg(scope, pointer);
                self.push(match runs {
                    Some(runs) => Insn::LoadRuns { dst, pointer, len, runs },
                    None => Insn::Load { dst, pointer, len },
                });
            }
        }
    }
}
