//! Finds libode with pkg-config, compiles the message shim with cc and
//! generates the raw bindings with bindgen.

use std::env;
use std::path::PathBuf;

const MIN_ODE_VERSION: &str = "0.16";

fn main() {
    println!("cargo:rerun-if-changed=wrapper.h");
    println!("cargo:rerun-if-changed=shim/ode_shim.c");
    println!("cargo:rerun-if-changed=shim/ode_shim.h");

    let ode = match pkg_config::Config::new().atleast_version(MIN_ODE_VERSION).probe("ode") {
        Ok(lib) => lib,
        Err(err) => {
            eprintln!(
                "\nerror: libode >= {MIN_ODE_VERSION} was not found by pkg-config ({err}).\n\
                 On Debian or Ubuntu install it with:  sudo apt-get install libode-dev pkg-config\n"
            );
            std::process::exit(1);
        }
    };
    println!("cargo:version={}", ode.version);
    println!("cargo:rustc-env=ODE_SYS_LIBODE_VERSION={}", ode.version);

    let mut shim = cc::Build::new();
    shim.file("shim/ode_shim.c").warnings(true);
    // ODE's include paths go after the compiler's own system headers, here
    // and for bindgen: a build against another C library's headers (the
    // portable wheel's, through zig) must not pick up this host's libc
    // headers from pkg-config's /usr/include.
    for path in &ode.include_paths {
        shim.flag("-idirafter").flag(path.display().to_string());
    }
    shim.compile("psa_ode_shim");

    let mut builder = bindgen::Builder::default()
        .header("wrapper.h")
        .allowlist_function("d[A-Z].*")
        .allowlist_type("d[A-Z].*")
        .allowlist_var("d[A-Z].*")
        .allowlist_function("psa_ode_.*")
        .allowlist_type("psa_ode_.*")
        .allowlist_var("PSA_ODE_.*")
        .default_enum_style(bindgen::EnumVariation::Consts)
        .derive_default(true)
        .layout_tests(false)
        .parse_callbacks(Box::new(bindgen::CargoCallbacks::new()));
    for path in &ode.include_paths {
        builder = builder.clang_args(["-idirafter".to_owned(), path.display().to_string()]);
    }
    for (name, value) in &ode.defines {
        builder = builder.clang_arg(match value {
            Some(v) => format!("-D{name}={v}"),
            None => format!("-D{name}"),
        });
    }
    // bindgen panics when it cannot load libclang: turn that into a message.
    let generated = std::panic::catch_unwind(std::panic::AssertUnwindSafe(move || builder.generate()))
        .unwrap_or_else(|_| Err(bindgen::BindgenError::NotExist(PathBuf::from("libclang"))));
    let bindings = match generated {
        Ok(b) => b,
        Err(err) => {
            eprintln!(
                "\nerror: bindgen could not generate the ODE bindings ({err}).\n\
                 bindgen needs libclang; on Debian or Ubuntu install it with:  sudo apt-get install libclang-dev\n"
            );
            std::process::exit(1);
        }
    };
    let out = PathBuf::from(env::var("OUT_DIR").expect("cargo sets OUT_DIR"));
    bindings
        .write_to_file(out.join("bindings.rs"))
        .expect("write bindings.rs into OUT_DIR");
}
