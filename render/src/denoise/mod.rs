//! Denoising the frames an engine would show: SVGF (Schied et al. 2017) as four kernels
//! (`kernels/wgsl/denoise/`) driven on any backend, and Intel Open Image Denoise on the
//! CPU ([`oidn`], spatial only, its library opened at run time). Both read only what an
//! engine has: the noisy colour and a per-pixel guide (albedo, depth, normal, object,
//! motion; [`strata_kernels::denoise_types::DenoiseGuide`]), which the ReSTIR renderer
//! writes with [`crate::restir::RestirRenderer::enable_guides`].

// Open Image Denoise is a native library opened at run time: not in a web page.
#[cfg(not(target_arch = "wasm32"))]
pub mod oidn;
mod settings;
mod svgf;

#[cfg(not(target_arch = "wasm32"))]
pub use oidn::{OidnDenoiser, OidnError, OidnLibrary};
pub use settings::{Denoiser, SvgfSettings};
pub use svgf::SvgfDenoiser;
