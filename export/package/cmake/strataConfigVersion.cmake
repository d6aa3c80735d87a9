# strataConfigVersion.cmake: which versions asked of find_package(strata VERSION) this
# package (@STRATA_VERSION@) satisfies: the same major version, and before 1.0 the same
# minor version (as strata_vk_create accepts headers), not older than asked.
# Written by `cargo xtask export`; do not edit.

set(PACKAGE_VERSION "@STRATA_VERSION@")
set(PACKAGE_VERSION_COMPATIBLE FALSE)
if(PACKAGE_FIND_VERSION_MAJOR STREQUAL "@STRATA_VERSION_MAJOR@"
   AND NOT PACKAGE_FIND_VERSION VERSION_GREATER PACKAGE_VERSION
   AND (NOT "@STRATA_VERSION_MAJOR@" STREQUAL "0" OR PACKAGE_FIND_VERSION_MINOR STREQUAL "@STRATA_VERSION_MINOR@"))
  set(PACKAGE_VERSION_COMPATIBLE TRUE)
endif()
if(PACKAGE_FIND_VERSION STREQUAL PACKAGE_VERSION)
  set(PACKAGE_VERSION_EXACT TRUE)
endif()
