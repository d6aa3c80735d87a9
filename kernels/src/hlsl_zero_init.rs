//! naga's zero-initialisation of workgroup arrays, rewritten as loops that glslang's and
//! Slang's HLSL front ends accept.
//!
//! WGSL promises zeroed workgroup memory, so naga's HLSL starts each entry point with
//! `NAME = (T[4][128])0;` for every workgroup array (written by one invocation, then a
//! barrier). DXC accepts that cast; glslang (12.0) refuses it ("array constructor needs
//! one argument per array element") and Slang refuses it for arrays of arrays ("type
//! mismatch"). Without the zeroing, a kernel that counts into a workgroup variable read
//! garbage on the glslang HLSL path (1690510940 instead of 64). So each such statement
//! becomes nested loops over the array's dimensions assigning `(T)0` to each element,
//! which all three compilers take: `{ for (uint _zi0 = 0u; _zi0 < 4u; ++_zi0) ... }`,
//! braced because HLSL's `for` variables outlive the loop. Scalars, vectors and structs
//! keep naga's `(T)0`, which every front end accepts.

/// `hlsl` with every `NAME = (T[N]...[M])0;` statement rewritten as loops (module
/// documentation); everything else unchanged.
pub fn zero_init_as_loops(hlsl: &str) -> String {
    let mut out = String::with_capacity(hlsl.len());
    for line in hlsl.split_inclusive('\n') {
        match array_zeroing(line) {
            Some(rewritten) => out.push_str(&rewritten),
            None => out.push_str(line),
        }
    }
    out
}

/// The loops for one line of the form `INDENT NAME = (T[a][b]...)0;`, if it is one.
fn array_zeroing(line: &str) -> Option<String> {
    let body = line.trim_end_matches(['\n', '\r']);
    let ending = &line[body.len()..];
    let indent = &body[..body.len() - body.trim_start().len()];
    let (name, cast) = body.trim().split_once(" = (")?;
    let element_and_dims = cast.strip_suffix(")0;")?;
    if name.is_empty() || !name.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'.') {
        return None;
    }
    let first_bracket = element_and_dims.find('[')?;
    let (element, dims_text) = element_and_dims.split_at(first_bracket);
    let mut dims = Vec::new();
    let mut rest = dims_text;
    while let Some(after) = rest.strip_prefix('[') {
        let (count, tail) = after.split_once(']')?;
        if count.is_empty() || !count.bytes().all(|b| b.is_ascii_digit()) {
            return None;
        }
        dims.push(count);
        rest = tail;
    }
    if !rest.is_empty() || dims.is_empty() || element.is_empty() {
        return None;
    }
    let mut text = format!("{indent}{{");
    let mut target = name.to_string();
    for (depth, count) in dims.iter().enumerate() {
        text += &format!(" for (uint _zi{depth} = 0u; _zi{depth} < {count}u; ++_zi{depth})");
        target += &format!("[_zi{depth}]");
    }
    text += &format!(" {target} = ({element})0; }}{ending}");
    Some(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arrays_become_loops_and_everything_else_stays() {
        let naga = "    if (i == 0) {\n        counter = (uint)0;\n        tile = (float3[4][128])0;\n        \
                    flat = (float[256])0;\n        s = (S)0;\n        list = (S[3])0;\n    }\n";
        let rewritten = zero_init_as_loops(naga);
        assert!(rewritten.contains("        counter = (uint)0;\n"));
        assert!(rewritten.contains("        s = (S)0;\n"));
        assert!(rewritten.contains(
            "        { for (uint _zi0 = 0u; _zi0 < 4u; ++_zi0) for (uint _zi1 = 0u; _zi1 < 128u; ++_zi1) \
             tile[_zi0][_zi1] = (float3)0; }\n"
        ));
        assert!(rewritten.contains("        { for (uint _zi0 = 0u; _zi0 < 256u; ++_zi0) flat[_zi0] = (float)0; }\n"));
        assert!(rewritten.contains("{ for (uint _zi0 = 0u; _zi0 < 3u; ++_zi0) list[_zi0] = (S)0; }"));
        assert!(!rewritten.contains("])0"));
    }

    #[test]
    fn lines_that_only_look_alike_are_left_alone() {
        for line in ["x = (float[n])0;\n", "a + b = (float[4])0;\n", "y = (float[4])1;\n", "z = (float[])0;\n"] {
            assert_eq!(zero_init_as_loops(line), line);
        }
    }
}
