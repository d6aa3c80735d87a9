// The buffer contract of the embeddable selection (strata-embed): the records an engine
// and the strata_select / strata_resample kernels exchange, declared once in Rust
// (kernels/src/embed_types.rs, which generates gpu/embed.wgsl). An engine that
// owns its candidates, reservoirs, shift mapping and shading writes one Candidate per
// pixel (strata/candidate.wgsl: luminance key + cluster id) and optionally one payload
// index per pixel; the histogram pass sorts each block; strata_select gives every pixel K
// payload indices of its own cluster's run at stratified positions; strata_resample,
// given the engine's resampling weights, picks one by inverse CDF (paper §4.2, whose
// functions are in strata/selection.wgsl). With what it imports (strata/candidate.wgsl and
// the generated gpu/ modules) it is what an engine prepends to its own shaders
// (strata_embed::wgsl::contract_source gives the whole text).

// #import gpu/embed.wgsl
// #import strata/candidate.wgsl

