//! Each exported kernel in the five languages an engine may compile, with the names and
//! registers the back ends gave it: naga's SPIR-V (Vulkan 1.1), HLSL (shader model 6.0,
//! `register(..., space...)` from WGSL's group and binding), MSL (2.1, `[[buffer(n)]]`
//! from the binding number, the array-sizes buffer at index 30), GLSL 4.50 for Vulkan
//! (`layout(set = g, binding = b)`) and the WGSL itself.

use crate::ExportError;
use strata_kernels::Kernel;
use strata_kernels::translate::{TranslateOptions, Translation, WorkgroupZeroInit};

/// The MSL buffer index of the array-sizes buffer naga's MSL writer reads
/// (`_mslBufferSizes`: one `uint` per runtime-sized binding).
pub const MSL_SIZES_BUFFER: u32 = 30;

/// One kernel in every language.
pub struct Translated {
    /// SPIR-V words.
    pub spirv: Vec<u32>,
    /// HLSL text and its entry point's name.
    pub hlsl: Translation,
    /// MSL text and its entry point's name.
    pub msl: Translation,
    /// GLSL text for Vulkan (entry point `main`).
    pub glsl: String,
    /// The WGSL source.
    pub wgsl: String,
    /// Each binding's HLSL register (`b0`, `t1`, `u6`) and space, by WGSL name.
    pub hlsl_registers: Vec<(String, String, u32)>,
    /// The bindings whose sizes naga's MSL reads from the sizes buffer, in the order of
    /// its members (`_mslBufferSizes { uint sizeN; ... }`, N the global's handle).
    pub msl_sized_bindings: Vec<String>,
}

/// Translates `kernel`. Workgroup memory is zeroed by the shader itself, in loops its
/// invocations share (every API and driver; the Rust flavours can leave it to a Vulkan 1.3
/// driver instead).
pub fn translate(kernel: &Kernel) -> Result<Translated, ExportError> {
    let options = TranslateOptions { workgroup_zero_init: WorkgroupZeroInit::Polyfill };
    let failed = |error: strata_kernels::KernelError| ExportError::Translation(error.to_string());
    let spirv = strata_kernels::translate::spirv(kernel, options).map_err(failed)?.words;
    let mut hlsl = strata_kernels::translate::hlsl(kernel, options).map_err(failed)?;
    hlsl.text = explicit_spaces(kernel, &hlsl.text)?;
    let msl = strata_kernels::translate::msl_version(kernel, options, (2, 1)).map_err(failed)?;
    let glsl = vulkan_glsl(kernel, &strata_kernels::translate::glsl(kernel, options).map_err(failed)?.text)?;
    let hlsl_registers = hlsl_registers(kernel, &hlsl.text)?;
    let msl_sized_bindings = msl_sized_bindings(kernel, &msl.text)?;
    Ok(Translated { spirv, hlsl, msl, glsl, wgsl: kernel.source.text.clone(), hlsl_registers, msl_sized_bindings })
}

/// The order of the members of naga's MSL sizes buffer, read from the MSL the package
/// ships: member `sizeN` holds the byte size of global variable N.
fn msl_sized_bindings(kernel: &Kernel, text: &str) -> Result<Vec<String>, ExportError> {
    let Some(start) = text.find("struct _mslBufferSizes {") else { return Ok(Vec::new()) };
    let body = &text[start..text[start..].find("};").map_or(text.len(), |end| start + end)];
    let globals: Vec<&naga::GlobalVariable> = kernel.module.global_variables.iter().map(|(_, g)| g).collect();
    body.lines()
        .filter_map(|line| line.trim().strip_prefix("uint size").and_then(|rest| rest.strip_suffix(';')))
        .map(|index| {
            let name = index.parse::<usize>().ok().and_then(|i| globals.get(i)).and_then(|g| g.name.clone());
            name.ok_or_else(|| {
                ExportError::Translation(format!("{}: MSL sizes member `size{index}` names no global", kernel.name()))
            })
        })
        .collect()
}

/// naga's GLSL (written for OpenGL: `layout(..., binding = b)`) with each binding's
/// descriptor set written in, as GLSL for Vulkan needs (`layout(..., set = g, binding = b)`).
/// Every binding line must be found, or the export fails naming the kernel.
fn vulkan_glsl(kernel: &Kernel, text: &str) -> Result<String, ExportError> {
    let mut out = String::with_capacity(text.len() + 64);
    let mut found = 0;
    for line in text.lines() {
        let rewritten = kernel.bindings.iter().find_map(|binding| {
            let marker = format!("binding = {})", binding.binding);
            (line.starts_with("layout(") && line.contains(&marker))
                .then(|| line.replacen(&marker, &format!("set = {}, binding = {})", binding.group, binding.binding), 1))
        });
        if rewritten.is_some() {
            found += 1;
        }
        out += rewritten.as_deref().unwrap_or(line);
        out.push('\n');
    }
    if found != kernel.bindings.len() {
        return Err(ExportError::Translation(format!(
            "{}: found {found} of its {} bindings in naga's GLSL",
            kernel.name(),
            kernel.bindings.len()
        )));
    }
    Ok(out)
}

/// naga's HLSL with every binding's register space written out (`register(u6)` →
/// `register(u6, space0)`; naga leaves space 0 implicit), so that a D3D12 root signature
/// can be read off the file as well as off the manifest.
fn explicit_spaces(kernel: &Kernel, text: &str) -> Result<String, ExportError> {
    let mut text = text.to_string();
    for binding in &kernel.bindings {
        let marker = format!("{} : register(", binding.name);
        let Some(start) = text.find(&marker) else {
            return Err(ExportError::Translation(format!(
                "{}: no HLSL register for `{}`",
                kernel.name(),
                binding.name
            )));
        };
        let open = start + marker.len();
        let close = open + text[open..].find(')').unwrap_or(0);
        if !text[open..close].contains(',') {
            text.insert_str(close, &format!(", space{}", binding.group));
        }
    }
    Ok(text)
}

/// Each binding's register and space as naga's HLSL declares it (`... name :
/// register(u6, space0);`), read from the text the package ships.
fn hlsl_registers(kernel: &Kernel, text: &str) -> Result<Vec<(String, String, u32)>, ExportError> {
    kernel
        .bindings
        .iter()
        .map(|binding| {
            let declaration = text
                .lines()
                .find(|line| {
                    line.contains("register(")
                        && line.split(|c: char| !(c.is_alphanumeric() || c == '_')).any(|word| word == binding.name)
                })
                .ok_or_else(|| {
                    ExportError::Translation(format!("{}: no HLSL register for `{}`", kernel.name(), binding.name))
                })?;
            let inside = declaration.split("register(").nth(1).and_then(|rest| rest.split(')').next()).unwrap_or("");
            let (register, space) = inside.split_once(',').unwrap_or((inside, "space0"));
            let space = space.trim().trim_start_matches("space").parse::<u32>().map_err(|_| {
                ExportError::Translation(format!("{}: HLSL register `{inside}` has no space", kernel.name()))
            })?;
            Ok((binding.name.clone(), register.trim().to_string(), space))
        })
        .collect()
}
