//! Checks that a struct declared with `gpu_struct!` ([`crate::gpu`]) lays out the same in
//! Rust and in its generated WGSL.
//!
//! The macro writes both from one declaration, but it cannot see whether the WGSL types
//! it writes have the Rust fields' offsets and sizes: a `[f32; 3]` said to be a
//! `vec3<f32>` at an offset that is not a multiple of 16, or a field whose padding was
//! left out, makes the GPU read garbage without any error. [`check_struct`] compares the
//! Rust struct's size and every field's name, offset and size with naga's layout of the
//! WGSL struct; the test below runs it on every declared struct.

use crate::gpu::StructDeclaration;
use naga::proc::Layouter;

/// The scalar (`f32`, `u32`, `i32`) a type's text names, WGSL's or Rust's (`vec3<f32>`,
/// `[u32; 4]`, `array<u32, 4>`); `None` for a struct or a type naming none or several.
fn scalar_of(ty: &str) -> Option<&'static str> {
    let words: Vec<&str> = ty.split(|c: char| !c.is_ascii_alphanumeric()).collect();
    let mut found = ["f32", "u32", "i32"].into_iter().filter(|scalar| words.contains(scalar));
    let scalar = found.next()?;
    found.next().is_none().then_some(scalar)
}

/// Compares `declaration` with the struct of its name in `module`; the error lists every
/// difference, including a field whose WGSL type holds another scalar than its Rust type
/// (same size, so only the values would be wrong).
pub fn check_struct(declaration: &StructDeclaration, module: &naga::Module) -> Result<(), String> {
    let name = declaration.name;
    let (_, ty) = module
        .types
        .iter()
        .find(|(_, ty)| ty.name.as_deref() == Some(name))
        .ok_or_else(|| format!("no WGSL struct `{name}` in the module"))?;
    let naga::TypeInner::Struct { members, span } = &ty.inner else {
        return Err(format!("WGSL `{name}` is not a struct"));
    };
    let mut layouter = Layouter::default();
    layouter.update(module.to_ctx()).map_err(|e| format!("naga layouter: {e}"))?;
    let mut problems = Vec::new();
    if *span as usize != declaration.size {
        problems.push(format!("size: WGSL {span} bytes, Rust {} bytes", declaration.size));
    }
    let fields = &declaration.fields;
    if fields.len() != members.len() {
        problems.push(format!("field count: WGSL {}, Rust {}", members.len(), fields.len()));
    }
    for (index, (wgsl, field)) in members.iter().zip(fields).enumerate() {
        let wgsl_name = wgsl.name.as_deref().unwrap_or("<unnamed>");
        let wgsl_size = layouter[wgsl.ty].size as usize;
        if wgsl_name != field.name {
            problems.push(format!("field {index}: WGSL `{wgsl_name}`, Rust `{}`", field.name));
        }
        if wgsl.offset as usize != field.offset {
            problems.push(format!(
                "field `{}` ({}): WGSL offset {}, Rust offset {}",
                field.name, field.wgsl_type, wgsl.offset, field.offset
            ));
        }
        if wgsl_size != field.size {
            problems.push(format!(
                "field `{}` ({}): WGSL size {wgsl_size}, Rust size {}",
                field.name, field.wgsl_type, field.size
            ));
        }
        if let (Some(wgsl), Some(rust)) = (scalar_of(&field.wgsl_type), scalar_of(field.rust_type))
            && wgsl != rust
        {
            problems.push(format!(
                "field `{}`: WGSL {} holds {wgsl}, Rust {} holds {rust}",
                field.name, field.wgsl_type, field.rust_type
            ));
        }
    }
    if problems.is_empty() {
        Ok(())
    } else {
        Err(format!("the Rust struct and the WGSL `{name}` differ:\n  {}", problems.join("\n  ")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::GpuField;
    use crate::wgsl_files::gpu_modules as modules;

    /// Every struct of every generated module lays out in naga as in Rust: all the
    /// modules, concatenated, parse, and each struct's size and fields' offsets and sizes
    /// are the Rust ones. (That every kernel reads these declarations and no other is
    /// the registry's doing: the WGSL files import the modules and declare none of them.)
    #[test]
    fn every_declared_struct_lays_out_in_wgsl_as_in_rust() {
        let modules = modules();
        let mut text: String = modules.iter().map(|module| module.wgsl()).collect();
        // The row readers' row functions, defined as the kernels that import them do.
        for readers in modules.iter().filter_map(|m| m.readers.as_ref()) {
            text += &format!("{} {{ return vec4<u32>(row); }}\n", readers.declaration());
        }
        let module = naga::front::wgsl::parse_str(&text).unwrap_or_else(|e| panic!("{}", e.emit_to_string(&text)));
        let mut failures = Vec::new();
        let mut checked = 0;
        for declaration in modules.iter().flat_map(|m| &m.structs) {
            checked += 1;
            if let Err(error) = check_struct(declaration, &module) {
                failures.push(error);
            }
        }
        assert!(failures.is_empty(), "{}", failures.join("\n"));
        assert!(checked >= 24, "only {checked} structs declared");
    }

    /// The comparison sees what the layouts disagree on: a 16-byte Rust field read as a
    /// `vec3<f32>` moves the next field, and a renamed or missing struct is named.
    #[test]
    fn a_wrong_wgsl_type_is_caught() {
        let field = |name, offset, size, wgsl_type| GpuField { name, offset, size, wgsl_type, rust_type: "", doc: "" };
        let declaration = StructDeclaration {
            name: "Padded",
            doc: "",
            size: 32,
            fields: vec![
                field("position", 0, 16, "vec3<f32>".into()),
                field("id", 16, 4, "u32".into()),
                field("pad", 20, 12, "array<u32, 3>".into()),
            ],
        };
        let module = naga::front::wgsl::parse_str(&declaration.wgsl()).unwrap();
        let error = check_struct(&declaration, &module).unwrap_err();
        assert!(error.contains("field `id` (u32): WGSL offset 12, Rust offset 16"), "{error}");
        assert!(error.contains("field `position` (vec3<f32>): WGSL size 12, Rust size 16"), "{error}");
        let other = naga::front::wgsl::parse_str("struct Other { id: u32 }").unwrap();
        assert!(check_struct(&declaration, &other).unwrap_err().contains("no WGSL struct `Padded`"));
    }

    /// A field given the right size but another scalar by hand (`[f32; 4] as "vec4<u32>"`)
    /// is caught; a struct field and an array of a struct are left to their own check.
    #[test]
    fn a_wgsl_type_of_another_scalar_is_caught() {
        let declaration = StructDeclaration {
            name: "Mixed",
            doc: "",
            size: 16,
            fields: vec![GpuField {
                name: "weights",
                offset: 0,
                size: 16,
                wgsl_type: "vec4<u32>".into(),
                rust_type: "[f32; 4]",
                doc: "",
            }],
        };
        let module = naga::front::wgsl::parse_str(&declaration.wgsl()).unwrap();
        let error = check_struct(&declaration, &module).unwrap_err();
        assert!(error.contains("field `weights`: WGSL vec4<u32> holds u32, Rust [f32; 4] holds f32"), "{error}");
        assert_eq!(scalar_of("array<PathCandidate, 4>"), None);
        assert_eq!(scalar_of("[u32; 2]"), Some("u32"));
    }
}
