//! Random WGSL compute programs for fuzzing the CPU interpreter: integer-only, bounded
//! loops, `if`, `switch`, calls of WGSL builtins, every operator, on `u32` and `i32`
//! variables seeded from an input buffer. Every generated program is valid WGSL (no
//! constant expression can overflow or divide by zero: each operator has a variable
//! operand).

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// Variables of a generated program: v0, v2 are `u32`; v1, v3 are `i32`.
const VARIABLES: usize = 4;

fn is_signed(v: usize) -> bool {
    v % 2 == 1
}

struct Generator {
    rng: Pcg64Mcg,
    depth: u32,
}

impl Generator {
    fn literal(&mut self, signed: bool) -> String {
        let choices = [0u32, 1, 2, 7, 31, 32, 255, 0x7fff_ffff, 0x8000_0000, 0xffff_ffff];
        let value = if self.rng.random_bool(0.5) {
            choices[self.rng.random_range(0..choices.len())]
        } else {
            self.rng.random()
        };
        if signed {
            format!("i32({}i)", value as i32).replace("i32(-2147483648i)", "i32(-2147483647i - 1i)")
        } else {
            format!("{value}u")
        }
    }

    fn variable(&mut self, signed: bool) -> String {
        let v = 2 * self.rng.random_range(0..VARIABLES / 2) + usize::from(signed);
        format!("v{v}")
    }

    /// An expression of type i32 (`signed`) or u32 that reads at least one variable.
    fn expression(&mut self, signed: bool, depth: u32) -> String {
        if depth == 0 || self.rng.random_bool(0.25) {
            return self.variable(signed);
        }
        let a = self.expression(signed, depth - 1);
        let other = if self.rng.random_bool(0.6) { self.expression(signed, depth - 1) } else { self.literal(signed) };
        match self.rng.random_range(0..16) {
            0 => format!("({a} + {other})"),
            1 => format!("({a} - {other})"),
            2 => format!("({a} * {other})"),
            3 => format!("({other} / {a})"),
            4 => format!("({other} % {a})"),
            5 => format!("({a} & {other})"),
            6 => format!("({a} | {other})"),
            7 => format!("({a} ^ {other})"),
            8 => format!("({other} << u32({a}))"),
            9 => format!("({other} >> u32({a}))"),
            10 => {
                if signed {
                    format!("(-{a})")
                } else {
                    format!("(~{a})")
                }
            }
            11 => format!("select({a}, {other}, {} < {})", self.expression(signed, depth - 1), self.literal(signed)),
            12 => format!("min({a}, {other})"),
            13 => format!("max({a}, {other})"),
            14 => {
                let f = ["countOneBits", "reverseBits", "firstLeadingBit", "firstTrailingBit", "countLeadingZeros"];
                format!("{}({a})", f[self.rng.random_range(0..f.len())])
            }
            _ => {
                if signed {
                    format!("bitcast<i32>({})", self.expression(false, depth - 1))
                } else {
                    format!("extractBits({a}, {}u, {}u)", self.rng.random_range(0..40), self.rng.random_range(0..40))
                }
            }
        }
    }

    fn statements(&mut self, count: u32, indent: usize, out: &mut String) {
        let pad = " ".repeat(indent);
        for _ in 0..count {
            let v = self.rng.random_range(0..VARIABLES);
            match self.rng.random_range(0..8) {
                0 if self.depth < 2 => {
                    self.depth += 1;
                    let condition = format!("{} < {}", self.expression(false, 2), self.expression(false, 1));
                    out.push_str(&format!("{pad}if {condition} {{\n"));
                    self.statements(2, indent + 4, out);
                    out.push_str(&format!("{pad}}} else {{\n"));
                    self.statements(2, indent + 4, out);
                    out.push_str(&format!("{pad}}}\n"));
                    self.depth -= 1;
                }
                1 if self.depth < 2 => {
                    self.depth += 1;
                    let n = self.rng.random_range(0..6);
                    let i = format!("i{}", self.rng.random::<u16>());
                    out.push_str(&format!("{pad}for (var {i} = 0u; {i} < {n}u; {i}++) {{\n"));
                    out.push_str(&format!("{pad}    v0 += {i};\n"));
                    self.statements(2, indent + 4, out);
                    out.push_str(&format!("{pad}}}\n"));
                    self.depth -= 1;
                }
                2 if self.depth < 2 => {
                    self.depth += 1;
                    out.push_str(&format!("{pad}switch {} % 4u {{\n", self.expression(false, 1)));
                    out.push_str(&format!("{pad}    case 0u: {{\n"));
                    self.statements(1, indent + 8, out);
                    out.push_str(&format!("{pad}    }}\n{pad}    case 1u, 2u: {{\n"));
                    self.statements(1, indent + 8, out);
                    out.push_str(&format!("{pad}    }}\n{pad}    default: {{\n"));
                    self.statements(1, indent + 8, out);
                    out.push_str(&format!("{pad}    }}\n{pad}}}\n"));
                    self.depth -= 1;
                }
                _ => {
                    let value = self.expression(is_signed(v), 3);
                    out.push_str(&format!("{pad}v{v} = {value};\n"));
                }
            }
        }
    }
}

/// A random integer-only compute program (`@workgroup_size(64)`, entry `main`): reads 4
/// words per invocation from binding 0, writes 4 words to binding 1.
pub fn integer_program(seed: u64) -> String {
    let mut generator = Generator { rng: Pcg64Mcg::seed_from_u64(seed), depth: 0 };
    let mut body = String::new();
    let count = generator.rng.random_range(4..12);
    generator.statements(count, 4, &mut body);
    format!(
        "@group(0) @binding(0) var<storage, read> input: array<u32>;
@group(0) @binding(1) var<storage, read_write> output: array<u32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {{
    let base = id.x * 4u;
    var v0: u32 = input[base];
    var v1: i32 = bitcast<i32>(input[base + 1u]);
    var v2: u32 = input[base + 2u];
    var v3: i32 = bitcast<i32>(input[base + 3u]);
{body}    output[base] = v0;
    output[base + 1u] = bitcast<u32>(v1);
    output[base + 2u] = v2;
    output[base + 3u] = bitcast<u32>(v3);
}}
"
    )
}
