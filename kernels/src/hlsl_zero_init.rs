//! naga's zero-initialisation of arrays, rewritten as loops that glslang's and Slang's
//! HLSL front ends accept.
//!
//! Workgroup arrays now reach the writer already zeroed in loops in naga's IR
//! (`translate`, `workgroup_zero_loops`); what this rewrite still meets is `var<private>`
//! and function arrays, and workgroup arrays where no loop could be written there.
//!
//! WGSL promises zeroed workgroup memory and zeroed `var`s without an initialiser, and
//! naga's HLSL keeps both promises with a cast of zero to the array's type:
//! - workgroup memory: `NAME = (T[4][128])0;` at the start of each entry point (written
//!   by one invocation, then a barrier);
//! - `var<private>`: `static T NAME[4][5] = (T[4][5])0;` at global scope;
//! - function `var`s: `T NAME[2][3] = (T[2][3])0;` at the top of the function.
//!
//! DXC accepts that cast; glslang (12.0) refuses it for any array ("array constructor
//! needs one argument per array element") and Slang refuses it for arrays of arrays of
//! two different sizes, reading the dimensions in reverse ("type mismatch"). Without the
//! zeroing, a kernel that counts into a workgroup variable read garbage on the glslang
//! HLSL path (1690510940 instead of 64). So each such array becomes nested loops over its
//! dimensions assigning `(T)0` to each element, which all three compilers take:
//! `{ for (uint _zi0 = 0u; _zi0 < 4u; ++_zi0) ... }`, braced because HLSL's `for`
//! variables outlive the loop. A workgroup assignment is replaced by its loops; a
//! function `var` keeps its declaration without the initialiser, its loops beside it; a
//! `var<private>` keeps its declaration without the initialiser, and its loops go at the
//! start of every entry point (a private variable belongs to one invocation, and every
//! use of it follows the entry point's first statement). Scalars, vectors and structs
//! keep naga's `(T)0`, which every front end accepts.

/// `hlsl` with every zeroing of an array by `(T[N]...[M])0` rewritten as loops (module
/// documentation); everything else unchanged.
pub fn zero_init_as_loops(hlsl: &str) -> String {
    let lines: Vec<&str> = hlsl.split_inclusive('\n').collect();
    let entry_bodies = entry_point_bodies(&lines);
    let mut out = String::with_capacity(hlsl.len());
    let mut private_loops = String::new();
    for line in &lines {
        match array_zeroing(line) {
            Some(Zeroing::Workgroup { indent, loops, ending }) => out.push_str(&format!("{indent}{loops}{ending}")),
            Some(Zeroing::Function { indent, declaration, loops, ending }) => {
                out.push_str(&format!("{indent}{declaration}; {loops}{ending}"))
            }
            // Only where the loops have somewhere to go.
            Some(Zeroing::Private { declaration, loops, ending }) if !entry_bodies.is_empty() => {
                out.push_str(&format!("{declaration};{ending}"));
                private_loops += &format!("    {loops}\n");
            }
            _ => out.push_str(line),
        }
    }
    if private_loops.is_empty() {
        return out;
    }
    // Second pass: the private variables' loops open every entry point's body.
    let mut with_private = String::with_capacity(out.len() + private_loops.len() * entry_bodies.len());
    for (index, line) in out.split_inclusive('\n').enumerate() {
        with_private.push_str(line);
        if entry_bodies.contains(&index) {
            with_private.push_str(&private_loops);
        }
    }
    with_private
}

/// The indices of the lines that open an entry point's body: the first line that is
/// exactly `{` after each `[numthreads(...)]` attribute. Rewriting keeps one output line
/// per input line, so the indices hold for the output too.
fn entry_point_bodies(lines: &[&str]) -> Vec<usize> {
    let mut bodies = Vec::new();
    let mut in_signature = false;
    for (index, line) in lines.iter().enumerate() {
        if line.starts_with("[numthreads(") {
            in_signature = true;
        } else if in_signature && line.trim_end_matches(['\n', '\r']) == "{" {
            bodies.push(index);
            in_signature = false;
        }
    }
    bodies
}

/// One zeroing of an array by naga, with the loops that replace it.
#[derive(Debug, PartialEq)]
enum Zeroing<'a> {
    /// `NAME = (T[..])0;` in an entry point (workgroup memory).
    Workgroup { indent: &'a str, loops: String, ending: &'a str },
    /// `T NAME[..] = (T[..])0;` in a function (a function `var`).
    Function { indent: &'a str, declaration: &'a str, loops: String, ending: &'a str },
    /// `static T NAME[..] = (T[..])0;` at global scope (a `var<private>`).
    Private { declaration: &'a str, loops: String, ending: &'a str },
}

/// The zeroing on one line of naga's HLSL, if the line is one (module documentation).
fn array_zeroing(line: &str) -> Option<Zeroing<'_>> {
    let body = line.trim_end_matches(['\n', '\r']);
    let ending = &line[body.len()..];
    let indent = &body[..body.len() - body.trim_start().len()];
    let (target, cast) = body.trim_start().split_once(" = (")?;
    let element_and_dims = cast.strip_suffix(")0;")?;
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
    if !rest.is_empty() || dims.is_empty() || element.is_empty() || !is_name(element) {
        return None;
    }
    let loops_for = |name: &str| {
        let mut text = String::from("{");
        let mut target = name.to_string();
        for (depth, count) in dims.iter().enumerate() {
            text += &format!(" for (uint _zi{depth} = 0u; _zi{depth} < {count}u; ++_zi{depth})");
            target += &format!("[_zi{depth}]");
        }
        text + &format!(" {target} = ({element})0; }}")
    };
    if is_name(target) {
        return (!indent.is_empty()).then(|| Zeroing::Workgroup { indent, loops: loops_for(target), ending });
    }
    // A declaration: `[static ]T NAME[..]`, with the cast's type and dimensions.
    let (private, declared) = match target.strip_prefix("static ") {
        Some(declared) => (true, declared),
        None => (false, target),
    };
    let (declared_element, name) = declared.strip_suffix(dims_text)?.rsplit_once(' ')?;
    if declared_element != element || !is_name(name) || name.contains('.') {
        return None;
    }
    let loops = loops_for(name);
    match (private, indent.is_empty()) {
        (true, true) => Some(Zeroing::Private { declaration: target, loops, ending }),
        (false, false) => Some(Zeroing::Function { indent, declaration: target, loops, ending }),
        _ => None,
    }
}

/// Whether `text` is an identifier or a member path (`a.b`) as naga writes them.
fn is_name(text: &str) -> bool {
    !text.is_empty() && text.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'.')
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

    /// naga's HLSL of `var<private>` and function arrays (as in
    /// `tests/data/corpus/private_zeroing.wgsl`): the declarations lose the cast, the
    /// private arrays are zeroed at the start of the entry point, the function arrays
    /// where they are declared.
    #[test]
    fn private_and_function_arrays_become_declarations_and_loops() {
        let naga = "static uint flat[8] = (uint[8])0;\nstatic uint grid[3][5] = (uint[3][5])0;\n\
                    static Bag bag = (Bag)0;\n\nuint helper(uint seed)\n{\n    uint scratch[7][2] = (uint[7][2])0;\n    \
                    uint c = (uint)0;\n}\n\n[numthreads(16, 1, 1)]\nvoid main(uint3 id : SV_DispatchThreadID)\n{\n    \
                    uint3 local[2][3] = (uint3[2][3])0;\n    return;\n}\n";
        let rewritten = zero_init_as_loops(naga);
        let expected = "static uint flat[8];\nstatic uint grid[3][5];\nstatic Bag bag = (Bag)0;\n\nuint helper(uint seed)\n\
                        {\n    uint scratch[7][2]; { for (uint _zi0 = 0u; _zi0 < 7u; ++_zi0) for (uint _zi1 = 0u; _zi1 < \
                        2u; ++_zi1) scratch[_zi0][_zi1] = (uint)0; }\n    uint c = (uint)0;\n}\n\n\
                        [numthreads(16, 1, 1)]\nvoid main(uint3 id : SV_DispatchThreadID)\n{\n    \
                        { for (uint _zi0 = 0u; _zi0 < 8u; ++_zi0) flat[_zi0] = (uint)0; }\n    \
                        { for (uint _zi0 = 0u; _zi0 < 3u; ++_zi0) for (uint _zi1 = 0u; _zi1 < 5u; ++_zi1) \
                        grid[_zi0][_zi1] = (uint)0; }\n    \
                        uint3 local[2][3]; { for (uint _zi0 = 0u; _zi0 < 2u; ++_zi0) for (uint _zi1 = 0u; _zi1 < 3u; \
                        ++_zi1) local[_zi0][_zi1] = (uint3)0; }\n    return;\n}\n";
        assert_eq!(rewritten, expected);
    }

    #[test]
    fn lines_that_only_look_alike_are_left_alone() {
        for line in [
            "x = (float[n])0;\n",
            "a + b = (float[4])0;\n",
            "y = (float[4])1;\n",
            "z = (float[])0;\n",
            "    int a[4] = (uint[4])0;\n",
            "    uint a[3] = (uint[4])0;\n",
            "static uint a[4] = (uint[4])0;\n",
            "    static uint a[4] = (uint[4])0;\n",
            "uint a[4] = (uint[4])0;\n",
        ] {
            assert_eq!(zero_init_as_loops(line), line);
        }
    }
}
