// slang_hlsl: compiles one HLSL compute shader to SPIR-V (Vulkan) with the Slang compiler
// library, the second HLSL front end strata checks its HLSL with (besides glslang's).
// Built by strata_kernels::slang against the library and headers of the `slangpy` wheel
// (PyPI), which ships the compiler as a library but no command-line tool.
//
//   slang_hlsl FILE.hlsl ENTRY OUT.spv
//
// HLSL registers map to Vulkan bindings one to one (bN, tN, uN, sN -> binding N of set
// `space`, in every space: a shift given for space 0 alone left space 1's registers in
// set 0), as naga writes them from WGSL's @group/@binding. Part of strata (MIT OR
// Apache-2.0).
#include <slang.h>

#include <cstdio>

int main(int argc, char **argv) {
    if (argc != 4) {
        std::fprintf(stderr, "usage: slang_hlsl FILE.hlsl ENTRY OUT.spv\n");
        return 2;
    }
    SlangSession *session = spCreateSession();
    SlangCompileRequest *request = spCreateCompileRequest(session);
    const char *args[] = {"-lang", "hlsl", "-target", "spirv", "-profile", "cs_6_0", "-entry", argv[2],
                          "-fvk-use-entrypoint-name", "-fvk-b-shift", "0", "all", "-fvk-t-shift", "0", "all",
                          "-fvk-u-shift", "0", "all", "-fvk-s-shift", "0", "all", argv[1]};
    if (SLANG_FAILED(spProcessCommandLineArguments(request, args, sizeof args / sizeof args[0]))) {
        std::fprintf(stderr, "%s", spGetDiagnosticOutput(request));
        return 1;
    }
    if (SLANG_FAILED(spCompile(request))) {
        std::fprintf(stderr, "%s", spGetDiagnosticOutput(request));
        return 1;
    }
    ISlangBlob *blob = nullptr;
    if (SLANG_FAILED(spGetTargetCodeBlob(request, 0, &blob)) || blob == nullptr) {
        std::fprintf(stderr, "no SPIR-V: %s", spGetDiagnosticOutput(request));
        return 1;
    }
    FILE *out = std::fopen(argv[3], "wb");
    size_t size = blob->getBufferSize();
    if (out == nullptr || std::fwrite(blob->getBufferPointer(), 1, size, out) != size || std::fclose(out) != 0) {
        std::fprintf(stderr, "%s: cannot write\n", argv[3]);
        return 1;
    }
    blob->release();
    spDestroyCompileRequest(request);
    spDestroySession(session);
    return 0;
}
