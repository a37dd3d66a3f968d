//! File formats. Writers write atomically: to a temporary file in the destination folder, then
//! renamed over the destination, so a crash never leaves a half-written file under the real name.

pub mod glb_write;

pub use glb_write::{to_glb_bytes, to_glb_bytes_with, write_glb, write_glb_with, GlbOptions};

use crate::error::{IoContext, Result};
use std::path::Path;

/// Write `bytes` to `path` atomically: a temporary file beside it (same folder, so the rename
/// stays on one file system), flushed, then renamed over `path`. The temporary file is removed
/// when anything fails.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    use std::io::Write;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into());
    let tmp = dir.join(format!(".{name}.{}.tmp", std::process::id()));
    let result = (|| -> Result<()> {
        let mut f = std::fs::File::create(&tmp).at(&tmp)?;
        f.write_all(bytes).at(&tmp)?;
        f.sync_all().at(&tmp)?;
        drop(f);
        std::fs::rename(&tmp, path).at(path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}
