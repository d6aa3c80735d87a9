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

/// What a generated float program may compute.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FloatMode {
    /// Only IEEE-exact operations (+ − × ÷ sqrt, comparisons, min/max against a non-zero
    /// literal, floor/ceil/trunc/round, abs, negation, mantissa masking, conversions of
    /// small integers) on values kept finite and free of NaN: every value is bounded
    /// (the generator tracks a bound on each expression's magnitude, divides only by
    /// `abs(y) + 1`, takes `sqrt` only of `abs(x)`, and clamps every assignment to
    /// ±2²⁴), so the results are defined bit for bit on any IEEE-conforming device.
    ///
    /// Every arithmetic result goes through `o(x)`, an XOR of its bits with a word the
    /// program reads from the last input element (which must be 0): the compiler cannot
    /// see through it, so it cannot contract `a * b + c` into an FMA nor apply the
    /// algebraic rewrites that change rounding (Mesa rewrites `x + (y - x)` to `y`,
    /// reassociates constants, distributes products) to the program as a whole. The sign
    /// of a zero is not defined (lavapipe folds `f32(i32(x))` into `trunc(x)`).
    Exact,
    /// Everything: transcendentals, `pow`, `fma`, vectors, NaN and infinities from the
    /// inputs, comparisons of NaN; only that the interpreter does not crash is defined.
    General,
}

/// The largest exponent (log2 of the magnitude) an exact-mode expression may reach.
const EXACT_BOUND: i32 = 100;

struct FloatGenerator {
    rng: Pcg64Mcg,
    mode: FloatMode,
    depth: u32,
    loops: u32,
}

impl FloatGenerator {
    fn pick<'a>(&mut self, choices: &[&'a str]) -> &'a str {
        choices[self.rng.random_range(0..choices.len())]
    }

    /// A literal and the log2 of its magnitude.
    fn literal(&mut self) -> (String, i32) {
        let exact: [(&str, i32); 10] = [
            ("0.0f", 0),
            ("(-0.0f)", 0),
            ("1.0f", 0),
            ("(-1.0f)", 0),
            ("0.5f", 0),
            ("3.0f", 2),
            ("(-2.75f)", 2),
            ("1024.0f", 10),
            ("1e-20f", 0),
            ("16777216.0f", 24),
        ];
        let general = ["3.4e38f", "(-3.4e38f)", "1e-38f", "6.2831855f", "0.1f", "(-7.5f)", "100.0f"];
        if self.mode == FloatMode::General && self.rng.random_bool(0.4) {
            (self.pick(&general).to_string(), 128)
        } else {
            let (text, bound) = exact[self.rng.random_range(0..exact.len())];
            (text.to_string(), bound)
        }
    }

    /// A non-zero literal for `min`/`max` (so that ±0 operands are never compared).
    fn nonzero_literal(&mut self) -> (String, i32) {
        loop {
            let (text, bound) = self.literal();
            if !text.contains("0.0f") {
                return (text, bound);
            }
        }
    }

    fn variable(&mut self) -> (String, i32) {
        if self.mode == FloatMode::General && self.rng.random_bool(0.15) {
            return (format!("w.{}", self.pick(&["x", "y", "z"])), 128);
        }
        (format!("f{}", self.rng.random_range(0..4)), 24)
    }

    /// A condition comparing two float expressions.
    fn condition(&mut self, depth: u32) -> String {
        let (a, _) = self.expression(depth);
        let (b, _) = if self.rng.random_bool(0.5) { self.expression(depth) } else { self.literal() };
        let op = self.pick(&["<", "<=", ">", ">=", "==", "!="]);
        format!("{a} {op} {b}")
    }

    /// An f32 expression that reads at least one variable, and (exact mode) a bound on
    /// log2 of its magnitude.
    fn expression(&mut self, depth: u32) -> (String, i32) {
        if depth == 0 || self.rng.random_bool(0.2) {
            return self.variable();
        }
        let (a, ba) = self.expression(depth - 1);
        let (b, bb) = if self.rng.random_bool(0.6) { self.expression(depth - 1) } else { self.literal() };
        let candidate = match self.mode {
            FloatMode::Exact => self.exact_operation(depth, (&a, ba), (&b, bb)),
            FloatMode::General => return (self.general_operation(depth, &a, &b), 128),
        };
        if candidate.1 > EXACT_BOUND { (a, ba) } else { candidate }
    }

    fn exact_operation(&mut self, depth: u32, (a, ba): (&str, i32), (b, bb): (&str, i32)) -> (String, i32) {
        match self.rng.random_range(0..14) {
            0 => (format!("o({a} + {b})"), ba.max(bb) + 1),
            1 => (format!("o({a} - {b})"), ba.max(bb) + 1),
            2 | 3 => (format!("o({a} * {b})"), ba + bb.max(1)),
            4 => (format!("o({a} / o(abs({b}) + 1.0f))"), ba),
            5 => (format!("o(sqrt(abs({a})))"), ba / 2 + 1),
            6 => {
                let (l, bl) = self.nonzero_literal();
                (format!("{}({a}, {l})", self.pick(&["min", "max"])), ba.max(bl))
            }
            7 => {
                let f = self.pick(&["floor", "ceil", "trunc", "round", "abs"]);
                (format!("{f}({a})"), ba.max(1))
            }
            8 => (format!("(-{a})"), ba),
            9 => {
                let condition = self.condition(depth - 1);
                (format!("select({a}, {b}, {condition})"), ba.max(bb))
            }
            10 => (format!("bitcast<f32>(bitcast<u32>({a}) & 0xffff0000u)"), ba),
            11 if ba <= 24 => (format!("f32(i32({a}))"), ba),
            12 if ba <= 24 => (format!("f32(u32(abs({a})))"), ba),
            _ => (format!("o({a} + {b})"), ba.max(bb) + 1),
        }
    }

    fn general_operation(&mut self, depth: u32, a: &str, b: &str) -> String {
        match self.rng.random_range(0..20) {
            0 => format!("({a} + {b})"),
            1 => format!("({a} - {b})"),
            2 => format!("({a} * {b})"),
            3 => format!("({b} / {a})"),
            4 => format!("(-{a})"),
            5 => {
                let condition = self.condition(depth - 1);
                format!("select({a}, {b}, {condition})")
            }
            6 | 7 => {
                let f = self.pick(&[
                    "sqrt",
                    "inverseSqrt",
                    "exp",
                    "exp2",
                    "log",
                    "log2",
                    "sin",
                    "cos",
                    "tan",
                    "atan",
                    "asin",
                    "acos",
                    "sinh",
                    "cosh",
                    "tanh",
                    "floor",
                    "ceil",
                    "round",
                    "trunc",
                    "fract",
                    "abs",
                    "sign",
                    "saturate",
                    "radians",
                    "degrees",
                    "asinh",
                    "acosh",
                    "atanh",
                ]);
                format!("{f}({a})")
            }
            8 => format!("{}({a}, {b})", self.pick(&["pow", "min", "max", "atan2", "step"])),
            9 => format!("clamp({a}, {b}, {})", self.literal().0),
            10 => format!("mix({a}, {b}, {})", self.expression(depth - 1).0),
            11 => format!("fma({a}, {b}, {})", self.expression(depth - 1).0),
            12 => {
                let f = self.pick(&[
                    "length(w)",
                    "normalize(w).y",
                    "dot(w, w)",
                    "distance(w, vec3<f32>(1.0f, 2.0f, 3.0f))",
                    "reflect(w, vec3<f32>(0.0f, 1.0f, 0.0f)).x",
                    "refract(normalize(w), vec3<f32>(0.0f, 1.0f, 0.0f), 0.7f).y",
                    "faceForward(w, w, vec3<f32>(1.0f, 0.0f, 0.0f)).z",
                    "ldexp(w.x, i32(w.y) % 64)",
                ]);
                format!("({a} + {f})")
            }
            13 => format!("dot(w, vec3<f32>({a}, {b}, 0.5f))"),
            14 => format!("cross(w, vec3<f32>({a}, {b}, 1.0f)).z"),
            15 => format!("f32(i32({a}))"),
            16 => format!("f32(u32({a}))"),
            17 => format!("bitcast<f32>(bitcast<u32>({a}) ^ {}u)", self.rng.random::<u32>() & 0x807f_ffff),
            18 => format!("smoothstep(0.0f, 1.0f, {a})"),
            _ => format!("modf({a}).fract + frexp({b}).fract"),
        }
    }

    fn assignment(&mut self, pad: &str, out: &mut String) {
        let v = self.rng.random_range(0..4);
        let (value, _) = self.expression(3);
        match self.mode {
            FloatMode::Exact => out.push_str(&format!("{pad}f{v} = clamp({value}, -16777216.0f, 16777216.0f);\n")),
            FloatMode::General => match self.rng.random_range(0..6) {
                0 => out.push_str(&format!("{pad}w = w * {value} + vec3<f32>(f0, f1, f2);\n")),
                1 => out.push_str(&format!("{pad}n ^= i32({value});\n")),
                2 => {
                    out.push_str(&format!("{pad}w = {}(w, vec3<f32>({value}));\n", self.pick(&["min", "max", "step"])))
                }
                _ => out.push_str(&format!("{pad}f{v} = {value};\n")),
            },
        }
    }

    fn statements(&mut self, count: u32, indent: usize, out: &mut String) {
        let pad = " ".repeat(indent);
        for _ in 0..count {
            match self.rng.random_range(0..8) {
                0 if self.depth < 2 => {
                    self.depth += 1;
                    let condition = self.condition(2);
                    out.push_str(&format!("{pad}if {condition} {{\n"));
                    self.statements(2, indent + 4, out);
                    out.push_str(&format!("{pad}}} else {{\n"));
                    self.statements(1, indent + 4, out);
                    out.push_str(&format!("{pad}}}\n"));
                    self.depth -= 1;
                }
                1 if self.depth < 2 => {
                    self.depth += 1;
                    self.loops += 1;
                    let i = format!("i{}", self.loops);
                    let n = self.rng.random_range(0..6);
                    out.push_str(&format!("{pad}for (var {i} = 0u; {i} < {n}u; {i}++) {{\n"));
                    let v = self.rng.random_range(0..4);
                    out.push_str(&format!("{pad}    f{v} = o(f{v} + o(f32({i}) * 0.5f));\n"));
                    self.statements(2, indent + 4, out);
                    out.push_str(&format!("{pad}}}\n"));
                    self.depth -= 1;
                }
                2 if self.depth < 2 => {
                    // A loop whose exit depends on float values (NaN included), with a guard.
                    self.depth += 1;
                    self.loops += 1;
                    let guard = format!("g{}", self.loops);
                    let condition = self.condition(1);
                    let limit = self.rng.random_range(1..8);
                    out.push_str(&format!("{pad}var {guard} = 0u;\n{pad}loop {{\n"));
                    out.push_str(&format!("{pad}    if {condition} || {guard} >= {limit}u {{ break; }}\n"));
                    out.push_str(&format!("{pad}    {guard}++;\n"));
                    self.statements(2, indent + 4, out);
                    out.push_str(&format!("{pad}}}\n"));
                    self.depth -= 1;
                }
                _ => self.assignment(&pad, out),
            }
        }
    }
}

/// A random f32 compute program (`@workgroup_size(64)`, entry `main`): reads 4 words per
/// invocation from binding 0 (as f32 bit patterns), writes 8 words per invocation to
/// binding 1 (f0..f3, w.xyz, n). See [`FloatMode`] for what each mode computes; an
/// exact-mode program needs the last input word to be 0.
pub fn float_program(seed: u64, mode: FloatMode) -> String {
    let mut generator = FloatGenerator { rng: Pcg64Mcg::seed_from_u64(seed), mode, depth: 0, loops: 0 };
    let mut body = String::new();
    let count = generator.rng.random_range(4..12);
    generator.statements(count, 4, &mut body);
    let load = |k: u32| match mode {
        FloatMode::Exact => format!("clamp(bitcast<f32>(input[base + {k}u]), -16777216.0f, 16777216.0f)"),
        FloatMode::General => format!("bitcast<f32>(input[base + {k}u])"),
    };
    let (f0, f1, f2, f3) = (load(0), load(1), load(2), load(3));
    let key_mask = if mode == FloatMode::Exact { u32::MAX } else { 0 };
    format!(
        "@group(0) @binding(0) var<storage, read> input: array<u32>;
@group(0) @binding(1) var<storage, read_write> output: array<u32>;

var<private> key: u32;

// The identity, opaque to the compiler (`key` is 0 at run time).
fn o(x: f32) -> f32 {{
    return bitcast<f32>(bitcast<u32>(x) ^ key);
}}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {{
    let base = id.x * 4u;
    key = input[arrayLength(&input) - 1u] & {key_mask}u;
    var f0: f32 = {f0};
    var f1: f32 = {f1};
    var f2: f32 = {f2};
    var f3: f32 = {f3};
    var w = vec3<f32>(f3, f2, f1);
    var n = 0i;
{body}    let out = id.x * 8u;
    output[out] = bitcast<u32>(f0);
    output[out + 1u] = bitcast<u32>(f1);
    output[out + 2u] = bitcast<u32>(f2);
    output[out + 3u] = bitcast<u32>(f3);
    output[out + 4u] = bitcast<u32>(w.x);
    output[out + 5u] = bitcast<u32>(w.y);
    output[out + 6u] = bitcast<u32>(w.z);
    output[out + 7u] = bitcast<u32>(n);
}}
"
    )
}

/// Workgroup sizes [`barrier_program`] picks from.
const BARRIER_SIZES: [u32; 9] = [1, 2, 7, 32, 63, 64, 100, 128, 256];

/// The operation each element of a barrier program's `totals` gets, whichever workgroup
/// or phase applies it (so that the order between workgroups does not matter), and the
/// element's initial value.
pub const TOTALS: [(&str, u32); 8] = [
    ("atomicAdd", 0),
    ("atomicAdd", 0),
    ("atomicXor", 0),
    ("atomicOr", 0),
    ("atomicMax", 0),
    ("atomicMin", u32::MAX),
    ("atomicAnd", u32::MAX),
    ("atomicSub", 0),
];

/// A random integer compute program exchanging data between invocations through
/// `var<workgroup>` memory and storage memory across `workgroupBarrier`,
/// `storageBarrier` and `workgroupUniformLoad`, with atomics on workgroup and storage
/// memory (including a `atomicCompareExchangeWeak` loop), all in uniform control flow
/// and schedule-independent: every read of shared memory comes after a barrier that
/// follows the writes it sees, every atomic is used commutatively and its result read
/// only after a barrier. Returns the source and its workgroup size S; the program runs
/// on any number W of workgroups with bindings 0: `input`, W·S words; 1: `output`,
/// 2·W·S words (the second half is scratch); 2: `totals`, 8 atomics initialised as
/// [`TOTALS`] says.
pub fn barrier_program(seed: u64) -> (String, u32) {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let size = BARRIER_SIZES[rng.random_range(0..BARRIER_SIZES.len())];
    let pow2 = size.next_power_of_two();
    let mut body = String::new();
    let ops = ["+", "^", "|", "*"];
    for _ in 0..rng.random_range(3..9) {
        let op = ops[rng.random_range(0..ops.len())];
        match rng.random_range(0..8) {
            0 => {
                let (p, r) = (rng.random_range(1..300u32), rng.random_range(0..300u32));
                body.push_str(&format!(
                    "    a[l] = x;\n    workgroupBarrier();\n    x = x {op} a[(l * {p}u + {r}u) % S];\n    workgroupBarrier();\n"
                ));
            }
            1 => body.push_str(&format!(
                "    a[l] = x;
    workgroupBarrier();
    for (var s = {half}u; s > 0u; s >>= 1u) {{
        if l < s && l + s < S {{
            a[l] = a[l] {op} a[l + s];
        }}
        workgroupBarrier();
    }}
    x = (x ^ a[0]) + l;
    workgroupBarrier();
",
                half = pow2 / 2
            )),
            2 => {
                let f = ["atomicAdd", "atomicMax", "atomicMin", "atomicXor", "atomicOr", "atomicAnd", "atomicSub"];
                let f = f[rng.random_range(0..f.len())];
                let k = rng.random_range(0..4);
                body.push_str(&format!(
                    "    {f}(&counters[{k}], x);\n    workgroupBarrier();\n    x = x * 3u + atomicLoad(&counters[{k}]);\n    workgroupBarrier();\n"
                ));
            }
            3 => {
                let k = rng.random_range(0..4);
                body.push_str(&format!(
                    "    {{
        var old = atomicLoad(&counters[{k}]);
        for (var t = 0u; t < 1000000u; t++) {{
            let r = atomicCompareExchangeWeak(&counters[{k}], old, old + (x & 1023u));
            if r.exchanged {{ break; }}
            old = r.old_value;
        }}
    }}
    workgroupBarrier();
    x ^= atomicLoad(&counters[{k}]);
    workgroupBarrier();
"
                ));
            }
            4 => body.push_str(&format!(
                "    if l == {leader}u {{ shared_value = x % 4u + 1u; }}
    let u{seed_step} = workgroupUniformLoad(&shared_value);
    for (var i = 0u; i < u{seed_step}; i++) {{
        a[l] = x;
        workgroupBarrier();
        x = x {op} a[(l + i + 1u) % S];
        workgroupBarrier();
    }}
    workgroupBarrier();
",
                leader = rng.random_range(0..size),
                seed_step = body.len()
            )),
            5 => body.push_str(&format!(
                "    output[n + gid.x] = x;\n    storageBarrier();\n    x = x {op} output[n + wg.x * S + (l + {r}u) % S];\n    storageBarrier();\n",
                r = rng.random_range(0..size)
            )),
            6 => {
                let k = rng.random_range(0..TOTALS.len());
                body.push_str(&format!("    {}(&totals[{k}], x);\n", TOTALS[k].0));
            }
            _ => body.push_str("    if x % 3u == 0u { x = x * 2654435761u; } else { x = (x >> 3u) ^ l; }\n"),
        }
    }
    let source = format!(
        "const S: u32 = {size}u;

@group(0) @binding(0) var<storage, read> input: array<u32>;
@group(0) @binding(1) var<storage, read_write> output: array<u32>;
@group(0) @binding(2) var<storage, read_write> totals: array<atomic<u32>, 8>;

var<workgroup> a: array<u32, S>;
var<workgroup> counters: array<atomic<u32>, 4>;
var<workgroup> shared_value: u32;

@compute @workgroup_size(S)
fn main(@builtin(local_invocation_index) l: u32, @builtin(global_invocation_id) gid: vec3<u32>,
        @builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {{
    let n = groups.x * S;
    var x = input[gid.x];
    if l == 0u {{
        for (var k = 0u; k < 4u; k++) {{ atomicStore(&counters[k], k * 77u); }}
    }}
    workgroupBarrier();
{body}    atomicAdd(&totals[0], x);
    output[gid.x] = x;
}}
"
    );
    (source, size)
}
