//! The `XDG_RUNTIME_DIR` the host's tests give the `strata` processes they start. Included
//! by `#[path]` in each test file that starts one (`mod support;` would bring the other
//! support modules too, unused there).

/// A name that does not exist, in cargo's target folder, not the shared `/tmp`: Mesa's
/// Vulkan layer connects to `$XDG_RUNTIME_DIR/wayland-0`, which anyone could create in
/// `/tmp` (SECURITY.md, "The display socket"). Any absolute path keeps Wayland's client
/// from printing that the variable is unset.
pub const NO_DISPLAY: &str = concat!(env!("CARGO_TARGET_TMPDIR"), "/no-display");
