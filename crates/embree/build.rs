//! Finds Debian's `libembree3` (package `libembree-dev`) and, when it is there and its
//! configuration matches the hand-written declarations in `src/ffi.rs`, links it and sets
//! `cfg(dualsplit_embree)`. Otherwise the crate builds without it and
//! `EmbreeScene::new` returns `EmbreeError::Missing` with the reason this script found.
//!
//! Looked at, in order: `$EMBREE_DIR/lib` (and its header `$EMBREE_DIR/include`), then the
//! usual system library folders. `DUALSPLIT_EMBREE=0` turns the library off even when it is
//! installed (to check the build without it).

use std::path::{Path, PathBuf};

const LIB: &str = "libembree3.so";

fn main() {
    println!("cargo::rustc-check-cfg=cfg(dualsplit_embree)");
    println!("cargo::rerun-if-changed=build.rs");
    println!("cargo::rerun-if-env-changed=EMBREE_DIR");
    println!("cargo::rerun-if-env-changed=DUALSPLIT_EMBREE");
    match find() {
        Ok((lib_dir, header)) => {
            println!("cargo::rerun-if-changed={}", lib_dir.join(LIB).display());
            println!("cargo::rerun-if-changed={}", header.display());
            println!("cargo::rustc-link-search=native={}", lib_dir.display());
            println!("cargo::rustc-link-lib=dylib=embree3");
            println!("cargo::rustc-cfg=dualsplit_embree");
            println!(
                "cargo::rustc-env=DUALSPLIT_EMBREE_STATUS=linked {}",
                lib_dir.join(LIB).display()
            );
        }
        Err(why) => {
            println!("cargo::rustc-env=DUALSPLIT_EMBREE_STATUS={why}");
        }
    }
}

/// The folders that might hold the library, with the header beside them and whether a
/// missing library there is watched for.
fn candidates() -> Vec<(PathBuf, PathBuf, bool)> {
    let mut v = Vec::new();
    if let Some(dir) = std::env::var_os("EMBREE_DIR") {
        let d = PathBuf::from(dir);
        v.push((
            d.join("lib"),
            d.join("include/embree3/rtcore_config.h"),
            true,
        ));
    }
    let sys_header = PathBuf::from("/usr/include/embree3/rtcore_config.h");
    let local_header = PathBuf::from("/usr/local/include/embree3/rtcore_config.h");
    let multiarch = format!(
        "/usr/lib/{}-linux-gnu",
        std::env::var("CARGO_CFG_TARGET_ARCH").unwrap_or_default()
    );
    v.push((PathBuf::from(multiarch), sys_header.clone(), true));
    for d in ["/usr/lib", "/usr/lib64"] {
        v.push((PathBuf::from(d), sys_header.clone(), false));
    }
    for d in ["/usr/local/lib", "/usr/local/lib64"] {
        v.push((PathBuf::from(d), local_header.clone(), false));
    }
    v
}

fn find() -> Result<(PathBuf, PathBuf), String> {
    if std::env::var("DUALSPLIT_EMBREE").is_ok_and(|v| v == "0") {
        return Err("turned off by DUALSPLIT_EMBREE=0 when dualsplit was built".into());
    }
    if std::env::var("CARGO_CFG_TARGET_OS").as_deref() != Ok("linux") {
        return Err("only Linux's libembree3.so is looked for".into());
    }
    let mut looked = Vec::new();
    for (lib_dir, header, watch) in candidates() {
        if !lib_dir.join(LIB).exists() {
            looked.push(lib_dir.display().to_string());
            // Rebuild when the library appears where Debian (or EMBREE_DIR) puts it. The other
            // folders are not watched: cargo would scan their whole trees on every build.
            if watch && lib_dir.is_dir() {
                println!("cargo::rerun-if-changed={}", lib_dir.display());
            }
            continue;
        }
        check_config(&header)?;
        return Ok((lib_dir, header));
    }
    Err(format!(
        "{LIB} not found when dualsplit was built (looked in {}; install libembree-dev or set EMBREE_DIR, then rebuild)",
        looked.join(", ")
    ))
}

/// The FFI's struct layouts assume Embree 3 with one instance level and no curve minimum
/// width (Debian's build); any other configuration changes `RTCIntersectContext` and
/// `RTCHit`, so it is refused rather than miscalled.
fn check_config(header: &Path) -> Result<(), String> {
    let text = std::fs::read_to_string(header).map_err(|e| {
        format!(
            "{} unreadable ({e}); install libembree-dev",
            header.display()
        )
    })?;
    let define = |name: &str| {
        text.lines().find_map(|l| {
            let mut w = l.split_whitespace();
            (w.next() == Some("#define") && w.next() == Some(name))
                .then(|| w.next().unwrap_or("").to_string())
        })
    };
    let want = [
        ("RTC_VERSION_MAJOR", "3"),
        ("RTC_MAX_INSTANCE_LEVEL_COUNT", "1"),
        ("EMBREE_MIN_WIDTH", "0"),
    ];
    for (name, value) in want {
        let got = define(name);
        if got.as_deref() != Some(value) {
            return Err(format!(
                "{} has {name} = {}, the bindings need {value}",
                header.display(),
                got.as_deref().unwrap_or("(none)")
            ));
        }
    }
    Ok(())
}
