//! The committed C header `include/projfluid.h` must be exactly what cbindgen generates from
//! `src/ffi/` with `cbindgen.toml`, must carry the crate's version, and must compile cleanly
//! as C11 and as C++.
//!
//! Regenerate it with `PROJFLUID_BLESS=1 cargo test --test header`.

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn header_path() -> PathBuf {
    root().join("include/projfluid.h")
}

/// Runs cbindgen on the crate with `cbindgen.toml` and returns the header text.
fn generate() -> String {
    let config = cbindgen::Config::from_file(root().join("cbindgen.toml"))
        .expect("cbindgen.toml must parse");
    let bindings = cbindgen::Builder::new()
        .with_crate(root())
        .with_config(config)
        .generate()
        .expect("cbindgen must generate the header");
    let mut out = Vec::new();
    bindings.write(&mut out);
    String::from_utf8(out).expect("the header is UTF-8")
}

#[test]
fn committed_header_is_up_to_date() {
    let fresh = generate();
    let path = header_path();
    if std::env::var_os("PROJFLUID_BLESS").is_some() {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, &fresh).unwrap();
        eprintln!("wrote {}", path.display());
        return;
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    if committed != fresh {
        let first = committed
            .lines()
            .zip(fresh.lines())
            .position(|(a, b)| a != b)
            .unwrap_or(committed.lines().count().min(fresh.lines().count()));
        panic!(
            "{} is out of date with src/ffi/ (first difference at line {}).\n\
             Regenerate it with: PROJFLUID_BLESS=1 cargo test --test header",
            path.display(),
            first + 1
        );
    }
}

#[test]
fn header_carries_the_crate_version() {
    let header = std::fs::read_to_string(header_path()).unwrap();
    for (name, value) in [
        ("PF_VERSION_MAJOR", env!("CARGO_PKG_VERSION_MAJOR")),
        ("PF_VERSION_MINOR", env!("CARGO_PKG_VERSION_MINOR")),
        ("PF_VERSION_PATCH", env!("CARGO_PKG_VERSION_PATCH")),
    ] {
        let line = format!("#define {name} {value}");
        assert!(
            header.lines().any(|l| l.trim() == line),
            "the header lacks `{line}`; update after_includes in cbindgen.toml and regenerate"
        );
    }
    let abi = format!(
        "#define PF_ABI_VERSION {}",
        projfluid::ffi::pf_abi_version()
    );
    assert!(
        header.lines().any(|l| l.trim() == abi),
        "the header lacks `{abi}`; update cbindgen.toml and regenerate"
    );
}

/// Compiles a translation unit that includes the header, with warnings as errors.
fn compile(compiler: &str, args: &[&str], source: &str, dir: &Path) {
    let file = dir.join(source);
    std::fs::write(
        &file,
        "#include \"projfluid.h\"\n#include \"projfluid.h\"\nint main(void) { return PF_OK; }\n",
    )
    .unwrap();
    let output = match Command::new(compiler)
        .args(args)
        .arg("-I")
        .arg(root().join("include"))
        .arg(&file)
        .output()
    {
        Ok(o) => o,
        Err(e) => {
            assert!(
                std::env::var_os("CI").is_none(),
                "cannot run {compiler} ({e}), and CI must run every check: install it"
            );
            eprintln!("note: skipping the {compiler} check: cannot run {compiler}: {e}");
            return;
        }
    };
    assert!(
        output.status.success(),
        "{compiler} {args:?} rejected the header:\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
}

#[test]
fn header_compiles_as_c11_and_cpp() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("header");
    std::fs::create_dir_all(&dir).unwrap();
    let strict = ["-Wall", "-Wextra", "-Wpedantic", "-Werror", "-fsyntax-only"];
    let c: Vec<&str> = ["-std=c11"].iter().chain(&strict).copied().collect();
    compile("cc", &c, "header_c11.c", &dir);
    let cpp: Vec<&str> = ["-x", "c++", "-std=c++11"]
        .iter()
        .chain(&strict)
        .copied()
        .collect();
    compile("c++", &cpp, "header_cpp.cpp", &dir);
}
