//! Intel Open Image Denoise (OIDN 1.4), loaded at run time so rt builds and runs without it.
//!
//! `scripts/ensure-oidn` installs the library from PyPI's `oidn` 0.2.1 wheel (Apache-2.0) into
//! `~/.cache/rt/oidn/lib`. The search order is `RT_OIDN_LIBRARY` (a file), that cache directory,
//! then the system's `libOpenImageDenoise.so.1`. The `RT` filter runs with `hdr` on and colour,
//! albedo and normal guides; `cleanAux` stays off because rt's guides are per-sample means that
//! are noisy at edges, through glass and out of focus (OIDN then treats them as noisy, as it
//! should).
//!
//! This is the one other audited use of `unsafe` in rt (besides wgpu's experimental-features
//! token): calls into the C API, with every pointer handed over living for the call.
#![allow(unsafe_code)]

use std::ffi::{CStr, CString, c_char, c_void};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

type Device = *mut c_void;
type Filter = *mut c_void;
/// `OIDNProgressMonitorFunction`: returning false cancels the filter.
type ProgressMonitor = unsafe extern "C" fn(*mut c_void, f64) -> bool;

/// `OIDN_DEVICE_TYPE_DEFAULT` and `OIDN_FORMAT_FLOAT3` of OIDN 1.x's `oidn.h`.
const DEVICE_TYPE_DEFAULT: i32 = 0;
const FORMAT_FLOAT3: i32 = 3;
/// `OIDN_ERROR_CANCELLED`.
const ERROR_CANCELLED: i32 = 5;

/// What a cancelled denoise returns (`Oidn::denoise` with `keep_going` saying no).
pub const CANCELLED: &str = "the denoise was cancelled";

/// Asks `keep_going` (behind `user`) whether OIDN should go on.
unsafe extern "C" fn progress(user: *mut c_void, _done: f64) -> bool {
    // SAFETY: `user` points at the `&dyn Fn` that `Oidn::denoise` keeps alive across the
    // execution it was registered for.
    let keep_going = unsafe { &*(user as *const &(dyn Fn() -> bool + Sync)) };
    keep_going()
}

struct Api {
    new_device: unsafe extern "C" fn(i32) -> Device,
    commit_device: unsafe extern "C" fn(Device),
    release_device: unsafe extern "C" fn(Device),
    get_device_error: unsafe extern "C" fn(Device, *mut *const c_char) -> i32,
    new_filter: unsafe extern "C" fn(Device, *const c_char) -> Filter,
    set_shared_filter_image: unsafe extern "C" fn(
        Filter,
        *const c_char,
        *mut c_void,
        i32,
        usize,
        usize,
        usize,
        usize,
        usize,
    ),
    set_filter_bool: unsafe extern "C" fn(Filter, *const c_char, bool),
    set_device_int: unsafe extern "C" fn(Device, *const c_char, i32),
    set_progress_monitor: unsafe extern "C" fn(Filter, Option<ProgressMonitor>, *mut c_void),
    commit_filter: unsafe extern "C" fn(Filter),
    execute_filter: unsafe extern "C" fn(Filter),
    release_filter: unsafe extern "C" fn(Filter),
}

/// A loaded OIDN library.
pub struct Oidn {
    api: Api,
    path: PathBuf,
    // The libraries stay loaded while `api`'s function pointers exist (TBB first: OIDN needs it).
    _libraries: Vec<libloading::Library>,
}

/// Inputs of one denoise, row-major `width × height`.
pub struct OidnInput<'a> {
    pub width: u32,
    pub height: u32,
    pub color: &'a [[f32; 3]],
    pub albedo: &'a [[f32; 3]],
    pub normal: &'a [[f32; 3]],
}

/// Where `scripts/ensure-oidn` puts the library: `$XDG_CACHE_HOME/rt/oidn/lib` or
/// `~/.cache/rt/oidn/lib`.
pub fn cache_dir() -> Option<PathBuf> {
    let cache = std::env::var_os("XDG_CACHE_HOME")
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))?;
    Some(cache.join("rt").join("oidn").join("lib"))
}

/// The command that installs OIDN for rt, for messages.
pub const INSTALL_HINT: &str = "scripts/ensure-oidn installs it (from PyPI's oidn 0.2.1 wheel)";

impl Oidn {
    /// The library from the search order above, loaded once per process; the error says where it
    /// looked and what failed.
    pub fn get() -> Result<&'static Oidn, String> {
        static LOADED: OnceLock<Result<Oidn, String>> = OnceLock::new();
        LOADED
            .get_or_init(Self::find)
            .as_ref()
            .map_err(Clone::clone)
    }

    fn find() -> Result<Oidn, String> {
        if let Some(path) = std::env::var_os("RT_OIDN_LIBRARY").filter(|p| !p.is_empty()) {
            return Oidn::load(Path::new(&path));
        }
        let mut tried = Vec::new();
        if let Some(dir) = cache_dir() {
            let path = dir.join("libOpenImageDenoise.so.1");
            if path.exists() {
                return Oidn::load(&path);
            }
            tried.push(path.display().to_string());
        }
        match Oidn::load(Path::new("libOpenImageDenoise.so.1")) {
            Ok(oidn) => Ok(oidn),
            Err(_) => {
                tried.push("libOpenImageDenoise.so.1 on the library path".into());
                Err(format!(
                    "Open Image Denoise was not found (looked for {}); {INSTALL_HINT}",
                    tried.join(", ")
                ))
            }
        }
    }

    /// Loads OIDN from `path` (a file, or a bare name the dynamic loader searches for). A TBB
    /// beside the file (`libtbb.so.12`) is loaded first, since OIDN's wheel build needs it.
    pub fn load(path: &Path) -> Result<Oidn, String> {
        let fail = |e: libloading::Error| {
            format!(
                "{}: not a usable Open Image Denoise library ({e})",
                path.display()
            )
        };
        let mut libraries = Vec::new();
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            let tbb = dir.join("libtbb.so.12");
            if tbb.exists() {
                // SAFETY: loading runs TBB's initialisers, which have no preconditions.
                libraries.push(unsafe { libloading::Library::new(&tbb) }.map_err(fail)?);
            }
        }
        // SAFETY: as above, for OIDN's.
        let library = unsafe { libloading::Library::new(path) }.map_err(fail)?;
        // SAFETY: each symbol is looked up by its C name and given its signature from OIDN 1.4's
        // oidn.h; the function pointers are used only while `library` is held (in `_libraries`).
        let api = unsafe {
            Api {
                new_device: *library.get(b"oidnNewDevice\0").map_err(fail)?,
                commit_device: *library.get(b"oidnCommitDevice\0").map_err(fail)?,
                release_device: *library.get(b"oidnReleaseDevice\0").map_err(fail)?,
                get_device_error: *library.get(b"oidnGetDeviceError\0").map_err(fail)?,
                new_filter: *library.get(b"oidnNewFilter\0").map_err(fail)?,
                set_shared_filter_image: *library
                    .get(b"oidnSetSharedFilterImage\0")
                    .map_err(fail)?,
                set_filter_bool: *library.get(b"oidnSetFilter1b\0").map_err(fail)?,
                set_device_int: *library.get(b"oidnSetDevice1i\0").map_err(fail)?,
                set_progress_monitor: *library
                    .get(b"oidnSetFilterProgressMonitorFunction\0")
                    .map_err(fail)?,
                commit_filter: *library.get(b"oidnCommitFilter\0").map_err(fail)?,
                execute_filter: *library.get(b"oidnExecuteFilter\0").map_err(fail)?,
                release_filter: *library.get(b"oidnReleaseFilter\0").map_err(fail)?,
            }
        };
        libraries.push(library);
        Ok(Oidn {
            api,
            path: path.to_path_buf(),
            _libraries: libraries,
        })
    }

    /// The file it was loaded from.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The `RT` filter's output for `input` (HDR colour, albedo and normal guides), on at most
    /// `threads` threads (`None`: all cores; the live viewport leaves some to the UI). OIDN asks
    /// `keep_going` now and then and stops (with `CANCELLED`) when it says no.
    pub fn denoise(
        &self,
        input: &OidnInput,
        threads: Option<u32>,
        keep_going: &(dyn Fn() -> bool + Sync),
    ) -> Result<Vec<[f32; 3]>, String> {
        let (w, h) = (input.width as usize, input.height as usize);
        let n = w * h;
        for (name, len) in [
            ("color", input.color.len()),
            ("albedo", input.albedo.len()),
            ("normal", input.normal.len()),
        ] {
            if len != n {
                return Err(format!("OIDN: {name} has {len} pixels, the image {w}x{h}"));
            }
        }
        if n == 0 {
            return Ok(Vec::new());
        }
        // OIDN reads NaN and infinities as they are; the mean of finite samples never holds them,
        // but a guard keeps one bad pixel from spreading over the filter's footprint.
        let clean = |v: &[[f32; 3]]| -> Vec<[f32; 3]> {
            v.iter()
                .map(|p| p.map(|c| if c.is_finite() { c } else { 0.0 }))
                .collect()
        };
        let (mut color, mut albedo, mut normal) =
            (clean(input.color), clean(input.albedo), clean(input.normal));
        let mut output = vec![[0.0f32; 3]; n];
        let api = &self.api;
        let name = |s: &str| CString::new(s).unwrap_or_default();
        // SAFETY: the device and filter are released on every path below; each shared image points
        // at a live `n`-pixel buffer of 3 floats (12 bytes a pixel, rows packed) that outlives
        // `execute_filter`, and OIDN writes only `output`.
        unsafe {
            let device = (api.new_device)(DEVICE_TYPE_DEFAULT);
            if device.is_null() {
                return Err("OIDN: could not create a device".into());
            }
            if let Some(n) = threads {
                (api.set_device_int)(device, name("numThreads").as_ptr(), n.max(1) as i32);
            }
            (api.commit_device)(device);
            if let Some(e) = self.error(device) {
                (api.release_device)(device);
                return Err(e);
            }
            let filter = (api.new_filter)(device, name("RT").as_ptr());
            if filter.is_null() {
                let e = self.error(device);
                (api.release_device)(device);
                return Err(e.unwrap_or_else(|| "OIDN: no RT filter".into()));
            }
            for (image, buffer) in [
                ("color", color.as_mut_ptr()),
                ("albedo", albedo.as_mut_ptr()),
                ("normal", normal.as_mut_ptr()),
                ("output", output.as_mut_ptr()),
            ] {
                (api.set_shared_filter_image)(
                    filter,
                    name(image).as_ptr(),
                    buffer.cast(),
                    FORMAT_FLOAT3,
                    w,
                    h,
                    0,
                    12,
                    12 * w,
                );
            }
            (api.set_filter_bool)(filter, name("hdr").as_ptr(), true);
            let mut keep_going = keep_going;
            (api.set_progress_monitor)(
                filter,
                Some(progress),
                (&mut keep_going as *mut &(dyn Fn() -> bool + Sync)).cast(),
            );
            (api.commit_filter)(filter);
            let mut failure = self.error(device);
            if failure.is_none() {
                (api.execute_filter)(filter);
                failure = self.error(device);
            }
            (api.release_filter)(filter);
            (api.release_device)(device);
            match failure {
                Some(e) => Err(e),
                None => Ok(output),
            }
        }
    }

    /// The device's pending error, if any.
    ///
    /// # Safety
    /// `device` must be a live OIDN device.
    unsafe fn error(&self, device: Device) -> Option<String> {
        let mut message: *const c_char = std::ptr::null();
        // SAFETY: per the caller; OIDN returns a message it owns until the next call, copied here.
        let code = unsafe { (self.api.get_device_error)(device, &mut message) };
        if code == ERROR_CANCELLED {
            return Some(CANCELLED.to_string());
        }
        (code != 0).then(|| {
            let text = if message.is_null() {
                String::new()
            } else {
                // SAFETY: a NUL-terminated string from OIDN (checked non-null).
                unsafe { CStr::from_ptr(message) }
                    .to_string_lossy()
                    .into_owned()
            };
            format!("OIDN error {code}: {text}")
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_corrupt_library_is_a_clear_error_naming_the_file() {
        let dir = std::env::temp_dir().join(format!("rt-oidn-corrupt-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("libOpenImageDenoise.so.1");
        std::fs::write(&path, b"\x7fELF but not really a library").unwrap();
        let error = Oidn::load(&path).err().expect("refused");
        assert!(error.contains(&path.display().to_string()), "{error}");
        assert!(error.contains("not a usable Open Image Denoise"), "{error}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_library_without_oidn_symbols_is_refused() {
        // libm is everywhere and has none of OIDN's entry points.
        let error = Oidn::load(Path::new("libm.so.6")).err().expect("refused");
        assert!(error.contains("oidnNewDevice"), "{error}");
    }
}
