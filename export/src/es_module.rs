//! `web/strata.js`, `web/strata.d.ts`, `web/example.html` and `web/example.js`: the pass
//! for web engines, an ES module that runs it on a WebGPU `GPUDevice`, its TypeScript
//! declarations and an example page.
//!
//! The module's code is written by hand (`export/package/web/strata.js`); everything it
//! knows of the kernels comes from the package's own `manifest.json`, serialised into it
//! as one object (`PACKAGE`) by [`package_object`]: each kernel's WGSL, entry point, workgroup
//! size and workgroup memory, each binding's number, buffer and access, each buffer's
//! owner and size rule, the uniforms' field offsets, the constants, the sampler ids and
//! the blue-noise file. No binding number or offset is written in the template: a kernel
//! whose bindings move changes the module with it. The block sizes and the default
//! settings, which the manifest does not carry, come from their Rust declarations
//! (`strata_kernels::types::BLOCK_SIZES`, `SelectionSettings::default`).
//!
//! The module computes each frame's uniforms and dispatch sizes as
//! `strata_kernels::pass_plan::frame_params` does; `tests/tests/es_module.rs` runs it in
//! headless Chromium against `strata-embed`'s wgpu pass, bit for bit.

use crate::ExportError;
use serde_json::{Value, json};
use strata_kernels::selection::SelectionSettings;
use strata_kernels::types::BLOCK_SIZES;

/// The module's template.
const TEMPLATE: &str = include_str!("../package/web/strata.js");
/// The declarations' template.
const DECLARATIONS: &str = include_str!("../package/web/strata.d.ts");
/// The example page and its script (no placeholders but the version).
const EXAMPLE: &str = include_str!("../package/web/example.html");
/// The example page's script.
const EXAMPLE_SCRIPT: &str = include_str!("../package/web/example.js");

/// Where the template takes the package object.
const PACKAGE_PLACEHOLDER: &str = "/* @STRATA_PACKAGE@ */ null";

/// The files' paths in the package.
pub const FILES: [&str; 4] = ["web/strata.js", "web/strata.d.ts", "web/example.html", "web/example.js"];

fn field<'a>(value: &'a Value, path: &[&str]) -> Result<&'a Value, ExportError> {
    path.iter().try_fold(value, |value, key| {
        value
            .get(key)
            .ok_or_else(|| ExportError::Header(format!("strata.js: the manifest has no `{}`", path.join("."))))
    })
}

fn array<'a>(value: &'a Value, path: &[&str]) -> Result<&'a Vec<Value>, ExportError> {
    field(value, path)?
        .as_array()
        .ok_or_else(|| ExportError::Header(format!("strata.js: the manifest's `{}` is not a list", path.join("."))))
}

/// The object the module's code reads (`PACKAGE`), from the manifest and the package's
/// WGSL files (`wgsl(path)` gives a file's text).
pub fn package_object(manifest: &Value, wgsl: &dyn Fn(&str) -> Option<String>) -> Result<Value, ExportError> {
    let mut kernels = Vec::new();
    for kernel in array(manifest, &["kernels"])? {
        let path = field(kernel, &["files", "wgsl"])?.as_str().unwrap_or_default();
        let source = wgsl(path).ok_or_else(|| ExportError::Header(format!("strata.js: no WGSL file {path}")))?;
        let features = array(kernel, &["required_features"])?;
        let subgroups = features.iter().any(|f| f == "subgroups");
        let mut bindings = Vec::new();
        for binding in array(kernel, &["bindings"])? {
            if field(binding, &["set"])? != 0 {
                return Err(ExportError::Header(format!(
                    "strata.js: binding `{}` of `{path}` is not in set 0",
                    field(binding, &["name"])?
                )));
            }
            bindings.push(json!({
                "name": field(binding, &["name"])?,
                "binding": field(binding, &["binding"])?,
                "buffer": field(binding, &["buffer"])?,
                "descriptor_type": field(binding, &["descriptor_type"])?,
                "access": field(binding, &["access"])?,
            }));
        }
        kernels.push(json!({
            "name": field(kernel, &["name"])?,
            "stage": field(kernel, &["stage"])?,
            "entry_point": field(kernel, &["entry_point", "wgsl"])?,
            "workgroup_size": field(kernel, &["workgroup_size"])?,
            "workgroup_memory_bytes": field(kernel, &["workgroup_memory_bytes"])?,
            "uniform": field(kernel, &["uniform"])?,
            "required_features": features,
            "bindings": bindings,
            "wgsl": strata_kernels::source::webgpu_source(&source, subgroups).0,
        }));
    }
    let buffers: Vec<Value> = array(manifest, &["buffers"])?
        .iter()
        .map(|b| {
            Ok(json!({
                "name": field(b, &["name"])?,
                "owner": field(b, &["owner"])?,
                "optional": field(b, &["optional"])?,
                "size": { "rule": field(b, &["size", "rule"])?, "bytes": field(b, &["size", "bytes"])? },
            }))
        })
        .collect::<Result<_, ExportError>>()?;
    let mut constants = serde_json::Map::new();
    for constant in array(manifest, &["constants"])? {
        let name = field(constant, &["name"])?.as_str().unwrap_or_default().to_string();
        constants.insert(name, field(constant, &["value"])?.clone());
    }
    let rules = array(manifest, &["histogram_choice", "rules"])?;
    let unconditional = rules
        .iter()
        .find(|rule| rule.get("when").and_then(Value::as_array).is_some_and(Vec::is_empty))
        .ok_or_else(|| ExportError::Header("strata.js: histogram_choice has no unconditional rule".into()))?;
    let defaults = SelectionSettings::default();
    Ok(json!({
        "version": field(manifest, &["strata_version"])?,
        "kernels": kernels,
        "buffers": buffers,
        "structs": field(manifest, &["structs"])?,
        "constants": constants,
        "samplers": field(manifest, &["samplers"])?,
        "blue_noise": {
            "file": field(manifest, &["blue_noise", "file"])?,
            "bytes": field(manifest, &["blue_noise", "bytes"])?,
        },
        "block_sizes": BLOCK_SIZES,
        "defaults": {
            "block_size": defaults.block_size,
            "candidates": defaults.candidates,
            "sampler": defaults.sampler.name(),
            "masking": defaults.masking,
            "block_shift": defaults.block_shift,
        },
        "histogram_default": field(unconditional, &["kernel"])?,
    }))
}

/// A TypeScript union of `values` (`"a" | "b"`, `4 | 8`).
fn union(values: impl IntoIterator<Item = String>) -> String {
    values.into_iter().collect::<Vec<_>>().join(" | ")
}

/// `template` with `@NAME@` replaced by each value; an error if a placeholder is left.
fn fill(template: &str, what: &str, values: &[(&str, String)]) -> Result<String, ExportError> {
    let mut text = template.to_string();
    for (name, value) in values {
        text = text.replace(&format!("@{name}@"), value);
    }
    match text.find("@STRATA_") {
        Some(at) => Err(ExportError::Header(format!(
            "{what}: placeholder {} left unfilled",
            text[at..].split_whitespace().next().unwrap_or_default()
        ))),
        None => Ok(text),
    }
}

/// The contents of [`FILES`], in its order, for the package whose manifest is `manifest`.
pub fn files(manifest: &Value, wgsl: &dyn Fn(&str) -> Option<String>) -> Result<[String; 4], ExportError> {
    let package = package_object(manifest, wgsl)?;
    let version = field(manifest, &["strata_version"])?.as_str().unwrap_or_default().to_string();
    let object = serde_json::to_string_pretty(&package).map_err(|e| ExportError::Header(e.to_string()))?;
    if !TEMPLATE.contains(PACKAGE_PLACEHOLDER) {
        return Err(ExportError::Header("strata.js: the template has no package placeholder".into()));
    }
    let module =
        fill(&TEMPLATE.replacen(PACKAGE_PLACEHOLDER, &object, 1), "strata.js", &[("STRATA_VERSION", version.clone())])?;
    let quoted = |path: &[&str], key: &str| -> Result<String, ExportError> {
        Ok(union(array(&package, path)?.iter().filter_map(|v| v.get(key)).map(|v| v.to_string())))
    };
    let histogram_kernels = union(
        array(&package, &["kernels"])?.iter().filter(|k| k["stage"] == "histogram").map(|k| k["name"].to_string()),
    );
    let constants = field(&package, &["constants"])?.as_object().map(|c| c.keys().cloned().collect::<Vec<_>>());
    let declarations = fill(
        DECLARATIONS,
        "strata.d.ts",
        &[
            ("STRATA_VERSION", version.clone()),
            ("STRATA_SAMPLER_NAMES", quoted(&["samplers"], "name")?),
            ("STRATA_BLOCK_SIZES", union(BLOCK_SIZES.iter().map(u32::to_string))),
            ("STRATA_HISTOGRAM_KERNELS", histogram_kernels),
            ("STRATA_RECORD_NAMES", quoted(&["structs"], "name")?),
            (
                "STRATA_CONSTANT_FIELDS",
                constants.unwrap_or_default().iter().map(|name| format!("  readonly {name}: number;\n")).collect(),
            ),
        ],
    )?;
    let example = fill(EXAMPLE, "example.html", &[("STRATA_VERSION", version.clone())])?;
    let example_script = fill(EXAMPLE_SCRIPT, "example.js", &[("STRATA_VERSION", version)])?;
    Ok([module, declarations, example, example_script])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The placeholders the templates have are the ones [`files`] fills, and the module's
    /// code reads no binding number of its own: every `binding` it uses comes from the
    /// package object.
    #[test]
    fn templates_have_no_hand_written_binding_numbers_and_every_placeholder_is_filled() {
        let template = TEMPLATE.replacen(PACKAGE_PLACEHOLDER, "", 1);
        assert!(!template.contains("@binding"), "the template declares no binding");
        for line in template.lines() {
            let code = line.split("//").next().unwrap_or_default();
            assert!(!code.contains("binding: 0") && !code.contains("binding: 1"), "a literal binding: {line}");
        }
        assert!(fill("x @STRATA_NOT_A_NAME@", "t", &[]).is_err());
        assert_eq!(fill("a @STRATA_VERSION@", "t", &[("STRATA_VERSION", "1.2.3".into())]).unwrap(), "a 1.2.3");
    }
}
