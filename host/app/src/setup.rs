//! What every command starts from: the scene to open and the headless GPU.

use std::path::Path;
use std::sync::Arc;

use anyhow::bail;
use zoo_host::{GpuContext, Scene, ShaderLibrary};

/// Loads `path`, or the built-in default scene when `None`.
pub fn load_scene(path: Option<&Path>) -> anyhow::Result<Scene> {
    Ok(match path {
        Some(path) => Scene::load(path)?,
        None => Scene::from_ron(
            crate::DEFAULT_SCENE,
            Path::new(crate::DEFAULT_SCENE_NAME),
            Path::new("scenes"),
        )?,
    })
}

/// Creates the headless GPU context and prints what it runs on.
pub fn headless_gpu() -> anyhow::Result<Arc<GpuContext>> {
    let gpu = GpuContext::new_headless()?;
    println!("adapter: {}", gpu.describe());
    Ok(Arc::new(gpu))
}

/// The shaders of `--shaders DIR` (read from there first, the built-in copies otherwise), or
/// the built-in ones; prints where they come from.
pub fn shader_library(dir: Option<&Path>) -> anyhow::Result<ShaderLibrary> {
    let Some(dir) = dir else {
        return Ok(ShaderLibrary::embedded());
    };
    if !dir.is_dir() {
        bail!("--shaders {}: no such folder", dir.display());
    }
    let root = dir.canonicalize()?;
    println!(
        "shaders: {} first, then the built-in copies",
        root.display()
    );
    Ok(ShaderLibrary::from_disk(root))
}
