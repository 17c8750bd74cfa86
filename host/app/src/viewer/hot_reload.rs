//! Watches `shaders/` so edits rebuild the affected pipelines while the viewer runs.

use std::path::{Path, PathBuf};
use std::sync::mpsc::{Receiver, channel};
use std::time::Duration;

use web_time::Instant;

use notify::{RecursiveMode, Watcher};

/// Quiet time after the last change before reloading (editors write in several steps).
const SETTLE: Duration = Duration::from_millis(150);

/// Reports when WGSL files under a folder change.
pub struct ShaderWatcher {
    root: PathBuf,
    events: Receiver<notify::Result<notify::Event>>,
    /// When the newest unhandled change arrived.
    pending_since: Option<Instant>,
    _watcher: notify::RecommendedWatcher,
}

impl ShaderWatcher {
    /// Watches `root` recursively.
    pub fn new(root: &Path) -> anyhow::Result<ShaderWatcher> {
        let (sender, events) = channel();
        let mut watcher = notify::recommended_watcher(move |event| {
            let _ = sender.send(event);
        })?;
        watcher
            .watch(root, RecursiveMode::Recursive)
            .map_err(|e| anyhow::anyhow!("cannot watch {}: {e}", root.display()))?;
        Ok(ShaderWatcher {
            root: root.to_path_buf(),
            events,
            pending_since: None,
            _watcher: watcher,
        })
    }

    /// The watched folder.
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// True once after WGSL files changed and then stayed unchanged for a moment.
    pub fn poll(&mut self) -> bool {
        while let Ok(event) = self.events.try_recv() {
            let touches_wgsl = event.is_ok_and(|e| {
                !e.kind.is_access()
                    && e.paths
                        .iter()
                        .any(|p| p.extension().is_some_and(|x| x == "wgsl"))
            });
            if touches_wgsl {
                self.pending_since = Some(Instant::now());
            }
        }
        match self.pending_since {
            Some(since) if since.elapsed() >= SETTLE => {
                self.pending_since = None;
                true
            }
            _ => false,
        }
    }
}
