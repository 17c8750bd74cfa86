//! Helpers for plugin and integration tests: one shared headless GPU context per test binary.

use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};

use crate::gpu::GpuContext;

/// The shared headless context, created on first use. Panics with the driver install hint when
/// no adapter exists, since GPU tests cannot run then.
pub fn gpu() -> Arc<GpuContext> {
    static GPU: OnceLock<Arc<GpuContext>> = OnceLock::new();
    GPU.get_or_init(|| match GpuContext::new_headless() {
        Ok(gpu) => {
            eprintln!("GPU tests run on {}", gpu.describe());
            Arc::new(gpu)
        }
        Err(e) => panic!("{e}"),
    })
    .clone()
}

/// The workspace root (where `scenes/` and `shaders/` are).
pub fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Path of a scene shipped in `scenes/`.
pub fn scene_path(name: &str) -> PathBuf {
    workspace_root().join("scenes").join(name)
}
