//! Denoising the frames an engine would show: SVGF (Schied et al. 2017) as four kernels
//! (`kernels/wgsl/denoise/`) driven on any backend, and Intel Open Image Denoise on the
//! CPU ([`oidn`], spatial only, its library opened at run time). Both read only what an
//! engine has: the noisy colour and a per-pixel guide (albedo, depth, normal, object,
//! motion; [`strata_kernels::denoise_types::DenoiseGuide`]), which the ReSTIR renderer
//! writes with [`crate::restir::RestirRenderer::enable_guides`].

pub mod oidn;
mod settings;
mod svgf;

pub use oidn::{OidnDenoiser, OidnError, OidnLibrary};
pub use settings::{Denoiser, SvgfSettings};
pub use svgf::SvgfDenoiser;
