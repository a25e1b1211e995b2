// Compiles the C++ shim (cpp/) against Debian's double-precision Bullet through cxx.

fn main() {
    println!("cargo:rerun-if-changed=cpp/shim.h");
    println!("cargo:rerun-if-changed=cpp/shim.cc");
    println!("cargo:rerun-if-changed=src/engine/bullet.rs");

    // bullet-float64 defines BT_USE_DOUBLE_PRECISION; mixing it with the single-precision
    // libraries corrupts memory, so take every flag from pkg-config and nothing by hand.
    let bullet = match pkg_config::Config::new()
        .atleast_version("3.0")
        .probe("bullet-float64")
    {
        Ok(lib) => lib,
        Err(e) => {
            eprintln!(
                "dicephys: Bullet (double precision) not found; install it with \
                 `apt-get install -y libbullet-dev pkg-config` ({e})"
            );
            std::process::exit(1);
        }
    };

    let mut build = cxx_build::bridge("src/engine/bullet.rs");
    build.file("cpp/shim.cc").std("c++17").warnings(false);
    for path in &bullet.include_paths {
        build.include(path);
    }
    for (name, value) in &bullet.defines {
        match value {
            Some(v) => build.define(name, v.as_str()),
            None => build.define(name, None),
        };
    }
    build.flag_if_supported("-O2");
    build.compile("dicephys-shim");
}
