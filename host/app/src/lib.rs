//! The Shadow Zoo application: the `shadow-zoo` command line (and, later, the viewer).
//!
//! This library links every technique plugin listed in the package's `Cargo.toml`, so the
//! binary and the workspace integration tests see the same registry.

pub mod bench;
pub mod claims;
pub mod cli;
pub mod commands;
pub mod compare;
pub mod contact_sheet;
pub mod font;
pub mod gpu_judge;
pub mod ron_file;
pub mod setup;
pub mod viewer;

mod linked {
    include!(concat!(env!("OUT_DIR"), "/linked_plugins.rs"));
}

pub use linked::LINKED_PLUGINS;

/// The default scene, compiled in so the application starts from any directory.
pub const DEFAULT_SCENE_NAME: &str = "planar-room.ron";
/// Text of the default scene.
pub const DEFAULT_SCENE: &str = include_str!("../../../scenes/planar-room.ron");
