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

#[cfg(test)]
mod tests {
    use super::super::decode::tests::{INVOCATIONS, entry_code, kernel_with, run_kernel, run_kernel_bound};
    use super::super::memory;

    /// Whether `template` holds a pointer's words `(tag, address)`.
    fn holds_pointer(template: &[u32], tag: u32, address: u32) -> bool {
        template.windows(2).any(|w| w == [tag, address])
    }

    #[test]
    fn a_pointer_with_a_known_target_gets_a_register_only_where_one_is_read() {
        // Loads and stores at places known when compiling, also through an inlined
        // callee's pointer arguments, read no pointer register: none is set when the
        // frame starts, and `table`'s pointer is not in the template.
        let declarations = "struct Pair { a: u32, b: array<u32, 4> }
            @group(0) @binding(1) var<storage, read> table: array<u32, 4>;
            fn bump(p: ptr<function, u32>, by: u32) { *p = *p * 3u + by; }";
        let body = "var pair: Pair; var v = array<u32, 4>(x, 1u, 2u, 3u);
            pair.a = x + 1u; pair.b[2] = v[0] * 5u; bump(&pair.b[2], 7u); bump(&v[3], x);
            data[id.x] = pair.a + pair.b[2] + v[3] + table[2];";
        let kernel = kernel_with(declarations, body);
        let code = entry_code(&kernel);
        assert_eq!(code.local_pointers.len(), 0, "local pointers set when the frame starts");
        assert!(!code.template.contains(&(memory::BUFFER | 1)), "a pointer into `table` in the template");
        assert!(holds_pointer(&code.template, memory::BUFFER, 0), "`data`, indexed at run time, reads its pointer");
        let expected: Vec<u32> = (0..INVOCATIONS).map(|x| (x + 1) + (x * 5 * 3 + 7) + (3 * 3 + x) + 30).collect();
        assert_eq!(run_kernel_bound(&kernel, &[(1, &[10, 20, 30, 40])]), expected);

        // An index known only at run time reads the variable's pointer: one register,
        // set when the frame starts.
        let body = "var v = array<u32, 4>(x, 1u, 2u, 3u); v[x & 3u] = 9u; data[id.x] = v[0] + v[3];";
        let kernel = kernel_with("", body);
        assert_eq!(entry_code(&kernel).local_pointers.len(), 1);
        let f = |x: u32| {
            let mut v = [x, 1, 2, 3];
            v[(x & 3) as usize] = 9;
            v[0] + v[3]
        };
        assert_eq!(run_kernel(&kernel), (0..INVOCATIONS).map(f).collect::<Vec<_>>());
    }

    #[test]
    fn a_pointer_register_made_where_it_is_read_points_at_its_target() {
        // Each way a pointer with a known target is read as a value: a workgroup and a
        // private array indexed at run time, a local indexed at run time by the caller
        // before an inlined callee indexes it too (the caller's register passed on), a
        // local first indexed at run time inside an inlined callee (the callee makes the
        // register), and that local indexed at run time again inside a branch.
        let declarations = "var<workgroup> w: array<u32, 8>;
            var<private> q: array<u32, 4>;
            fn put(p: ptr<function, array<u32, 4>>, i: u32, value: u32) { (*p)[i] = value; }";
        let body = "w[x & 7u] = x * 2u;
            workgroupBarrier();
            q[x & 3u] = x + 100u;
            var v = array<u32, 4>(0u, 0u, 0u, 0u);
            v[(x + 1u) & 3u] = 5u;
            put(&v, x & 3u, 7u);
            var u = array<u32, 4>(1u, 2u, 3u, 4u);
            put(&u, (x + 2u) & 3u, 40u);
            if (x & 1u) == 1u { u[x & 3u] = 50u; }
            data[id.x] = w[(x + 1u) & 7u] + q[x & 3u] + v[(x + 1u) & 3u] * 1000u + v[x & 3u] * 100u
                + u[0] + u[1] + u[2] + u[3];";
        let kernel = kernel_with(declarations, body);
        // One register for each of `v` and `u`, however many pointers to them are read.
        assert_eq!(entry_code(&kernel).local_pointers.len(), 2);
        let f = |x: u32| {
            // The workgroup's neighbour (8 invocations a workgroup, `x & 7` the local index).
            let w = ((x & !7) + ((x + 1) & 7)) * 2;
            let mut u = [1, 2, 3, 4];
            u[((x + 2) & 3) as usize] = 40;
            if x & 1 == 1 {
                u[(x & 3) as usize] = 50;
            }
            w + (x + 100) + 5 * 1000 + 7 * 100 + u.iter().sum::<u32>()
        };
        assert_eq!(run_kernel(&kernel), (0..INVOCATIONS).map(f).collect::<Vec<_>>());
    }
}
