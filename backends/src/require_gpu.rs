//! `STRATA_REQUIRE_GPU=1`: tests that need a GPU device fail instead of skipping.

/// The environment variable that makes a missing GPU device an error.
pub const GPU_REQUIRED_VARIABLE: &str = "STRATA_REQUIRE_GPU";

/// Whether `STRATA_REQUIRE_GPU` is set to anything but empty or `0`.
pub fn gpu_required() -> bool {
    std::env::var(GPU_REQUIRED_VARIABLE).is_ok_and(|v| !v.is_empty() && v != "0")
}
