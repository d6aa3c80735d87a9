fn main() {
    let args: Vec<String> = std::env::args().collect();
    let src = std::fs::read_to_string(&args[1]).unwrap();
    let k = strata_kernels::Kernel::from_wgsl(&args[1], src, &args[2], false).unwrap();
    let opts = strata_kernels::translate::TranslateOptions { workgroup_zero_init: strata_kernels::translate::WorkgroupZeroInit::Off };
    let t = if args[3] == "hlsl" { strata_kernels::translate::hlsl(&k, opts).unwrap() } else { strata_kernels::translate::glsl(&k, opts).unwrap() };
    println!("{}", t.text);
}
