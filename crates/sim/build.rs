//! Sets `incise_avx512` where the compiler has the AVX-512 intrinsics (stable since Rust
//! 1.89; the crate's MSRV is 1.85, where the AVX lanes serve alone).

use std::process::Command;

fn main() {
    println!("cargo:rustc-check-cfg=cfg(incise_avx512)");
    println!("cargo:rerun-if-env-changed=RUSTC");
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    let version = Command::new(rustc)
        .arg("--version")
        .output()
        .ok()
        .and_then(|o| String::from_utf8(o.stdout).ok());
    if version.as_deref().and_then(major_minor) >= Some((1, 89)) {
        println!("cargo:rustc-cfg=incise_avx512");
    }
}

/// `(1, 95)` from `rustc 1.95.0 (59807616e 2026-04-14)`.
fn major_minor(version: &str) -> Option<(u32, u32)> {
    let mut parts = version.split_whitespace().nth(1)?.split('.');
    Some((parts.next()?.parse().ok()?, parts.next()?.parse().ok()?))
}
