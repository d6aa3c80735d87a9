//! Intel Open Image Denoise (OIDN), the neural denoiser behind Blender/Cycles and many
//! offline renderers, as a second denoiser (`strata compare --denoise oidn`). It is a
//! spatial-only filter: each frame is denoised on its own, with no history, from its HDR
//! colour and the guides' albedo and normal ([`DenoiseGuide`]). It runs on the CPU.
//!
//! The library is opened at run time ([`OidnLibrary::find`]), never linked: a build needs
//! neither it nor its headers, and only a run that asks for OIDN needs it installed. It is
//! looked for in the file [`LIBRARY_VARIABLE`] names if set, else in the `pyoidn` wheel's
//! folder (`pip install pyoidn==2.5.1.0`, found through `python3`), else by the system's
//! own search for [`LIBRARY_NAME`]. The few C functions used are declared here from
//! OIDN 2's public API (`include/OpenImageDenoise/oidn.h`).

use std::ffi::{CStr, c_char, c_int, c_void};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use strata_kernels::denoise_types::DenoiseGuide;

use crate::rgb_image::RgbImage;

/// The environment variable that names the library file to open, skipping the search.
pub const LIBRARY_VARIABLE: &str = "STRATA_OIDN_LIBRARY";

/// The library's file name (OIDN 2's ABI), as the system's search and the wheel name it.
#[cfg(target_os = "linux")]
pub const LIBRARY_NAME: &str = "libOpenImageDenoise.so.2";
/// The library's file name (OIDN 2's ABI), as the system's search and the wheel name it.
#[cfg(target_os = "macos")]
pub const LIBRARY_NAME: &str = "libOpenImageDenoise.2.dylib";
/// The library's file name (OIDN 2's ABI), as the system's search and the wheel name it.
#[cfg(windows)]
pub const LIBRARY_NAME: &str = "OpenImageDenoise.dll";
/// The library's file name (OIDN 2's ABI), as the system's search and the wheel name it.
#[cfg(not(any(target_os = "linux", target_os = "macos", windows)))]
pub const LIBRARY_NAME: &str = "libOpenImageDenoise.so.2";

/// What a user installs to get the library: the `pyoidn` wheel, whose `oidn/lib` folder
/// holds OIDN 2.5.1's CPU device with its weights built in.
pub const PIP_PACKAGE: &str = "pyoidn==2.5.1.0";

/// Why OIDN could not be opened or run: one line each, naming what is wrong.
#[derive(Debug, thiserror::Error, Clone, PartialEq, Eq)]
pub enum OidnError {
    /// No library was found anywhere it is looked for.
    #[error("{LIBRARY_NAME} not found (pip install {PIP_PACKAGE}, or set {LIBRARY_VARIABLE} to its path)")]
    NotFound,
    /// [`LIBRARY_VARIABLE`] names no file.
    #[error("{LIBRARY_VARIABLE}={0}: no such file (set it to the path of {LIBRARY_NAME}, or unset it)")]
    NoSuchFile(String),
    /// The file exists but the system's loader refused it.
    #[error("cannot load {path}: {reason}")]
    Load {
        /// The file.
        path: String,
        /// The loader's reason, on one line.
        reason: String,
    },
    /// The library lacks one of the functions used: not OIDN 2.
    #[error("{path} has no function {function}: not Open Image Denoise 2")]
    Symbol {
        /// The file.
        path: String,
        /// The missing function.
        function: &'static str,
    },
    /// The library is another major version than the 2 these declarations are for.
    #[error("{path} is Open Image Denoise {major}, not 2")]
    Version {
        /// The file.
        path: String,
        /// Its major version.
        major: i32,
    },
    /// OIDN reported an error (`oidnGetDeviceError`).
    #[error("Open Image Denoise: {operation} failed: {code}: {message}")]
    Device {
        /// What was being done.
        operation: &'static str,
        /// The error code's name (`OIDN_ERROR_*`).
        code: &'static str,
        /// OIDN's message.
        message: String,
    },
    /// Images whose sizes or values OIDN cannot take.
    #[error("Open Image Denoise: {0}")]
    Input(String),
}

// The declarations of the C API used, from OIDN 2's `oidn.h`. C enums are `int`; C99
// `bool` is Rust's `bool`; handles are opaque pointers.
type DevicePtr = *mut c_void;
type FilterPtr = *mut c_void;
type BufferPtr = *mut c_void;
/// `OIDN_DEVICE_TYPE_CPU`.
const DEVICE_TYPE_CPU: c_int = 1;
/// `OIDN_FORMAT_FLOAT3`: three 32-bit floats per pixel.
const FORMAT_FLOAT3: c_int = 3;
/// `OIDN_ERROR_NONE`.
const ERROR_NONE: c_int = 0;
/// The names of `OIDNError`'s values, in order from 0.
const ERROR_NAMES: [&str; 7] = [
    "OIDN_ERROR_NONE",
    "OIDN_ERROR_UNKNOWN",
    "OIDN_ERROR_INVALID_ARGUMENT",
    "OIDN_ERROR_INVALID_OPERATION",
    "OIDN_ERROR_OUT_OF_MEMORY",
    "OIDN_ERROR_UNSUPPORTED_HARDWARE",
    "OIDN_ERROR_CANCELLED",
];

/// The functions used, resolved from the library once.
struct Api {
    new_device: unsafe extern "C" fn(c_int) -> DevicePtr,
    commit_device: unsafe extern "C" fn(DevicePtr),
    get_device_error: unsafe extern "C" fn(DevicePtr, *mut *const c_char) -> c_int,
    get_device_int: unsafe extern "C" fn(DevicePtr, *const c_char) -> c_int,
    release_device: unsafe extern "C" fn(DevicePtr),
    new_buffer: unsafe extern "C" fn(DevicePtr, usize) -> BufferPtr,
    write_buffer: unsafe extern "C" fn(BufferPtr, usize, usize, *const c_void),
    read_buffer: unsafe extern "C" fn(BufferPtr, usize, usize, *mut c_void),
    release_buffer: unsafe extern "C" fn(BufferPtr),
    new_filter: unsafe extern "C" fn(DevicePtr, *const c_char) -> FilterPtr,
    #[allow(clippy::type_complexity)]
    set_filter_image:
        unsafe extern "C" fn(FilterPtr, *const c_char, BufferPtr, c_int, usize, usize, usize, usize, usize),
    set_filter_bool: unsafe extern "C" fn(FilterPtr, *const c_char, bool),
    commit_filter: unsafe extern "C" fn(FilterPtr),
    execute_filter: unsafe extern "C" fn(FilterPtr),
    release_filter: unsafe extern "C" fn(FilterPtr),
}

impl Api {
    /// Resolves every function of `library`, opened from `path`.
    fn resolve(library: &libloading::Library, path: &str) -> Result<Api, OidnError> {
        /// One function by its C name, as the pointer type the field declares.
        fn get<T: Copy>(library: &libloading::Library, path: &str, function: &'static str) -> Result<T, OidnError> {
            let name = format!("{function}\0");
            // SAFETY: `T` is the `unsafe extern "C" fn` type of the field it is assigned
            // to, each declared above from `oidn.h`'s prototype of `function`; the
            // pointer is used only while the library stays loaded, which is forever
            // (`OidnLibrary` never unloads it).
            let symbol = unsafe { library.get::<T>(name.as_bytes()) };
            symbol.map(|s| *s).map_err(|_| OidnError::Symbol { path: path.to_string(), function })
        }
        Ok(Api {
            new_device: get(library, path, "oidnNewDevice")?,
            commit_device: get(library, path, "oidnCommitDevice")?,
            get_device_error: get(library, path, "oidnGetDeviceError")?,
            get_device_int: get(library, path, "oidnGetDeviceInt")?,
            release_device: get(library, path, "oidnReleaseDevice")?,
            new_buffer: get(library, path, "oidnNewBuffer")?,
            write_buffer: get(library, path, "oidnWriteBuffer")?,
            read_buffer: get(library, path, "oidnReadBuffer")?,
            release_buffer: get(library, path, "oidnReleaseBuffer")?,
            new_filter: get(library, path, "oidnNewFilter")?,
            set_filter_image: get(library, path, "oidnSetFilterImage")?,
            set_filter_bool: get(library, path, "oidnSetFilterBool")?,
            commit_filter: get(library, path, "oidnCommitFilter")?,
            execute_filter: get(library, path, "oidnExecuteFilter")?,
            release_filter: get(library, path, "oidnReleaseFilter")?,
        })
    }
}

/// An opened Open Image Denoise library. Opened once per file for the whole process and
/// never unloaded (its worker threads may outlive a filter), so copies are cheap.
#[derive(Clone, Copy)]
pub struct OidnLibrary {
    api: &'static Api,
    path: &'static str,
}

impl std::fmt::Debug for OidnLibrary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("OidnLibrary").field("path", &self.path).finish()
    }
}

/// Libraries opened so far, by the name they were opened with.
static OPENED: Mutex<Vec<OidnLibrary>> = Mutex::new(Vec::new());

impl OidnLibrary {
    /// Finds and opens the library: the file [`LIBRARY_VARIABLE`] names if it is set,
    /// else `oidn/lib/`[`LIBRARY_NAME`] in the `pyoidn` package's folder (asked of
    /// `python3`), else [`LIBRARY_NAME`] through the system's own search.
    pub fn find() -> Result<OidnLibrary, OidnError> {
        if let Some(path) = std::env::var_os(LIBRARY_VARIABLE) {
            let path = PathBuf::from(path);
            if !path.is_file() {
                return Err(OidnError::NoSuchFile(path.display().to_string()));
            }
            return OidnLibrary::open(&path);
        }
        if let Some(path) = wheel_library().filter(|p| p.is_file()) {
            return OidnLibrary::open(&path);
        }
        match OidnLibrary::open(Path::new(LIBRARY_NAME)) {
            Err(OidnError::Load { .. }) => Err(OidnError::NotFound),
            other => other,
        }
    }

    /// Opens the library at `path` (a bare file name: through the system's search),
    /// checking that it has every function used and is OIDN 2.
    pub fn open(path: &Path) -> Result<OidnLibrary, OidnError> {
        let shown = path.display().to_string();
        let mut opened = OPENED.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        if let Some(library) = opened.iter().find(|l| l.path == shown) {
            return Ok(*library);
        }
        // SAFETY: opening a library runs its initialisers. The path is the user's own
        // choice (LIBRARY_VARIABLE), the user's installed pyoidn package or the system's
        // library folders: trusted as the user's environment is (SECURITY.md). OIDN's
        // initialisers have no preconditions.
        let library = unsafe { libloading::Library::new(path) }
            .map_err(|e| OidnError::Load { path: shown.clone(), reason: e.to_string().replace('\n', " ") })?;
        let api = Api::resolve(&library, &shown)?;
        // Never unloaded: the function pointers in `api` live as long as the process.
        std::mem::forget(library);
        let library = OidnLibrary { api: Box::leak(Box::new(api)), path: Box::leak(shown.into_boxed_str()) };
        library.check_version()?;
        opened.push(library);
        Ok(library)
    }

    /// Where the library was opened from (as given: a path, or the bare file name the
    /// system's search resolved).
    pub fn path(&self) -> &str {
        self.path
    }

    /// Refuses a library whose major version is not 2.
    fn check_version(&self) -> Result<(), OidnError> {
        let device = Device::new(self.api)?;
        // SAFETY: a live, committed device and a NUL-terminated parameter name.
        let major = unsafe { (self.api.get_device_int)(device.handle, c"versionMajor".as_ptr()) };
        device.check("reading the version")?;
        if major != 2 {
            return Err(OidnError::Version { path: self.path.to_string(), major });
        }
        Ok(())
    }
}

/// `oidn/lib/`[`LIBRARY_NAME`] in the installed `pyoidn` package's folder, asked of
/// `python3` without importing the package (which needs numpy), once per process (a
/// Python start is about 90 ms through pyenv's shim); `None` without Python or the
/// package.
fn wheel_library() -> Option<PathBuf> {
    static FOUND: std::sync::OnceLock<Option<PathBuf>> = std::sync::OnceLock::new();
    FOUND.get_or_init(ask_python_for_the_wheel_library).clone()
}

/// [`wheel_library`], asked of `python3`.
fn ask_python_for_the_wheel_library() -> Option<PathBuf> {
    let finder =
        "import importlib.util as u; s = u.find_spec('pyoidn'); print(s.submodule_search_locations[0] if s else '')";
    let output = std::process::Command::new("python3").args(["-c", finder]).output().ok()?;
    let folder = String::from_utf8_lossy(&output.stdout).trim().to_string();
    (output.status.success() && !folder.is_empty())
        .then(|| Path::new(&folder).join("oidn").join("lib").join(LIBRARY_NAME))
}

/// The first error OIDN stored for `device` (null: the thread's global errors) on this
/// thread, if any, cleared as it is read.
fn take_error(api: &Api, device: DevicePtr, operation: &'static str) -> Result<(), OidnError> {
    let mut message: *const c_char = std::ptr::null();
    // SAFETY: `device` is null or live; `message` is a valid place for OIDN to store a
    // pointer to its NUL-terminated message, valid until the next call on this thread,
    // and copied out before then.
    let code = unsafe { (api.get_device_error)(device, &mut message) };
    if code == ERROR_NONE {
        return Ok(());
    }
    let message = if message.is_null() {
        String::new()
    } else {
        // SAFETY: non-null, NUL-terminated, and not yet invalidated (see above).
        unsafe { CStr::from_ptr(message) }.to_string_lossy().replace('\n', " ")
    };
    let code = usize::try_from(code).ok().and_then(|c| ERROR_NAMES.get(c)).copied().unwrap_or("OIDN_ERROR_UNKNOWN");
    Err(OidnError::Device { operation, code, message })
}

/// A committed CPU device, released when dropped.
struct Device {
    api: &'static Api,
    handle: DevicePtr,
}

impl Device {
    /// A new committed CPU device.
    fn new(api: &'static Api) -> Result<Device, OidnError> {
        // SAFETY: no preconditions; a null result is an error OIDN stores per thread.
        let handle = unsafe { (api.new_device)(DEVICE_TYPE_CPU) };
        if handle.is_null() {
            take_error(api, std::ptr::null_mut(), "creating the CPU device")?;
            return Err(OidnError::Device {
                operation: "creating the CPU device",
                code: "OIDN_ERROR_UNKNOWN",
                message: "no device and no error".into(),
            });
        }
        let device = Device { api, handle };
        // SAFETY: a live device, committed once before use as the API requires.
        unsafe { (api.commit_device)(device.handle) };
        device.check("committing the CPU device")?;
        Ok(device)
    }

    /// The device's first stored error on this thread since the last check, if any.
    fn check(&self, operation: &'static str) -> Result<(), OidnError> {
        take_error(self.api, self.handle, operation)
    }
}

impl Drop for Device {
    fn drop(&mut self) {
        // SAFETY: a live device whose filters and buffers were released first (a
        // denoiser releases its own before its device field is dropped); not used after.
        unsafe { (self.api.release_device)(self.handle) };
    }
}

/// OIDN's `RT` filter (ray-traced images) for one image size, on its own CPU device,
/// denoising HDR colour with albedo and normal guides. Spatial only: each frame is
/// filtered on its own, with no history. Not `Send`: OIDN keeps its errors per thread.
pub struct OidnDenoiser {
    library: OidnLibrary,
    filter: FilterPtr,
    /// colour, albedo, normal, output: OIDN's own buffers of `width × height` FLOAT3.
    buffers: [BufferPtr; 4],
    width: u32,
    height: u32,
    /// Bytes of one image: `width × height × 12`.
    bytes: usize,
    /// Dropped after the filter and buffers are released ([`Drop`] runs first).
    device: Device,
}

impl std::fmt::Debug for OidnDenoiser {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("OidnDenoiser")
            .field("library", &self.library.path)
            .field("width", &self.width)
            .field("height", &self.height)
            .finish()
    }
}

/// The filter's images, in the order of [`OidnDenoiser`]'s buffers.
const IMAGES: [&CStr; 4] = [c"color", c"albedo", c"normal", c"output"];

impl OidnDenoiser {
    /// A committed filter for `width × height` images of `library`, its colour HDR and
    /// its guides clean (noise-free: the renderer's guides come from the primary hit, with
    /// no Monte Carlo noise, OIDN's `cleanAux`).
    pub fn new(library: OidnLibrary, width: u32, height: u32) -> Result<OidnDenoiser, OidnError> {
        let api = library.api;
        let pixels = usize::try_from(u64::from(width) * u64::from(height)).ok();
        let bytes = pixels.and_then(|p| p.checked_mul(size_of::<[f32; 3]>())).filter(|&b| b > 0).ok_or_else(|| {
            OidnError::Input(format!("a {width}x{height} image: its size must be positive and fit in memory"))
        })?;
        let device = Device::new(api)?;
        let handle = device.handle;
        let mut denoiser = OidnDenoiser {
            library,
            filter: std::ptr::null_mut(),
            buffers: [std::ptr::null_mut(); 4],
            width,
            height,
            bytes,
            device,
        };
        for index in 0..denoiser.buffers.len() {
            // SAFETY: a live device and a positive size; a null result is a stored error.
            let buffer = unsafe { (api.new_buffer)(handle, bytes) };
            denoiser.buffers[index] = buffer;
            denoiser.check("allocating a buffer")?;
            if buffer.is_null() {
                return Err(OidnError::Input(format!("no buffer of {bytes} bytes")));
            }
        }
        // SAFETY: a live device and a NUL-terminated filter type.
        denoiser.filter = unsafe { (api.new_filter)(handle, c"RT".as_ptr()) };
        denoiser.check("creating the RT filter")?;
        if denoiser.filter.is_null() {
            return Err(OidnError::Input("no RT filter".into()));
        }
        for (name, buffer) in IMAGES.iter().zip(denoiser.buffers) {
            // SAFETY: a live filter, a NUL-terminated image name and a live buffer of
            // `bytes` = width × height × 12 bytes, exactly a tightly packed FLOAT3 image
            // (offset 0; strides 0: computed by OIDN as 12 and width × 12).
            unsafe {
                (api.set_filter_image)(
                    denoiser.filter,
                    name.as_ptr(),
                    buffer,
                    FORMAT_FLOAT3,
                    width as usize,
                    height as usize,
                    0,
                    0,
                    0,
                )
            };
        }
        for (name, value) in [(c"hdr", true), (c"cleanAux", true)] {
            // SAFETY: a live filter and a NUL-terminated parameter name.
            unsafe { (api.set_filter_bool)(denoiser.filter, name.as_ptr(), value) };
        }
        // SAFETY: a live filter with every image set.
        unsafe { (api.commit_filter)(denoiser.filter) };
        denoiser.check("committing the RT filter")?;
        Ok(denoiser)
    }

    /// The image size the filter was made for.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The device's stored error, if any.
    fn check(&self, operation: &'static str) -> Result<(), OidnError> {
        self.device.check(operation)
    }

    /// Denoises `colour` (linear HDR, finite and 0 or more) guided by `albedo` (each
    /// channel in [0, 1]) and `normal` (each component in [-1, 1]), each `width × height`
    /// pixels row-major: the denoised colour.
    pub fn denoise(
        &mut self,
        colour: &[[f32; 3]],
        albedo: &[[f32; 3]],
        normal: &[[f32; 3]],
    ) -> Result<Vec<[f32; 3]>, OidnError> {
        let pixels = self.bytes / size_of::<[f32; 3]>();
        for (name, image) in [("colour", colour), ("albedo", albedo), ("normal", normal)] {
            if image.len() != pixels {
                return Err(OidnError::Input(format!(
                    "the {name} image has {} pixels, the filter's {}x{} image {pixels}",
                    image.len(),
                    self.width,
                    self.height
                )));
            }
        }
        let bad = |name: &str, at: usize, value: [f32; 3], rule: &str| {
            let (x, y) = (at % self.width as usize, at / self.width as usize);
            Err(OidnError::Input(format!("{name} pixel ({x}, {y}) is {value:?}: must be {rule}")))
        };
        for (at, &p) in colour.iter().enumerate() {
            if !p.iter().all(|c| c.is_finite() && *c >= 0.0) {
                return bad("colour", at, p, "finite and 0 or more");
            }
        }
        for (at, &p) in albedo.iter().enumerate() {
            if !p.iter().all(|c| (0.0..=1.0).contains(c)) {
                return bad("albedo", at, p, "in [0, 1]");
            }
        }
        for (at, &p) in normal.iter().enumerate() {
            if !p.iter().all(|c| (-1.0..=1.0).contains(c)) {
                return bad("normal", at, p, "in [-1, 1]");
            }
        }
        let api = self.library.api;
        for (image, buffer) in [colour, albedo, normal].into_iter().zip(self.buffers) {
            // SAFETY: a live buffer of `self.bytes` bytes, and `image` holds exactly
            // `pixels` × 12 = `self.bytes` bytes (checked above) to read.
            unsafe { (api.write_buffer)(buffer, 0, self.bytes, image.as_ptr().cast()) };
        }
        self.check("writing the images")?;
        // SAFETY: a committed filter whose images are all set.
        unsafe { (api.execute_filter)(self.filter) };
        self.check("denoising")?;
        let mut output = vec![[0.0f32; 3]; pixels];
        // SAFETY: a live buffer of `self.bytes` bytes, and `output` has room for exactly
        // `self.bytes` bytes.
        unsafe { (api.read_buffer)(self.buffers[3], 0, self.bytes, output.as_mut_ptr().cast()) };
        self.check("reading the output")?;
        Ok(output)
    }

    /// Denoises one frame as the renderer gives it: its colour (`vec4<f32>` per pixel,
    /// the fourth word ignored) and its guides, whose albedo is clamped to [0, 1] and
    /// normal to [-1, 1] as OIDN requires.
    pub fn denoise_frame(&mut self, colour: &[[f32; 4]], guides: &[DenoiseGuide]) -> Result<RgbImage, OidnError> {
        let colour: Vec<[f32; 3]> = colour.iter().map(|p| [p[0], p[1], p[2]]).collect();
        let clamp = |v: [f32; 3], low: f32| v.map(|c| if c.is_nan() { 0.0 } else { c.clamp(low, 1.0) });
        let albedo: Vec<[f32; 3]> = guides.iter().map(|g| clamp(g.albedo, 0.0)).collect();
        let normal: Vec<[f32; 3]> = guides.iter().map(|g| clamp(g.normal, -1.0)).collect();
        let pixels = self.denoise(&colour, &albedo, &normal)?;
        Ok(RgbImage { width: self.width, height: self.height, pixels })
    }
}

impl Drop for OidnDenoiser {
    fn drop(&mut self) {
        let api = self.library.api;
        if !self.filter.is_null() {
            // SAFETY: a live filter, not used after.
            unsafe { (api.release_filter)(self.filter) };
        }
        for buffer in self.buffers.into_iter().filter(|b| !b.is_null()) {
            // SAFETY: a live buffer, not used after (the filter holding it is released).
            unsafe { (api.release_buffer)(buffer) };
        }
        // The device is released next, when its field is dropped.
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_file_is_one_line_naming_it() {
        let error = OidnLibrary::open(Path::new("/nonexistent/strata/libOpenImageDenoise.so.2")).unwrap_err();
        let message = error.to_string();
        assert!(message.starts_with("cannot load /nonexistent/strata/libOpenImageDenoise.so.2: "), "{message}");
        assert!(!message.contains('\n'), "{message}");
    }
}
