// A C++17 engine's first contact with strata's kernel package, built with CMake
// (CMakeLists.txt beside it): the headers compile as C++, the library links, its version
// matches the headers', a header of another major version is refused, and the package's
// files are where the CMake package says. Needs no GPU. Part of strata (MIT OR Apache-2.0).
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>

#include "strata_vk.h"

namespace {

bool readable(const std::string &path) { return std::ifstream(path, std::ios::binary).good(); }

int fail(const char *what) {
    std::fprintf(stderr, "error: %s\n", what);
    return 1;
}

}  // namespace

int main() {
    static_assert(sizeof(StrataSelectedCandidates) % 4 == 0, "records are whole words");
    if (strata_vk_version_number() != STRATA_VERSION) {
        return fail("the library's version is not the headers' (STRATA_VERSION)");
    }
    StrataError error{};
    StrataVkPass *pass = nullptr;
    StrataSelectionSettings settings = strata_default_settings();
    // Headers one major version newer: refused before anything else is read.
    uint32_t newer = STRATA_MAKE_VERSION(STRATA_VERSION_MAJOR + 1, 0, 0);
    if (strata_vk_create(newer, nullptr, &settings, 16, 16, &pass, &error) != STRATA_STATUS_VERSION) {
        return fail("a header of another major version was not refused");
    }
    // The right headers: the NULL device is what is refused.
    if (strata_vk_create(STRATA_VERSION, nullptr, &settings, 16, 16, &pass, &error) != STRATA_STATUS_INVALID_ARGUMENT ||
        std::strcmp(error.message, "device is NULL") != 0) {
        return fail("strata_vk_create did not refuse a NULL device");
    }
    if (!readable(std::string(STRATA_CONSUMER_SPIRV_DIR) + "/strata_select.spv") || !readable(STRATA_CONSUMER_MANIFEST)) {
        return fail("the package's kernels or manifest are not where its CMake package says");
    }
    std::printf("strata %s (headers %d.%d.%d): ok\n", strata_vk_version(), STRATA_VERSION_MAJOR, STRATA_VERSION_MINOR,
                STRATA_VERSION_PATCH);
    return 0;
}
