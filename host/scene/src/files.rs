//! Where scene files are read from: files mounted in memory first, then the file system.
//!
//! A build without a file system (the browser's) mounts the bundled scenes and the files a
//! user picks; scene, OBJ, MTL, glTF and image reads all go through [`read`], so a mounted
//! scene finds its models and textures by the same relative paths as on disk.

use std::collections::HashMap;
use std::io;
use std::path::{Component, Path, PathBuf};
use std::sync::{Arc, RwLock};

/// Files mounted in memory, by normalised path.
static MOUNTED: RwLock<Option<HashMap<PathBuf, Arc<[u8]>>>> = RwLock::new(None);

/// `path` without `.` components and with `..` applied where it can be, so that
/// `scenes/../scenes/a.ron` and `scenes/a.ron` name one mounted file.
fn normalised(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for component in path.components() {
        match component {
            Component::CurDir => {}
            Component::ParentDir if out.file_name().is_some() => {
                out.pop();
            }
            other => out.push(other),
        }
    }
    out
}

/// Makes `bytes` readable at `path` (replacing what was mounted there).
pub fn mount(path: impl AsRef<Path>, bytes: impl Into<Arc<[u8]>>) {
    let mut mounted = MOUNTED.write().unwrap_or_else(|e| e.into_inner());
    mounted
        .get_or_insert_with(HashMap::new)
        .insert(normalised(path.as_ref()), bytes.into());
}

/// The mounted files under `folder` (not recursive), sorted.
pub fn mounted_in(folder: &Path) -> Vec<PathBuf> {
    let folder = normalised(folder);
    let mounted = MOUNTED.read().unwrap_or_else(|e| e.into_inner());
    let mut files: Vec<PathBuf> = (mounted.iter().flat_map(|m| m.keys()))
        .filter(|p| p.parent() == Some(folder.as_path()))
        .cloned()
        .collect();
    files.sort();
    files
}

/// The bytes of `path`: the mounted file, else the file on disk.
pub fn read(path: &Path) -> io::Result<Vec<u8>> {
    let mounted = MOUNTED.read().unwrap_or_else(|e| e.into_inner());
    if let Some(bytes) = mounted.as_ref().and_then(|m| m.get(&normalised(path))) {
        return Ok(bytes.to_vec());
    }
    drop(mounted);
    std::fs::read(path)
}

/// The text of `path` (see [`read`]).
pub fn read_to_string(path: &Path) -> io::Result<String> {
    String::from_utf8(read(path)?).map_err(|e| io::Error::new(io::ErrorKind::InvalidData, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mounted_files_are_read_before_the_disk_by_any_spelling_of_their_path() {
        mount("mounted-test/scenes/a.ron", b"(objects: [])".to_vec());
        let text = read_to_string(Path::new("mounted-test/scenes/../scenes/./a.ron")).unwrap();
        assert_eq!(text, "(objects: [])");
        assert_eq!(
            mounted_in(Path::new("mounted-test/scenes")),
            vec![PathBuf::from("mounted-test/scenes/a.ron")]
        );
        let missing = read(Path::new("mounted-test/scenes/b.ron")).unwrap_err();
        assert_eq!(missing.kind(), io::ErrorKind::NotFound);
    }
}
