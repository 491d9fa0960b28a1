//! In builds with the feature `denoise`, tells the linker where Open Image Denoise is when
//! OIDN_DIR names its folder (tools/fetch-oidn's target/oidn): its `lib` is searched for the
//! library and recorded as the rpath of the program and its tests, so that they find it without
//! LD_LIBRARY_PATH. Without OIDN_DIR the system's library paths must hold it.

fn main() {
    println!("cargo::rerun-if-env-changed=OIDN_DIR");
    if std::env::var_os("CARGO_FEATURE_DENOISE").is_some()
        && let Some(dir) = std::env::var_os("OIDN_DIR").filter(|d| !d.is_empty())
    {
        let lib = std::path::Path::new(&dir).join("lib");
        println!("cargo::rustc-link-search=native={}", lib.display());
        println!("cargo::rustc-link-arg=-Wl,-rpath,{}", lib.display());
    }
}
