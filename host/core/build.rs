//! Embeds every WGSL file under the workspace's `shaders/` folder into the library, so the
//! binaries run from any directory. The viewer can still reload them from disk.
//!
//! Every path this script prints or generates is relative to the package (`rerun-if-changed`)
//! or to `CARGO_MANIFEST_DIR` at compile time (`include_str!`): a `target/` folder copied
//! from another checkout embeds, and watches, the shaders of the checkout it builds in.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The shader folder, relative to this package.
const SHADERS: &str = "../../shaders";

/// Adds every WGSL file under `dir` to `out` as its path relative to `root`, and watches
/// every folder and file by its path relative to the package.
fn collect(dir: &Path, root: &Path, out: &mut Vec<String>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut entries: Vec<_> = entries.filter_map(Result::ok).map(|e| e.path()).collect();
    entries.sort();
    for path in entries {
        let name = path
            .strip_prefix(root)
            .expect("inside the shader root")
            .to_string_lossy()
            .replace('\\', "/");
        if path.is_dir() {
            println!("cargo:rerun-if-changed={SHADERS}/{name}");
            collect(&path, root, out);
        } else if path.extension().is_some_and(|e| e == "wgsl") {
            println!("cargo:rerun-if-changed={SHADERS}/{name}");
            out.push(name);
        }
    }
}

fn main() {
    let manifest = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("set by cargo"));
    let root = manifest.join(SHADERS);
    println!("cargo:rerun-if-changed={SHADERS}");
    let mut files = Vec::new();
    collect(&root, &root, &mut files);
    let mut code =
        String::from("/// Every WGSL file under `shaders/`, as (relative path, source).\n");
    code.push_str("pub static EMBEDDED: &[(&str, &str)] = &[\n");
    for name in &files {
        writeln!(
            code,
            "    ({name:?}, include_str!(concat!(env!(\"CARGO_MANIFEST_DIR\"), \"/{SHADERS}/{name}\"))),"
        )
        .unwrap();
    }
    code.push_str("];\n");
    writeln!(
        code,
        "/// Where the shaders were at build time (for hot reload).\npub const SOURCE_ROOT: &str = concat!(env!(\"CARGO_MANIFEST_DIR\"), \"/{SHADERS}\");"
    )
    .unwrap();
    let out =
        PathBuf::from(std::env::var("OUT_DIR").expect("set by cargo")).join("embedded_shaders.rs");
    std::fs::write(out, code).expect("write embedded_shaders.rs");
}
