//! naga's zero-initialisation of workgroup arrays in GLSL, rewritten as loops.
//!
//! Since `translate` zeroes workgroup memory in loops in naga's IR before the writer
//! (`workgroup_zero_loops`), the writer's constructors remain only where no loop could be
//! written there; this text rewrite is kept for those.
//!
//! WGSL promises zeroed workgroup memory, so naga's GLSL starts each entry point with
//! one statement per workgroup variable, written by one invocation before a barrier. For
//! an array that statement is one constructor with an argument per element
//! (`shared_local = uint[1024](0u, 0u, ... 0u);`, 1024 arguments). glslang, Mesa and
//! LLVM then spend minutes on it: on lavapipe the three block-histogram kernels took
//! 0.8 to 3.4 minutes each to compile on the `ash-glsl` path against seconds on the
//! HLSL paths, which zero in loops ([`crate::hlsl_zero_init`]); it was most of a first
//! `cargo xtask check` (BENCHMARKS.md). Each such statement whose elements are all the
//! same text becomes nested loops assigning that element:
//! `for (uint _zi0 = 0u; _zi0 < 1024u; ++_zi0) { shared_local[_zi0] = 0u; }`. Assigning
//! one value to every element in order is what the constructor did, so the rewrite
//! keeps the meaning of any statement it matches; everything else is left as it is.

/// `glsl` with every `NAME = T[a]...[b](X, X, ...);` statement whose innermost elements
/// are all the same text `X` rewritten as loops (module documentation).
pub fn zero_init_as_loops(glsl: &str) -> String {
    let mut out = String::with_capacity(glsl.len());
    for line in glsl.split_inclusive('\n') {
        match array_fill(line) {
            Some(rewritten) => out.push_str(&rewritten),
            None => out.push_str(line),
        }
    }
    out
}

/// The loops for one line `INDENT NAME = T[a][b](...);` whose elements are one text.
fn array_fill(line: &str) -> Option<String> {
    let body = line.trim_end_matches(['\n', '\r']);
    let ending = &line[body.len()..];
    let indent = &body[..body.len() - body.trim_start().len()];
    let (name, value) = body.trim().split_once(" = ")?;
    let value = value.strip_suffix(';')?;
    if name.is_empty() || !name.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_') {
        return None;
    }
    let (dims, element) = fill_of(value)?;
    if dims.is_empty() || contains_word(&element, name) {
        return None;
    }
    let mut text = String::from(indent);
    let mut index = String::new();
    for (depth, dim) in dims.iter().enumerate() {
        text += &format!("for (uint _zi{depth} = 0u; _zi{depth} < {dim}u; ++_zi{depth}) {{ ");
        index += &format!("[_zi{depth}]");
    }
    text += &format!("{name}{index} = {element}; ");
    text += &"} ".repeat(dims.len());
    Some(text.trim_end().to_string() + ending)
}

/// For an array constructor `T[a][b](...)` every innermost element of which is the same
/// text: the dimensions `[a, b]` and that element. `None` for anything else.
fn fill_of(value: &str) -> Option<(Vec<u64>, String)> {
    let open = value.find('(')?;
    let (type_text, rest) = value.split_at(open);
    let dims = dimensions(type_text)?;
    let arguments = rest.strip_prefix('(')?.strip_suffix(')')?;
    let elements = split_top_level(arguments)?;
    if elements.len() as u64 != dims[0] {
        return None;
    }
    let first = elements[0].trim();
    if elements.iter().any(|e| e.trim() != first) {
        return None;
    }
    if dims.len() == 1 {
        // An element that is itself an array constructor stays whole (the type said one
        // dimension); a plain value is what is assigned.
        return Some((dims, first.to_string()));
    }
    let (inner_dims, element) = fill_of(first)?;
    if inner_dims != dims[1..] {
        return None;
    }
    Some((dims, element))
}

/// The sizes of `T[a][b]...` (at least one), `None` if it is not that form.
fn dimensions(type_text: &str) -> Option<Vec<u64>> {
    let bracket = type_text.find('[')?;
    let (element, mut rest) = type_text.split_at(bracket);
    if element.is_empty() || !element.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_') {
        return None;
    }
    let mut dims = Vec::new();
    while !rest.is_empty() {
        let inner = rest.strip_prefix('[')?;
        let close = inner.find(']')?;
        dims.push(inner[..close].parse::<u64>().ok().filter(|&n| n > 0)?);
        rest = &inner[close + 1..];
    }
    Some(dims)
}

/// `text` split at its commas outside parentheses and brackets; `None` if they do not
/// balance.
fn split_top_level(text: &str) -> Option<Vec<&str>> {
    let mut parts = Vec::new();
    let (mut depth, mut start) = (0i32, 0);
    for (i, c) in text.char_indices() {
        match c {
            '(' | '[' => depth += 1,
            ')' | ']' => {
                depth -= 1;
                if depth < 0 {
                    return None;
                }
            }
            ',' if depth == 0 => {
                parts.push(&text[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    (depth == 0).then(|| {
        parts.push(&text[start..]);
        parts
    })
}

/// Whether `word` occurs in `text` as a whole identifier.
fn contains_word(text: &str, word: &str) -> bool {
    text.match_indices(word).any(|(at, _)| {
        let ident = |c: char| c.is_ascii_alphanumeric() || c == '_';
        let before = text[..at].chars().next_back().is_some_and(ident);
        let after = text[at + word.len()..].chars().next().is_some_and(ident);
        !before && !after
    })
}

#[cfg(test)]
mod tests {
    use super::zero_init_as_loops;

    #[test]
    fn zeroing_constructors_become_loops_and_the_rest_is_kept() {
        let zeros = |n: usize, z: &str| vec![z; n].join(", ");
        let glsl = format!(
            "    if (gl_LocalInvocationID == uvec3(0u)) {{\n        shared_local = uint[4]({});\n        \
             keys = uvec2[3]({});\n        grid = float[2][3]({});\n        counter = 0u;\n        \
             mixed = uint[2](0u, 1u);\n    }}\n",
            zeros(4, "0u"),
            zeros(3, "uvec2(0u)"),
            zeros(2, &format!("float[3]({})", zeros(3, "0.0")))
        );
        let out = zero_init_as_loops(&glsl);
        assert!(
            out.contains("        for (uint _zi0 = 0u; _zi0 < 4u; ++_zi0) { shared_local[_zi0] = 0u; }\n"),
            "{out}"
        );
        assert!(out.contains("for (uint _zi0 = 0u; _zi0 < 3u; ++_zi0) { keys[_zi0] = uvec2(0u); }"), "{out}");
        let nested = "for (uint _zi0 = 0u; _zi0 < 2u; ++_zi0) { for (uint _zi1 = 0u; _zi1 < 3u; ++_zi1) { \
                      grid[_zi0][_zi1] = 0.0; } }";
        assert!(out.contains(nested), "{out}");
        assert!(out.contains("        counter = 0u;\n") && out.contains("mixed = uint[2](0u, 1u);"), "{out}");
        // A count that does not match the type, or an element naming the array: kept.
        for kept in ["    a = uint[3](0u, 0u);\n", "    a = uint[2](a[1], a[1]);\n"] {
            assert_eq!(zero_init_as_loops(kept), kept);
        }
    }
}
