# strataConfig.cmake: find_package(strata CONFIG [COMPONENTS vk]) for strata's kernel
# package (@STRATA_VERSION@). Point CMake at the package: -Dstrata_DIR=PACKAGE/lib/cmake/strata
# or CMAKE_PREFIX_PATH=PACKAGE. The component `vk` is the strata_vk library (strata::vk).
# Written by `cargo xtask export`; do not edit.

include("${CMAKE_CURRENT_LIST_DIR}/strataTargets.cmake")

foreach(_strata_component IN LISTS strata_FIND_COMPONENTS)
  if(NOT _strata_component STREQUAL "vk")
    set(strata_FOUND FALSE)
    set(strata_NOT_FOUND_MESSAGE "strata has no component `${_strata_component}` (it has: vk)")
  elseif(NOT strata_vk_FOUND AND strata_FIND_REQUIRED_vk)
    set(strata_FOUND FALSE)
    set(strata_NOT_FOUND_MESSAGE
        "strata component vk: the strata_vk library was not found: set STRATA_VK_LIBRARY to its path")
  endif()
endforeach()
