//! Where an image's encoded bytes are ([`ImageSource`]): a file of its own, or inside another.

use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Where an image's encoded bytes are.
#[derive(Debug, Clone, PartialEq)]
pub enum ImageSource {
    /// A file of its own.
    File(PathBuf),
    /// Bytes inside another file (a GLB's binary chunk, a data URI); `name` says where.
    Encoded { name: PathBuf, bytes: Arc<[u8]> },
}

impl ImageSource {
    /// The file, or the place in a file, that names the image in warnings and layers.
    pub fn name(&self) -> &Path {
        match self {
            ImageSource::File(path) | ImageSource::Encoded { name: path, .. } => path,
        }
    }
}
