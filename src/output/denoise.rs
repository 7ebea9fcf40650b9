//! Denoising with Intel Open Image Denoise (OIDN 2), fed with the albedo and normal layers.
//!
//! OIDN is a native library that gridtrace loads when `--denoise` asks for it, so gridtrace
//! builds and runs without it. It is looked for at `$GRIDTRACE_OIDN` (the library file or
//! its folder), then by the system's loader (`libOpenImageDenoise.so.2` on the library
//! path), then beside the executable. The auxiliary layers are noisy too (depth of field,
//! motion blur, rough glass), so they are first filtered on their own and the beauty is
//! then denoised with `cleanAux` set — the "prefiltering" OIDN's documentation recommends
//! for final frames.

use std::ffi::{CStr, CString, c_char, c_int, c_void};
use std::path::{Path, PathBuf};

use glam::Vec3;

use crate::limits::{OverBudget, check_memory};
use crate::render::Image;

/// The environment variable naming the OIDN library or its folder.
pub const LIBRARY_VARIABLE: &str = "GRIDTRACE_OIDN";

/// The library's file name (OIDN 2's ABI).
#[cfg(target_os = "linux")]
const LIBRARY_NAME: &str = "libOpenImageDenoise.so.2";
#[cfg(target_os = "macos")]
const LIBRARY_NAME: &str = "libOpenImageDenoise.2.dylib";
#[cfg(windows)]
const LIBRARY_NAME: &str = "OpenImageDenoise.dll";
#[cfg(not(any(target_os = "linux", target_os = "macos", windows)))]
const LIBRARY_NAME: &str = "libOpenImageDenoise.so.2";

/// `OIDN_DEVICE_TYPE_CPU`.
const DEVICE_CPU: c_int = 1;
/// `OIDN_FORMAT_FLOAT3`.
const FORMAT_FLOAT3: c_int = 3;
/// `OIDN_QUALITY_HIGH` (final-frame quality).
const QUALITY_HIGH: c_int = 6;

/// Why an image could not be denoised.
#[derive(Debug, thiserror::Error)]
pub enum DenoiseError {
    /// The library is not installed where gridtrace looks.
    #[error(
        "--denoise needs Intel Open Image Denoise 2 ({LIBRARY_NAME}), which was not found \
         ({tried}); install it (`pip install pyoidn` ships it in pyoidn/oidn/lib, or the \
         project's tools/user/install-oidn.sh) and point {LIBRARY_VARIABLE} at the library or \
         its folder"
    )]
    NotInstalled {
        /// Where it was looked for.
        tried: String,
    },
    /// The library is there but lacks a function of the OIDN 2 API.
    #[error("{path}: not Open Image Denoise 2: {message}")]
    WrongLibrary {
        /// The library loaded.
        path: String,
        /// What was missing.
        message: String,
    },
    /// OIDN reported an error.
    #[error("Open Image Denoise: {0}")]
    Failed(String),
    /// The denoiser's buffers would exceed the memory budget.
    #[error("{0}")]
    Memory(#[from] OverBudget),
}

/// The OIDN functions gridtrace calls.
struct Api {
    new_device: unsafe extern "C" fn(c_int) -> *mut c_void,
    commit_device: unsafe extern "C" fn(*mut c_void),
    release_device: unsafe extern "C" fn(*mut c_void),
    set_device_int: unsafe extern "C" fn(*mut c_void, *const c_char, c_int),
    device_error: unsafe extern "C" fn(*mut c_void, *mut *const c_char) -> c_int,
    new_filter: unsafe extern "C" fn(*mut c_void, *const c_char) -> *mut c_void,
    #[allow(clippy::type_complexity)]
    set_shared_image: unsafe extern "C" fn(
        *mut c_void,
        *const c_char,
        *mut c_void,
        c_int,
        usize,
        usize,
        usize,
        usize,
        usize,
    ),
    set_filter_bool: unsafe extern "C" fn(*mut c_void, *const c_char, bool),
    set_filter_int: unsafe extern "C" fn(*mut c_void, *const c_char, c_int),
    commit_filter: unsafe extern "C" fn(*mut c_void),
    execute_filter: unsafe extern "C" fn(*mut c_void),
    release_filter: unsafe extern "C" fn(*mut c_void),
    /// Keeps the functions above loaded.
    _library: libloading::Library,
}

/// Where the library is looked for, in order.
fn candidates() -> Vec<PathBuf> {
    let mut paths = Vec::new();
    if let Some(value) = std::env::var_os(LIBRARY_VARIABLE) {
        let path = PathBuf::from(value);
        if path.is_dir() {
            paths.push(path.join(LIBRARY_NAME));
        } else {
            paths.push(path);
        }
    }
    // A bare name: the system loader's search (LD_LIBRARY_PATH, the cache, rpath).
    paths.push(PathBuf::from(LIBRARY_NAME));
    if let Ok(exe) = std::env::current_exe()
        && let Some(dir) = exe.parent()
    {
        paths.push(dir.join(LIBRARY_NAME));
        paths.push(dir.join("../lib").join(LIBRARY_NAME));
    }
    paths
}

impl Api {
    /// Loads the library from the first of `paths` that opens.
    fn load_from(paths: Vec<PathBuf>) -> Result<Api, DenoiseError> {
        let mut tried = Vec::new();
        for path in paths {
            // SAFETY: loading runs the library's initialisers; OIDN's only set up its own
            // state.
            match unsafe { libloading::Library::new(&path) } {
                Ok(library) => return Api::bind(library, &path),
                Err(_) => tried.push(path.display().to_string()),
            }
        }
        Err(DenoiseError::NotInstalled {
            tried: format!("tried {}", tried.join(", ")),
        })
    }

    /// Loads the library from where gridtrace looks for it ([`candidates`]).
    fn load() -> Result<Api, DenoiseError> {
        Api::load_from(candidates())
    }

    fn bind(library: libloading::Library, path: &Path) -> Result<Api, DenoiseError> {
        let wrong = |e: libloading::Error| DenoiseError::WrongLibrary {
            path: path.display().to_string(),
            message: e.to_string(),
        };
        // SAFETY: each symbol is read with the signature OIDN 2's C API (oidn.h) gives it.
        unsafe {
            macro_rules! symbol {
                ($name:literal) => {
                    *library.get($name).map_err(wrong)?
                };
            }
            Ok(Api {
                new_device: symbol!(b"oidnNewDevice\0"),
                commit_device: symbol!(b"oidnCommitDevice\0"),
                release_device: symbol!(b"oidnReleaseDevice\0"),
                set_device_int: symbol!(b"oidnSetDeviceInt\0"),
                device_error: symbol!(b"oidnGetDeviceError\0"),
                new_filter: symbol!(b"oidnNewFilter\0"),
                set_shared_image: symbol!(b"oidnSetSharedFilterImage\0"),
                set_filter_bool: symbol!(b"oidnSetFilterBool\0"),
                set_filter_int: symbol!(b"oidnSetFilterInt\0"),
                commit_filter: symbol!(b"oidnCommitFilter\0"),
                execute_filter: symbol!(b"oidnExecuteFilter\0"),
                release_filter: symbol!(b"oidnReleaseFilter\0"),
                _library: library,
            })
        }
    }
}

/// Checks that the OIDN library can be loaded, so a render that will need it fails before
/// it starts rather than after.
pub fn check_available() -> Result<(), DenoiseError> {
    Api::load().map(drop)
}

/// A CPU device, released when dropped.
struct Device<'a> {
    api: &'a Api,
    handle: *mut c_void,
}

impl Drop for Device<'_> {
    fn drop(&mut self) {
        // SAFETY: the handle came from oidnNewDevice and is released once.
        unsafe { (self.api.release_device)(self.handle) }
    }
}

impl Device<'_> {
    /// The device's pending error, if any.
    fn check(&self) -> Result<(), DenoiseError> {
        let mut message: *const c_char = std::ptr::null();
        // SAFETY: a valid device; OIDN sets `message` to a string it owns or leaves it null.
        let code = unsafe { (self.api.device_error)(self.handle, &mut message) };
        if code == 0 {
            return Ok(());
        }
        let text = if message.is_null() {
            format!("error {code}")
        } else {
            // SAFETY: a NUL-terminated string valid until the next call on the device.
            unsafe { CStr::from_ptr(message) }
                .to_string_lossy()
                .into_owned()
        };
        Err(DenoiseError::Failed(text))
    }

    /// Runs OIDN's "RT" filter with the named images (`(name, buffer)`, each `width`×
    /// `height` RGB f32) and boolean parameters.
    fn filter(
        &self,
        width: usize,
        height: usize,
        images: &mut [(&str, &mut [f32])],
        flags: &[(&str, bool)],
    ) -> Result<(), DenoiseError> {
        let name = |s: &str| CString::new(s).expect("no NUL in OIDN parameter names");
        // SAFETY: every buffer holds width × height × 3 floats and outlives the execution,
        // which is synchronous; the filter is released before returning.
        unsafe {
            let filter = (self.api.new_filter)(self.handle, name("RT").as_ptr());
            for (image, buffer) in images.iter_mut() {
                assert_eq!(buffer.len(), width * height * 3);
                (self.api.set_shared_image)(
                    filter,
                    name(image).as_ptr(),
                    buffer.as_mut_ptr().cast(),
                    FORMAT_FLOAT3,
                    width,
                    height,
                    0,
                    12,
                    12 * width,
                );
            }
            for (flag, value) in flags {
                (self.api.set_filter_bool)(filter, name(flag).as_ptr(), *value);
            }
            (self.api.set_filter_int)(filter, name("quality").as_ptr(), QUALITY_HIGH);
            (self.api.commit_filter)(filter);
            (self.api.execute_filter)(filter);
            (self.api.release_filter)(filter);
        }
        self.check()
    }
}

/// Bytes a denoise of `pixels` pixels holds beyond the image: five RGB f32 buffers.
fn denoise_bytes(pixels: usize) -> u64 {
    (pixels as u64).saturating_mul(5 * 12)
}

/// Denoises `image` in place with `threads` worker threads (0: OIDN's choice): the beauty
/// becomes the denoised one and the noisy beauty is kept as the `noisy` layer. Uses the
/// albedo and normal layers when the image has them (both, or albedo alone, as OIDN
/// accepts), and the beauty alone otherwise.
pub fn denoise(image: &mut Image, threads: usize) -> Result<(), DenoiseError> {
    denoise_with(image, threads, Api::load)
}

/// [`denoise`] with the library at `library` (a file, or a folder holding it).
pub fn denoise_with_library(
    image: &mut Image,
    threads: usize,
    library: &Path,
) -> Result<(), DenoiseError> {
    let path = if library.is_dir() {
        library.join(LIBRARY_NAME)
    } else {
        library.to_path_buf()
    };
    denoise_with(image, threads, || Api::load_from(vec![path]))
}

fn denoise_with(
    image: &mut Image,
    threads: usize,
    load: impl FnOnce() -> Result<Api, DenoiseError>,
) -> Result<(), DenoiseError> {
    let (width, height) = (image.width as usize, image.height as usize);
    check_memory(
        || format!("denoising a {width}x{height} image"),
        denoise_bytes(width * height),
    )?;
    let api = load()?;
    let flat = |v: &[Vec3]| v.iter().flat_map(|p| p.to_array()).collect::<Vec<f32>>();
    let mut color = flat(&image.pixels);
    let mut output = vec![0.0f32; color.len()];
    let mut albedo = image.aovs.albedo.as_deref().map(flat);
    let mut normal = image.aovs.normal.as_deref().map(flat);
    if albedo.is_none() {
        // OIDN takes a normal only with an albedo.
        normal = None;
    }
    // SAFETY: oidnNewDevice returns a handle or null; null is reported by check().
    let handle = unsafe { (api.new_device)(DEVICE_CPU) };
    let device = Device { api: &api, handle };
    if handle.is_null() {
        return Err(DenoiseError::Failed("no CPU device".into()));
    }
    if threads > 0 {
        let threads = c_int::try_from(threads).unwrap_or(c_int::MAX);
        let key = CString::new("numThreads").expect("static name");
        // SAFETY: a valid device, before commit as OIDN requires.
        unsafe { (api.set_device_int)(handle, key.as_ptr(), threads) };
    }
    // SAFETY: a valid device.
    unsafe { (api.commit_device)(handle) };
    device.check()?;
    // Prefilter the auxiliary layers (each into a clean copy).
    for (layer, aux) in [("albedo", &mut albedo), ("normal", &mut normal)] {
        if let Some(buffer) = aux {
            let mut clean = vec![0.0f32; buffer.len()];
            device.filter(
                width,
                height,
                &mut [
                    (layer, buffer.as_mut_slice()),
                    ("output", clean.as_mut_slice()),
                ],
                &[],
            )?;
            *buffer = clean;
        }
    }
    let mut images: Vec<(&str, &mut [f32])> = vec![("color", color.as_mut_slice())];
    let guided = albedo.is_some();
    if let Some(a) = albedo.as_mut() {
        images.push(("albedo", a.as_mut_slice()));
    }
    if let Some(n) = normal.as_mut() {
        images.push(("normal", n.as_mut_slice()));
    }
    images.push(("output", output.as_mut_slice()));
    device.filter(
        width,
        height,
        &mut images,
        &[("hdr", true), ("cleanAux", guided)],
    )?;
    let denoised: Vec<Vec3> = output
        .chunks_exact(3)
        .map(|c| Vec3::new(c[0], c[1], c[2]).max(Vec3::ZERO))
        .collect();
    let noisy = std::mem::replace(&mut image.pixels, denoised);
    image.aovs.noisy = Some((noisy, image.alpha.clone()));
    Ok(())
}
