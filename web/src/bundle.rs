//! The scene files compiled into the build, mounted where scenes look for them.

mod generated {
    include!(concat!(env!("OUT_DIR"), "/bundled_scenes.rs"));
}

/// Mounts every bundled file at its path from the repository root (`scenes/...`).
pub fn mount_scenes() {
    for (path, bytes) in generated::FILES {
        zoo_host::scene::files::mount(path, bytes.to_vec());
    }
}
