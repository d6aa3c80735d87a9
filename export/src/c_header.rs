//! `strata.h`: the C11 declarations of the pass's records and constants, generated from
//! the same Rust declarations the kernels' WGSL is generated from
//! (`strata_kernels::gpu::GpuStruct`, `strata_kernels::constants::shared`): each
//! struct's fields in declaration order with the C type of the field's WGSL type, a
//! `_Static_assert` on the struct's size and on every field's offset (Rust's, which a
//! test of strata-kernels holds equal to naga's), the constants as `STRATA_` macros, the
//! sampler variants as an enum, and the kernels' workgroup sizes. The doc comments are
//! the Rust declarations' own.

use crate::ExportError;
use strata_kernels::gpu::{ConstantValue, GpuConstant, GpuStruct, StructDeclaration};
use strata_kernels::selection::SamplerVariant;

/// The C macro of the WGSL constant `name`: `STRATA_` and its name.
pub fn c_name(name: &str) -> String {
    format!("STRATA_{name}")
}

/// A constant's doc comment as one line of text (`None` if it has none).
pub(crate) fn constant_doc(constant: &GpuConstant) -> Option<String> {
    let text = constant.doc.split_whitespace().collect::<Vec<_>>().join(" ");
    (!text.is_empty()).then_some(text)
}

/// `text` as a C comment indented by `indent`, wrapped at about 96 columns.
pub(crate) fn comment(text: &str, indent: &str) -> String {
    let mut lines = vec![String::new()];
    for word in text.split_whitespace() {
        // Rust's intra-doc links ([`Name`]) lose their brackets; other brackets ("in [0, 1)") stay.
        let word = word.replace("*/", "* /").replace("[`", "`").replace("`]", "").replace('`', "");
        let line = lines.last_mut().expect("one line");
        if !line.is_empty() && line.len() + word.len() > 88 {
            lines.push(word);
        } else {
            if !line.is_empty() {
                line.push(' ');
            }
            line.push_str(&word);
        }
    }
    match lines.as_slice() {
        [one] if one.len() < 86 => format!("{indent}/* {one} */\n"),
        _ => {
            let body: String = lines.iter().map(|l| format!("{indent} * {l}\n")).collect();
            format!("{indent}/*\n{body}{indent} */\n")
        }
    }
}

/// The C declarator of a field named `name` of WGSL type `wgsl` (`u32`, `f32`, `i32`,
/// `array<u32, 4>`, `vec3<f32>`).
fn c_declarator(wgsl: &str, name: &str) -> Result<String, ExportError> {
    let scalar = |t: &str| match t.trim() {
        "u32" => Some("uint32_t"),
        "i32" => Some("int32_t"),
        "f32" => Some("float"),
        _ => None,
    };
    if let Some(c) = scalar(wgsl) {
        return Ok(format!("{c} {name}"));
    }
    let inner = |prefix: &str| wgsl.strip_prefix(prefix).and_then(|rest| rest.strip_suffix('>'));
    if let Some(args) = inner("array<")
        && let Some((element, count)) = args.rsplit_once(',')
        && let (Some(c), Ok(count)) = (scalar(element), count.trim().parse::<u32>())
    {
        return Ok(format!("{c} {name}[{count}]"));
    }
    for (prefix, count) in [("vec2<", 2), ("vec3<", 3), ("vec4<", 4)] {
        if let Some(c) = inner(prefix).and_then(scalar) {
            return Ok(format!("{c} {name}[{count}]"));
        }
    }
    Err(ExportError::Header(format!("field `{name}`: no C type for WGSL `{wgsl}`")))
}

/// A struct of the header with its layout and docs.
pub struct HeaderStruct {
    /// The manifest's entry (name, size, fields with offsets and WGSL types).
    pub entry: crate::manifest::StructEntry,
    /// The struct's doc comment as one paragraph (empty: none).
    pub doc: String,
    /// Each field's, in the entry's order.
    pub field_docs: Vec<String>,
}

impl HeaderStruct {
    /// The struct `T` as declared.
    pub fn of<T: GpuStruct>() -> HeaderStruct {
        let declaration = StructDeclaration::of::<T>();
        HeaderStruct {
            entry: crate::manifest::struct_entry(&declaration),
            doc: paragraph(declaration.doc),
            field_docs: declaration.fields.iter().map(|field| paragraph(field.doc)).collect(),
        }
    }
}

/// The lines of a doc comment as one paragraph.
fn paragraph(doc: &str) -> String {
    doc.lines().map(|line| line.strip_prefix(' ').unwrap_or(line)).collect::<Vec<_>>().join(" ")
}

/// `MAJOR.MINOR.PATCH` (a pre-release or build suffix after `-` or `+` ignored) as three
/// numbers; an error naming `version` otherwise.
pub fn version_parts(version: &str) -> Result<[u32; 3], ExportError> {
    let core = version.split(['-', '+']).next().unwrap_or(version);
    let parts: Vec<Option<u32>> = core.split('.').map(|p| p.parse::<u32>().ok()).collect();
    match parts.as_slice() {
        [Some(major), Some(minor), Some(patch)] if *minor < 1024 && *patch < 4096 => Ok([*major, *minor, *patch]),
        _ => Err(ExportError::Header(format!(
            "version `{version}`: not MAJOR.MINOR.PATCH with MINOR < 1024 and PATCH < 4096 (STRATA_MAKE_VERSION's packing)"
        ))),
    }
}

/// The version macros of `strata.h` for the workspace's `version` (the export passes
/// `CARGO_PKG_VERSION`: the workspace's version, so nothing here is written by hand).
fn version_macros(version: &str) -> Result<String, ExportError> {
    let [major, minor, patch] = version_parts(version)?;
    Ok(format!(
        "/* The strata version this package was exported from (semantic versioning). */\n\
         #define STRATA_VERSION_MAJOR {major}\n#define STRATA_VERSION_MINOR {minor}\n#define STRATA_VERSION_PATCH {patch}\n\
         /* A version as one number (Vulkan's packing): major << 22 | minor << 12 | patch. */\n\
         #define STRATA_MAKE_VERSION(major, minor, patch) \\\n    \
         ((((uint32_t)(major)) << 22) | (((uint32_t)(minor)) << 12) | ((uint32_t)(patch)))\n\
         /*\n * The version of these headers, which strata_vk_create takes as its first argument: the\n \
         * library refuses (STRATA_STATUS_VERSION) headers of another major version, or before 1.0\n \
         * of another minor version, whose records and functions may differ from its own.\n */\n\
         #define STRATA_VERSION STRATA_MAKE_VERSION(STRATA_VERSION_MAJOR, STRATA_VERSION_MINOR, STRATA_VERSION_PATCH)\n\n"
    ))
}

/// The header's text.
pub fn header(
    structs: &[HeaderStruct],
    constants: &[GpuConstant],
    workgroup_sizes: &[(String, [u32; 3])],
    version: &str,
) -> Result<String, ExportError> {
    let mut h = String::new();
    h += &format!(
        "/*\n * strata.h: the records and constants of strata {version}'s stratified selection pass (Salaün et al.,\n \
         * SIGGRAPH 2025) for C11 and C++.\n *\n * Generated by `cargo xtask export` from the Rust declarations the kernels' \
         WGSL structs are\n * generated from (checked against naga's layout by strata's tests); do not edit. Each struct's layout is the WGSL's\n \
         * (std430 / std140-compatible: 4-byte fields, no implicit padding); the _Static_asserts below fail\n \
         * the build where a compiler lays one out otherwise. manifest.json says which buffer holds which.\n */\n"
    );
    h += "#ifndef STRATA_H\n#define STRATA_H\n\n#include <stddef.h>\n#include <stdint.h>\n\n";
    h += &version_macros(version)?;
    h += "/* C11's _Static_assert, C++'s static_assert. */\n#ifdef __cplusplus\n#define STRATA_STATIC_ASSERT \
          static_assert\n#else\n#define STRATA_STATIC_ASSERT _Static_assert\n#endif\n\n";
    h += "#ifdef __cplusplus\nextern \"C\" {\n#endif\n\n";
    h += "/* Constants the kernels and the host share (WGSL names with STRATA_ in front). */\n";
    for constant in constants {
        let name = constant.name;
        // The sampler ids are the enum below.
        if name.starts_with("SAMPLER_") {
            continue;
        }
        let doc = constant_doc(constant);
        let text = match constant.value {
            ConstantValue::U32(v) => format!("{v}u"),
            ConstantValue::F32(v) => format!("{v:?}f"),
        };
        if let Some(doc) = doc {
            h += &comment(&doc, "");
        }
        h += &format!("#define {} {text}\n", c_name(name));
    }
    h += "\n/* Workgroup sizes (x, y, z) of the kernels, from naga's reflection. */\n";
    for (kernel, size) in workgroup_sizes {
        let upper = kernel.strip_prefix("strata_").unwrap_or(kernel).to_uppercase();
        for (axis, value) in ["X", "Y", "Z"].iter().zip(size) {
            h += &format!("#define STRATA_{upper}_WORKGROUP_SIZE_{axis} {value}u\n");
        }
    }
    h += "\n/* The sampler variants (StrataSelectionParams.sampler; paper Table 2). */\ntypedef enum StrataSampler {\n";
    for variant in SamplerVariant::ALL {
        let name = variant.name().to_uppercase().replace('-', "_");
        h += &format!("    STRATA_SAMPLER_{name} = {},\n", variant.id());
    }
    h += "} StrataSampler;\n";
    // How many there are, and their range as the settings' checks say it (strata_frame.h).
    let count = SamplerVariant::ALL.len();
    h += &format!("#define STRATA_SAMPLER_COUNT {count}u\n#define STRATA_SAMPLER_RANGE \"0 to {}\"\n\n", count - 1);
    for s in structs {
        let entry = &s.entry;
        if !s.doc.is_empty() {
            h += &comment(&s.doc, "");
        }
        h += &format!("typedef struct Strata{} {{\n", entry.name);
        for (field, doc) in entry.fields.iter().zip(&s.field_docs) {
            if !doc.is_empty() {
                h += &comment(doc, "    ");
            }
            h += &format!("    {};\n", c_declarator(&field.wgsl_type, field.name)?);
        }
        h += &format!("}} Strata{};\n\n", entry.name);
    }
    h += "/* The layouts, as Rust and naga have them. */\n";
    for s in structs {
        let e = &s.entry;
        h += &format!(
            "STRATA_STATIC_ASSERT(sizeof(Strata{0}) == {1}, \"Strata{0} must be {1} bytes\");\n",
            e.name, e.size
        );
        for field in &e.fields {
            h += &format!(
                "STRATA_STATIC_ASSERT(offsetof(Strata{0}, {1}) == {2}, \"Strata{0}.{1} must lie at byte {2}\");\n",
                e.name, field.name, field.offset
            );
        }
    }
    h += "\n#ifdef __cplusplus\n}\n#endif\n\n#endif /* STRATA_H */\n";
    Ok(h)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn docs_are_found_for_structs_fields_and_constants() {
        let candidate = HeaderStruct::of::<strata_kernels::types::Candidate>();
        assert!(!candidate.doc.is_empty() && candidate.field_docs.iter().all(|d| !d.is_empty()));
        assert!(!candidate.doc.contains('\n'), "{}", candidate.doc);
        // Every shared constant carries its declaration's doc, on one line.
        for constant in strata_kernels::constants::shared() {
            let doc = constant_doc(&constant).unwrap_or_else(|| panic!("{} has no doc", constant.name));
            assert!(!doc.contains('\n'), "{doc}");
        }
    }

    #[test]
    fn the_version_macros_are_the_workspace_version() {
        let [major, minor, patch] = version_parts(env!("CARGO_PKG_VERSION")).unwrap();
        assert_eq!(major.to_string(), env!("CARGO_PKG_VERSION_MAJOR"));
        assert_eq!(minor.to_string(), env!("CARGO_PKG_VERSION_MINOR"));
        assert_eq!(patch.to_string(), env!("CARGO_PKG_VERSION_PATCH"));
        let macros = version_macros("3.14.15-beta.1").unwrap();
        for line in [
            "#define STRATA_VERSION_MAJOR 3\n",
            "#define STRATA_VERSION_MINOR 14\n",
            "#define STRATA_VERSION_PATCH 15\n",
        ] {
            assert!(macros.contains(line), "{line:?} not in {macros}");
        }
        for broken in ["1.2", "1.x.3", "1.1024.0", ""] {
            let error = version_parts(broken).unwrap_err().to_string();
            assert!(error.contains(&format!("`{broken}`")) && !error.contains('\n'), "{error}");
        }
    }

    #[test]
    fn comments_drop_link_brackets_and_keep_intervals() {
        let text = comment("The number in [0, 1) of [`ResampleOutput::slot`], or [`NO_SLOT`].", "");
        assert_eq!(text, "/* The number in [0, 1) of ResampleOutput::slot, or NO_SLOT. */\n");
    }

    #[test]
    fn wgsl_types_become_c_declarators() {
        assert_eq!(c_declarator("u32", "width").unwrap(), "uint32_t width");
        assert_eq!(c_declarator("array<u32, 4>", "payloads").unwrap(), "uint32_t payloads[4]");
        assert_eq!(c_declarator("vec3<f32>", "origin").unwrap(), "float origin[3]");
        assert!(c_declarator("mat4x4<f32>", "m").is_err());
    }
}
