//! File-system helpers: atomic writes, atomic output folders, stable JSON.

use crate::error::{Error, Result};
use std::path::Path;

/// Write a file (the parent must exist).
pub fn write(path: &Path, bytes: &[u8]) -> Result<()> {
    std::fs::write(path, bytes).map_err(|e| Error::io(path, e))
}

/// Write a file through a temporary file in the same folder and a rename.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<()> {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let mut tmp = tempfile::Builder::new()
        .prefix(".interact3d-")
        .tempfile_in(dir)
        .map_err(|e| Error::io(dir, e))?;
    std::io::Write::write_all(&mut tmp, bytes).map_err(|e| Error::io(path, e))?;
    tmp.persist(path).map_err(|e| Error::io(path, e.error))?;
    Ok(())
}

/// Create a folder and its parents.
pub fn create_dir(path: &Path) -> Result<()> {
    std::fs::create_dir_all(path).map_err(|e| Error::io(path, e))
}

/// Pretty JSON with a final newline; struct fields keep their declared order, maps are sorted
/// (we only serialise `BTreeMap`s), so output is byte-stable.
pub fn json_bytes<T: serde::Serialize>(v: &T) -> Result<Vec<u8>> {
    let mut s = serde_json::to_vec_pretty(v).map_err(|e| Error::Internal(format!("JSON: {e}")))?;
    s.push(b'\n');
    Ok(s)
}

/// Whether `out` may be replaced: missing, empty, or an earlier interact3d export (has a
/// `report.json` written by us) or `compose` output (its `metadata.json` names the tool).
fn replaceable(out: &Path) -> bool {
    match std::fs::read_dir(out) {
        Err(_) => true,
        Ok(mut it) => {
            it.next().is_none()
                || ["report.json", "metadata.json"].iter().any(|f| {
                    // report.json: an export; metadata.json: a `compose` output.
                    std::fs::read_to_string(out.join(f))
                        .map(|s| s.contains("\"tool\": \"interact3d\""))
                        .unwrap_or(false)
                })
        }
    }
}

/// Build a folder's content in a temporary sibling folder with `fill`, then move it to `out`
/// (replacing an earlier export). On error nothing is left behind and `out` is untouched.
pub fn write_dir_atomically(
    out: &Path,
    force: bool,
    fill: impl FnOnce(&Path) -> Result<()>,
) -> Result<()> {
    if out.exists() && !out.is_dir() {
        return Err(Error::Usage(format!(
            "{} exists and is not a folder",
            out.display()
        )));
    }
    if out.is_dir() && !force && !replaceable(out) {
        return Err(Error::Usage(format!(
            "{} exists and is not an interact3d export; choose another folder or pass --force",
            out.display()
        )));
    }
    let parent = out
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    create_dir(parent)?;
    let tmp = tempfile::Builder::new()
        .prefix(".interact3d-tmp-")
        .tempdir_in(parent)
        .map_err(|e| Error::io(parent, e))?;
    fill(tmp.path())?;
    let tmp_path = tmp.keep();
    if out.exists() {
        let old = tempfile::Builder::new()
            .prefix(".interact3d-old-")
            .tempdir_in(parent)
            .map_err(|e| Error::io(parent, e))?
            .keep();
        std::fs::remove_dir(&old).map_err(|e| Error::io(&old, e))?;
        std::fs::rename(out, &old).map_err(|e| Error::io(out, e))?;
        if let Err(e) = std::fs::rename(&tmp_path, out) {
            let _ = std::fs::rename(&old, out);
            let _ = std::fs::remove_dir_all(&tmp_path);
            return Err(Error::io(out, e));
        }
        let _ = std::fs::remove_dir_all(&old);
    } else if let Err(e) = std::fs::rename(&tmp_path, out) {
        let _ = std::fs::remove_dir_all(&tmp_path);
        return Err(Error::io(out, e));
    }
    Ok(())
}
