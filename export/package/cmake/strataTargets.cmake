# strataTargets.cmake: the targets and variables of strata's kernel package, shared by
# strataConfig.cmake (find_package(strata CONFIG)) and the package's CMakeLists.txt
# (add_subdirectory). Written by `cargo xtask export` for strata @STRATA_VERSION@; do not edit.
#
# Targets:
#   strata::headers  INTERFACE: include/ (strata.h, strata_frame.h, strata_vk.h)
#   strata::vk       the C ABI library strata_vk (libstrata_vk.so, strata_vk.dll,
#                    libstrata_vk.dylib), when found: set STRATA_VK_LIBRARY to its path, or
#                    put it in the package's lib/ folder
# Variables (and the same as properties of strata::headers):
#   STRATA_INCLUDE_DIR, STRATA_MANIFEST, STRATA_BLUE_NOISE, STRATA_VERSION,
#   STRATA_SPIRV_DIR, STRATA_HLSL_DIR, STRATA_MSL_DIR, STRATA_GLSL_DIR, STRATA_WGSL_DIR
#   (the kernels' folders per language), strata_vk_FOUND.

get_filename_component(_strata_root "${CMAKE_CURRENT_LIST_DIR}/../../.." ABSOLUTE)

set(STRATA_VERSION "@STRATA_VERSION@")
set(STRATA_INCLUDE_DIR "${_strata_root}/include")
set(STRATA_MANIFEST "${_strata_root}/manifest.json")
set(STRATA_BLUE_NOISE "${_strata_root}/data/blue_noise.bin")
set(STRATA_SPIRV_DIR "${_strata_root}/kernels/spirv")
set(STRATA_HLSL_DIR "${_strata_root}/kernels/hlsl")
set(STRATA_MSL_DIR "${_strata_root}/kernels/msl")
set(STRATA_GLSL_DIR "${_strata_root}/kernels/glsl")
set(STRATA_WGSL_DIR "${_strata_root}/kernels/wgsl")
set(_strata_variables STRATA_VERSION STRATA_INCLUDE_DIR STRATA_MANIFEST STRATA_BLUE_NOISE STRATA_SPIRV_DIR
    STRATA_HLSL_DIR STRATA_MSL_DIR STRATA_GLSL_DIR STRATA_WGSL_DIR)

if(NOT TARGET strata::headers)
  add_library(strata::headers INTERFACE IMPORTED GLOBAL)
  set_target_properties(strata::headers PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${STRATA_INCLUDE_DIR}")
  foreach(_strata_variable IN LISTS _strata_variables)
    set_property(TARGET strata::headers PROPERTY "${_strata_variable}" "${${_strata_variable}}")
  endforeach()
endif()

find_library(STRATA_VK_LIBRARY NAMES strata_vk HINTS "${_strata_root}/lib"
             DOC "the strata_vk library (cargo build --release -p strata-vk)")
set(strata_vk_FOUND FALSE)
if(STRATA_VK_LIBRARY)
  set(strata_vk_FOUND TRUE)
  if(NOT TARGET strata::vk)
    add_library(strata::vk SHARED IMPORTED GLOBAL)
    set_target_properties(strata::vk PROPERTIES IMPORTED_LOCATION "${STRATA_VK_LIBRARY}"
                                                INTERFACE_LINK_LIBRARIES strata::headers)
    if(WIN32)
      # strata_vk.dll's import library, beside it.
      get_filename_component(_strata_vk_folder "${STRATA_VK_LIBRARY}" DIRECTORY)
      set_target_properties(strata::vk PROPERTIES IMPORTED_IMPLIB "${_strata_vk_folder}/strata_vk.dll.lib")
    endif()
    # strata_vk.h includes <vulkan/vulkan.h>.
    find_package(Vulkan QUIET)
    if(TARGET Vulkan::Headers)
      set_property(TARGET strata::vk APPEND PROPERTY INTERFACE_LINK_LIBRARIES Vulkan::Headers)
    endif()
  endif()
endif()
