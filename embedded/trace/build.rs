//! Wraps the seed's `.mech` files (the CLI's scenes, which a main-workspace test holds to the
//! `mechanism!` twins in `examples/src/scenes.rs`) in `mechanism!`, so the firmware and the host
//! compile exactly the scenes the rest of the project uses.

use std::{env, fs, path::PathBuf};

fn main() {
    let manifest = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("set by cargo"));
    let scenes = manifest.join("../../examples/scenes");
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("set by cargo"));
    for name in ["piston_crank", "piston_crank_dynamics"] {
        let path = scenes.join(format!("{name}.mech"));
        println!("cargo::rerun-if-changed={}", path.display());
        let spec = fs::read_to_string(&path)
            .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
        let code = format!("::mechgen_runtime::mechanism! {{\n{spec}\n}}\n");
        fs::write(out.join(format!("{name}.rs")), code).expect("OUT_DIR is writable");
    }
}
