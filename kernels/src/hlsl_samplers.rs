//! naga's HLSL samplers made plain HLSL samplers, for the HLSL compilers that target
//! Vulkan (glslang, Slang).
//!
//! naga's HLSL writer (30) declares no sampler per WGSL binding: it declares a heap
//! `SamplerState nagaSamplerHeap[2048]` (and one of comparison samplers) and per bind
//! group a `StructuredBuffer<uint> nagaGroupGSamplerIndexArray`, and reads the sampler of
//! `@group(G) @binding(B)` once into `static const SamplerState name =
//! nagaSamplerHeap[nagaGroupGSamplerIndexArray[B]];`. That is D3D12's descriptor-heap
//! model; compiled for Vulkan it fails both ways measured here: glslang makes the
//! sampler a variable in Private memory, on which lavapipe 22.3 crashes while compiling
//! the pipeline, and Slang refuses the initializer as not a compile-time constant.
//! [`plain_samplers`] declares each such sampler at its own register instead
//! (`SamplerState name : register(sB, spaceG);`, binding B of set G as for every other
//! resource) and drops the heaps and index buffers.

/// The HLSL with naga's heap samplers declared at their WGSL registers, or the line it
/// cannot read (naga's output changed: update this).
pub fn plain_samplers(hlsl: &str) -> Result<String, String> {
    if !hlsl.contains("nagaSamplerHeap") {
        return Ok(hlsl.to_string());
    }
    let mut out = String::with_capacity(hlsl.len());
    for line in hlsl.lines() {
        let heap_declaration = line.starts_with("SamplerState nagaSamplerHeap[")
            || line.starts_with("SamplerComparisonState nagaComparisonSamplerHeap[")
            || (line.starts_with("StructuredBuffer<uint> nagaGroup") && line.contains("SamplerIndexArray"));
        if heap_declaration {
            continue;
        }
        if let Some(rest) = line.strip_prefix("static const SamplerState ") {
            let parsed = parse_heap_sampler(rest)
                .ok_or_else(|| format!("naga's HLSL has a heap sampler this rewrite cannot read: `{line}`"))?;
            let (name, group, binding) = parsed;
            out.push_str(&format!("SamplerState {name} : register(s{binding}, space{group});\n"));
            continue;
        }
        if line.contains("nagaSamplerHeap") || line.contains("nagaComparisonSamplerHeap") {
            return Err(format!("naga's HLSL uses its sampler heap where this rewrite does not know it: `{line}`"));
        }
        out.push_str(line);
        out.push('\n');
    }
    Ok(out)
}

/// `name = nagaSamplerHeap[nagaGroupGSamplerIndexArray[B]];` as (name, G, B).
fn parse_heap_sampler(text: &str) -> Option<(&str, u32, u32)> {
    let (name, access) = text.strip_suffix(';')?.split_once(" = ")?;
    let rest = access.strip_prefix("nagaSamplerHeap[nagaGroup")?;
    let digits = rest.find(|c: char| !c.is_ascii_digit())?;
    let group = rest[..digits].parse().ok()?;
    let rest = rest[digits..].strip_prefix("SamplerIndexArray")?;
    let rest = &rest[rest.find('[')? + 1..];
    let binding = rest.strip_suffix("]]")?.parse().ok()?;
    name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_').then_some((name, group, binding))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn heap_samplers_become_registers_and_the_heap_goes() {
        let hlsl = "Texture2D<float4> src : register(t0);\n\
                    SamplerState nagaSamplerHeap[2048]: register(s0, space0);\n\
                    SamplerComparisonState nagaComparisonSamplerHeap[2048]: register(s0, space1);\n\
                    StructuredBuffer<uint> nagaGroup2SamplerIndexArray : register(t2, space255);\n\
                    static const SamplerState smp = nagaSamplerHeap[nagaGroup2SamplerIndexArray[7]];\n\
                    static const float k = 2.0;\n";
        let out = plain_samplers(hlsl).unwrap();
        assert_eq!(
            out,
            "Texture2D<float4> src : register(t0);\nSamplerState smp : register(s7, space2);\nstatic const float k = 2.0;\n"
        );
        assert_eq!(plain_samplers("float4 x;\n").unwrap(), "float4 x;\n");
        let unknown = "SamplerState nagaSamplerHeap[2048]: register(s0, space0);\nfoo(nagaSamplerHeap[i]);\n";
        assert!(plain_samplers(unknown).unwrap_err().contains("foo(nagaSamplerHeap[i])"));
    }
}
