//! The shader-side twins of `strata.h`: `strata.glsl` (GLSL 4.50, `#include`),
//! `strata.hlsli` (HLSL, `#include`) and `strata.wgsl` (a WGSL module, to be put before the
//! engine's shader), declaring the same records and constants for an engine's own shaders
//! (its candidate generation writes `StrataCandidate`s, its resampling reads
//! `StrataSelectedCandidates`). They are generated from the same structs and constants as
//! `strata.h` ([`crate::c_header`]), field for field in the same order; every field is a
//! 4-byte scalar, an array of them, or a vec2 or vec4 at an offset its alignment divides
//! (the Rust declarations pad explicitly), so the records lay out the same in C, in GLSL's
//! `std430` buffers, in HLSL's structured buffers and in WGSL's storage buffers (a test of
//! strata's compiles a shader including each and compares every offset and size with
//! `strata.h`'s).

use crate::ExportError;
use crate::c_header::{HeaderStruct, c_name, comment, constant_doc, version_parts};
use strata_kernels::gpu::{ConstantValue, GpuConstant};

/// A shading language of the includes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Language {
    /// GLSL 4.50 (`strata.glsl`).
    Glsl,
    /// HLSL (`strata.hlsli`).
    Hlsl,
    /// WGSL (`strata.wgsl`).
    Wgsl,
}

impl Language {
    /// Every language, in the order of [`Language::file`].
    pub const ALL: [Language; 3] = [Language::Glsl, Language::Hlsl, Language::Wgsl];

    /// The include's path in the package.
    pub fn file(self) -> &'static str {
        match self {
            Language::Glsl => "include/strata.glsl",
            Language::Hlsl => "include/strata.hlsli",
            Language::Wgsl => "include/strata.wgsl",
        }
    }
}

/// The scalar type of WGSL `wgsl` in `language`; `None` if it is not a 4-byte scalar.
fn scalar(language: Language, wgsl: &str) -> Option<&'static str> {
    let wgsl = wgsl.trim();
    Some(match (language, wgsl) {
        (Language::Wgsl, "u32") => "u32",
        (Language::Wgsl, "i32") => "i32",
        (Language::Wgsl, "f32") => "f32",
        (_, "u32") => "uint",
        (_, "i32") => "int",
        (_, "f32") => "float",
        _ => return None,
    })
}

/// The declaration of field `name` of WGSL type `wgsl` in `language` (a scalar or an array
/// of scalars: the only fields whose layout is the same in every language).
fn field(language: Language, wgsl: &str, name: &str) -> Result<String, ExportError> {
    if let Some(t) = scalar(language, wgsl) {
        return Ok(match language {
            Language::Wgsl => format!("{name}: {t},"),
            _ => format!("{t} {name};"),
        });
    }
    let array = wgsl.strip_prefix("array<").and_then(|rest| rest.strip_suffix('>'));
    if let Some((element, count)) = array.and_then(|args| args.rsplit_once(','))
        && let (Some(t), Ok(count)) = (scalar(language, element), count.trim().parse::<u32>())
    {
        return Ok(match language {
            Language::Wgsl => format!("{name}: array<{t}, {count}>,"),
            _ => format!("{t} {name}[{count}];"),
        });
    }
    // vec2 and vec4 (not vec3, which GLSL's std430 pads and HLSL does not): at the offsets
    // the Rust twin gives them (multiples of their alignment), the same in every language.
    for (prefix, count) in [("vec2<", 2), ("vec4<", 4)] {
        if let Some(element) = wgsl.strip_prefix(prefix).and_then(|rest| rest.strip_suffix('>'))
            && let Some(t) = scalar(language, element)
        {
            let vector = match (language, t) {
                (Language::Wgsl, _) => format!("vec{count}<{t}>"),
                (Language::Glsl, "uint") => format!("uvec{count}"),
                (Language::Glsl, "int") => format!("ivec{count}"),
                (Language::Glsl, _) => format!("vec{count}"),
                (Language::Hlsl, _) => format!("{t}{count}"),
            };
            return Ok(match language {
                Language::Wgsl => format!("{name}: {vector},"),
                _ => format!("{vector} {name};"),
            });
        }
    }
    Err(ExportError::Header(format!(
        "field `{name}`: WGSL `{wgsl}` is not a 4-byte scalar, an array of them, a vec2 or a vec4, whose layout every \
         shading language shares"
    )))
}

/// Words GLSL or HLSL reserve (types, qualifiers) that may be a field's name: such a field
/// is declared with `_` after its name in those languages (`StrataSelectionParams.sampler`
/// is `sampler_` in GLSL and HLSL), at the same offset.
const RESERVED: [&str; 24] = [
    "sampler",
    "texture",
    "buffer",
    "shared",
    "in",
    "out",
    "input",
    "output",
    "filter",
    "precise",
    "sample",
    "point",
    "line",
    "triangle",
    "packed",
    "half",
    "common",
    "partition",
    "active",
    "smooth",
    "flat",
    "uniform",
    "patch",
    "groupshared",
];

/// Field `name`'s name in `language`: with `_` after it where GLSL or HLSL reserve the word
/// (`sampler`, `buffer`, `texture`, ...).
pub fn field_name(language: Language, name: &str) -> String {
    if language != Language::Wgsl && RESERVED.contains(&name) { format!("{name}_") } else { name.to_string() }
}

/// The constant `name` = `value` in `language`.
fn constant(language: Language, name: &str, value: ConstantValue) -> String {
    let (wgsl_type, text) = match value {
        ConstantValue::U32(v) => ("u32", format!("{v}u")),
        ConstantValue::F32(v) => ("f32", format!("{v:?}")),
    };
    match language {
        Language::Wgsl => format!("const {name}: {wgsl_type} = {text}{};\n", if wgsl_type == "f32" { "f" } else { "" }),
        _ => format!("#define {name} {text}\n"),
    }
}

/// The include's text in `language`.
pub fn header(
    language: Language,
    structs: &[HeaderStruct],
    constants: &[GpuConstant],
    version: &str,
) -> Result<String, ExportError> {
    let file = language.file().trim_start_matches("include/");
    let mut h = comment(
        &format!(
            "{file}: the records and constants of strata {version}'s stratified selection pass (Salaün et al., SIGGRAPH \
             2025) for an engine's own shaders, the twins of strata.h's, field for field. Generated by `cargo xtask \
             export`; do not edit. {}",
            match language {
                Language::Glsl =>
                    "GLSL 4.50: #include it (GL_GOOGLE_include_directive); use the records in std430 buffers.",
                Language::Hlsl => "HLSL: #include it; use the records in (RW)StructuredBuffers.",
                Language::Wgsl => "WGSL has no #include: put this module's text before your shader's.",
            }
        ),
        "",
    );
    let guard = if language == Language::Hlsl { "STRATA_HLSLI" } else { "STRATA_GLSL" };
    if language != Language::Wgsl {
        h += &format!("#ifndef {guard}\n#define {guard}\n\n");
    }
    let [major, minor, patch] = version_parts(version)?;
    for (name, value) in [("MAJOR", major), ("MINOR", minor), ("PATCH", patch)] {
        h += &constant(language, &format!("STRATA_VERSION_{name}"), ConstantValue::U32(value));
    }
    h += "\n";
    for c in constants {
        if let Some(doc) = constant_doc(c) {
            h += &comment(&doc, "");
        }
        h += &constant(language, &c_name(c.name), c.value);
    }
    for s in structs {
        let entry = &s.entry;
        h += "\n";
        if !s.doc.is_empty() {
            h += &comment(&s.doc, "");
        }
        h += &format!("struct Strata{} {{\n", entry.name);
        for (f, doc) in entry.fields.iter().zip(&s.field_docs) {
            if !doc.is_empty() {
                h += &comment(doc, "    ");
            }
            h += &format!("    {}\n", field(language, &f.wgsl_type, &field_name(language, f.name))?);
        }
        h += if language == Language::Wgsl { "}\n" } else { "};\n" };
    }
    if language != Language::Wgsl {
        h += &format!("\n#endif /* {guard} */\n");
    }
    Ok(h)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_are_scalars_or_arrays_of_them_in_each_language() {
        assert_eq!(field(Language::Glsl, "array<u32, 4>", "payloads").unwrap(), "uint payloads[4];");
        assert_eq!(field(Language::Hlsl, "f32", "key").unwrap(), "float key;");
        assert_eq!(field(Language::Wgsl, "array<f32, 4>", "weights").unwrap(), "weights: array<f32, 4>,");
        assert_eq!(field(Language::Glsl, "vec4<u32>", "payloads").unwrap(), "uvec4 payloads;");
        assert_eq!(field(Language::Hlsl, "vec4<f32>", "weights").unwrap(), "float4 weights;");
        assert_eq!(field_name(Language::Glsl, "sampler"), "sampler_");
        assert_eq!(field_name(Language::Wgsl, "sampler"), "sampler");
        let error = field(Language::Glsl, "vec3<f32>", "origin").unwrap_err().to_string();
        assert!(error.contains("`origin`") && error.contains("vec3<f32>"), "{error}");
    }
}
