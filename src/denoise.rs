//! Denoising with Intel Open Image Denoise's "RT" filter (OIDN 2; a convolutional U-Net trained on
//! path-traced images, guided by the albedo and normal of the surface each pixel sees first), in
//! builds with the cargo feature `denoise`. tools/fetch-oidn fetches the library; without the
//! feature, [`check_available`] says how to get a build that has it.
//!
//! The filter runs on OIDN's CPU device with its default (high) quality, in HDR mode (the colour
//! is linear and unbounded), on the caller's arrays shared with it
//! (`oidnSetSharedFilterImage`). The few functions of OIDN's C API this needs are declared in
//! [`ffi`] as its header `OpenImageDenoise/oidn.h` (version 2.x) declares them: the `oidn` crate
//! would bring a proc-macro dependency whose features make cargo build the renderer once more.

use prism_core::error::{Error, Result};

/// An image to denoise with its guides, each row-major from the top row with three interleaved
/// values per pixel.
#[derive(Clone, Copy, Debug)]
pub struct DenoiseInput<'a> {
    pub width: usize,
    pub height: usize,
    /// The noisy colour, linear (HDR).
    pub color: &'a [f32],
    /// The reflectance of the surface each pixel sees first; values outside [0, 1] are clamped,
    /// as OIDN requires.
    pub albedo: &'a [f32],
    /// The shading normal there (world space, any length, components in [-1, 1]).
    pub normal: &'a [f32],
    /// Whether the guides are free of noise (OIDN's `cleanAux`): then the filter keeps their
    /// detail; otherwise it treats them as noisy too.
    pub clean_guides: bool,
    /// Threads of OIDN's CPU device (None: one per core).
    pub threads: Option<usize>,
}

/// Whether this build can denoise: it needs the cargo feature `denoise`.
pub fn check_available() -> Result<()> {
    if cfg!(feature = "denoise") {
        Ok(())
    } else {
        Err(unavailable())
    }
}

fn unavailable() -> Error {
    Error::usage("this prism was built without Open Image Denoise, so --denoise is not available")
        .with_help(
            "run tools/fetch-oidn, then rebuild as it says: \
             `OIDN_DIR=$PWD/target/oidn cargo build --release --features denoise`",
        )
}

/// Without the feature there is no denoiser: the error of [`check_available`].
#[cfg(not(feature = "denoise"))]
pub fn denoise(_: &DenoiseInput) -> Result<Vec<f32>> {
    Err(unavailable())
}

/// The denoised colour of `input`, laid out as its colour is.
#[cfg(feature = "denoise")]
pub fn denoise(input: &DenoiseInput) -> Result<Vec<f32>> {
    use std::ffi::{CStr, c_void};
    let values = 3 * input.width * input.height;
    assert!(
        input.color.len() == values && input.albedo.len() == values && input.normal.len() == values,
        "the colour and guides must each have three values per pixel"
    );
    let albedo: Vec<f32> = input.albedo.iter().map(|a| a.clamp(0.0, 1.0)).collect();
    let mut output = vec![0.0f32; values];
    let threads = input
        .threads
        .map_or(0, |t| i32::try_from(t).unwrap_or(i32::MAX));
    let image = |filter: ffi::Filter, name: &CStr, pixels: *const f32| {
        // SAFETY: `pixels` holds `values` floats, three per pixel of width × height, packed
        // (strides 0: OIDN derives them from the format); OIDN only reads the inputs.
        unsafe {
            ffi::oidnSetSharedFilterImage(
                filter,
                name.as_ptr(),
                pixels as *mut c_void,
                ffi::FORMAT_FLOAT3,
                input.width,
                input.height,
                0,
                0,
                0,
            );
        }
    };
    // SAFETY: the device and filter are created, used and released here in the order OIDN's
    // API asks for; the shared images outlive the filter's execution, which is synchronous.
    unsafe {
        let device = ffi::oidnNewDevice(ffi::DEVICE_TYPE_CPU);
        if device.is_null() {
            return Err(Error::usage(
                "Open Image Denoise could not create its CPU device",
            ));
        }
        if threads > 0 {
            ffi::oidnSetDeviceInt(device, c"numThreads".as_ptr(), threads);
        }
        ffi::oidnCommitDevice(device);
        let filter = ffi::oidnNewFilter(device, c"RT".as_ptr());
        if !filter.is_null() {
            image(filter, c"color", input.color.as_ptr());
            image(filter, c"albedo", albedo.as_ptr());
            image(filter, c"normal", input.normal.as_ptr());
            image(filter, c"output", output.as_mut_ptr());
            ffi::oidnSetFilterBool(filter, c"hdr".as_ptr(), true);
            ffi::oidnSetFilterBool(filter, c"cleanAux".as_ptr(), input.clean_guides);
            ffi::oidnCommitFilter(filter);
            ffi::oidnExecuteFilter(filter);
            ffi::oidnReleaseFilter(filter);
        }
        let mut message = std::ptr::null();
        let error = ffi::oidnGetDeviceError(device, &mut message);
        let message = if message.is_null() {
            String::new()
        } else {
            CStr::from_ptr(message).to_string_lossy().into_owned()
        };
        ffi::oidnReleaseDevice(device);
        if error != ffi::ERROR_NONE || filter.is_null() {
            return Err(Error::usage(format!(
                "Open Image Denoise failed (error {error}): {message}"
            )));
        }
    }
    Ok(output)
}

/// The functions, handles and constants of OIDN 2's C API that [`denoise`] uses.
#[cfg(feature = "denoise")]
mod ffi {
    use std::ffi::{c_char, c_int, c_void};

    #[repr(C)]
    pub struct DeviceImpl {
        _private: [u8; 0],
    }
    #[repr(C)]
    pub struct FilterImpl {
        _private: [u8; 0],
    }
    /// `OIDNDevice`.
    pub type Device = *mut DeviceImpl;
    /// `OIDNFilter`.
    pub type Filter = *mut FilterImpl;

    /// `OIDN_DEVICE_TYPE_CPU` of `OIDNDeviceType`.
    pub const DEVICE_TYPE_CPU: c_int = 1;
    /// `OIDN_FORMAT_FLOAT3` of `OIDNFormat`.
    pub const FORMAT_FLOAT3: c_int = 3;
    /// `OIDN_ERROR_NONE` of `OIDNError`.
    pub const ERROR_NONE: c_int = 0;

    #[link(name = "OpenImageDenoise")]
    unsafe extern "C" {
        pub fn oidnNewDevice(device_type: c_int) -> Device;
        pub fn oidnSetDeviceInt(device: Device, name: *const c_char, value: c_int);
        pub fn oidnCommitDevice(device: Device);
        pub fn oidnGetDeviceError(device: Device, message: *mut *const c_char) -> c_int;
        pub fn oidnReleaseDevice(device: Device);
        pub fn oidnNewFilter(device: Device, filter_type: *const c_char) -> Filter;
        pub fn oidnSetSharedFilterImage(
            filter: Filter,
            name: *const c_char,
            pointer: *mut c_void,
            format: c_int,
            width: usize,
            height: usize,
            byte_offset: usize,
            pixel_byte_stride: usize,
            row_byte_stride: usize,
        );
        pub fn oidnSetFilterBool(filter: Filter, name: *const c_char, value: bool);
        pub fn oidnCommitFilter(filter: Filter);
        pub fn oidnExecuteFilter(filter: Filter);
        pub fn oidnReleaseFilter(filter: Filter);
    }
}
