//! File-system helpers: atomic writes, atomic output folders, stable JSON.
//!
//! Entry points: [`write`], [`write_atomically`], [`write_new_atomically`],
//! [`write_dir_atomically`], [`create_dir`], [`json_bytes`]. Files and folders made through a temporary path get the modes a plain
//! `create` would give them (0666 / 0777 less the umask: 0644 / 0755 under the usual 022), not
//! the owner-only modes of temporary files, so other users and web servers can read the output.

use crate::error::{Error, Result};
use std::path::Path;

/// The mode asked for when creating a file (the kernel takes the umask off).
#[cfg(unix)]
fn file_mode() -> std::fs::Permissions {
    std::os::unix::fs::PermissionsExt::from_mode(0o666)
}

/// The mode asked for when creating a folder (the kernel takes the umask off).
#[cfg(unix)]
fn dir_mode() -> std::fs::Permissions {
    std::os::unix::fs::PermissionsExt::from_mode(0o777)
}

/// A temporary-path builder whose files and folders honour the umask like a plain create.
fn builder<'a>(prefix: &'a str, dir: bool) -> tempfile::Builder<'a, 'a> {
    let mut b = tempfile::Builder::new();
    b.prefix(prefix);
    #[cfg(unix)]
    b.permissions(if dir { dir_mode() } else { file_mode() });
    #[cfg(not(unix))]
    let _ = dir;
    b
}

/// Write a file (the parent must exist).
pub fn write(path: &Path, bytes: &[u8]) -> Result<()> {
    std::fs::write(path, bytes).map_err(|e| Error::io(path, e))
}

/// Write a file through a temporary file in the same folder and a rename.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<()> {
    temp_beside(path, bytes)?
        .persist(path)
        .map_err(|e| Error::io(path, e.error))?;
    Ok(())
}

/// `bytes` in a temporary file in `path`'s folder, ready to be renamed onto `path`.
fn temp_beside(path: &Path, bytes: &[u8]) -> Result<tempfile::NamedTempFile> {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let mut tmp = builder(".interact3d-", false)
        .tempfile_in(dir)
        .map_err(|e| Error::io(dir, e))?;
    std::io::Write::write_all(&mut tmp, bytes).map_err(|e| Error::io(path, e))?;
    Ok(tmp)
}

/// Like [`write_atomically`], but never replaces: `Ok(false)` when `path` already exists (made
/// by another process, perhaps at the same moment), `Ok(true)` when this call created it.
pub fn write_new_atomically(path: &Path, bytes: &[u8]) -> Result<bool> {
    match temp_beside(path, bytes)?.persist_noclobber(path) {
        Ok(_) => Ok(true),
        Err(e) if e.error.kind() == std::io::ErrorKind::AlreadyExists => Ok(false),
        Err(e) => Err(Error::io(path, e.error)),
    }
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
    let tmp = builder(".interact3d-tmp-", true)
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

#[cfg(all(test, target_os = "linux"))]
mod tests {
    use super::*;
    use std::os::unix::fs::PermissionsExt;

    /// This process's umask, as the kernel reports it.
    fn umask() -> u32 {
        let status = std::fs::read_to_string("/proc/self/status").unwrap();
        let line = status.lines().find(|l| l.starts_with("Umask:")).unwrap();
        u32::from_str_radix(line["Umask:".len()..].trim(), 8).unwrap()
    }

    fn mode(p: &Path) -> u32 {
        std::fs::metadata(p).unwrap().permissions().mode() & 0o777
    }

    #[test]
    fn atomic_writes_get_the_modes_of_a_plain_create() {
        let t = tempfile::tempdir().unwrap();
        let u = umask();
        // The kernel's own answer for a plain create in the same folder.
        write(&t.path().join("plain.txt"), b"x").unwrap();
        std::fs::create_dir(t.path().join("plain_dir")).unwrap();
        assert_eq!(mode(&t.path().join("plain.txt")), 0o666 & !u);
        assert_eq!(mode(&t.path().join("plain_dir")), 0o777 & !u);

        let f = t.path().join("atomic.json");
        write_atomically(&f, b"{}").unwrap();
        assert_eq!(mode(&f), mode(&t.path().join("plain.txt")), "umask {u:o}");
        // Replacing a file keeps the rule (the new file is a new inode).
        write_atomically(&f, b"{ }").unwrap();
        assert_eq!(mode(&f), 0o666 & !u);

        let d = t.path().join("folder");
        write_dir_atomically(&d, false, |tmp| write(&tmp.join("a.txt"), b"a")).unwrap();
        assert_eq!(mode(&d), mode(&t.path().join("plain_dir")), "umask {u:o}");
        assert_eq!(mode(&d.join("a.txt")), 0o666 & !u);
        // Under the usual umask that is readable by everyone.
        if u == 0o022 {
            assert_eq!((mode(&f), mode(&d)), (0o644, 0o755));
        }
    }
}
