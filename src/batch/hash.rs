//! The content hash that decides whether a scene's output is still current: SHA-256 over the
//! tool version, the options, the scene's relative path and every input file's name and bytes.

use super::discover::{SceneEntry, SceneKind};
use crate::error::{Error, Result};
use crate::pipeline::ExportJob;
use sha2::{Digest, Sha256};
use std::io::Read;
use std::path::{Path, PathBuf};

/// Bumped when the batch output layout changes (invalidates every earlier output).
const LAYOUT: &str = "interact3d-batch/1";

/// A stable text of everything in `job` that changes the output, plus the bytes of any
/// template overrides. `force` is left out (it decides whether to replace, not what is written).
/// The options are all plain data (numbers, enums, ordered maps), so their `Debug` text is
/// deterministic and lists every field, including ones added later.
pub fn options_fingerprint(job: &ExportJob) -> Result<Vec<u8>> {
    let mut j = job.clone();
    j.export.force = false;
    let templates = j.export.templates.take();
    let mut out = format!(
        "{LAYOUT}\ninteract3d {}\n{j:?}\n",
        env!("CARGO_PKG_VERSION")
    )
    .into_bytes();
    if let Some(dir) = templates {
        for name in ["scene.xml.j2", "object.xml.j2", "object.urdf.j2"] {
            let p = dir.join(name);
            out.extend_from_slice(format!("template {name}\n").as_bytes());
            if p.is_file() {
                let bytes = std::fs::read(&p).map_err(|e| Error::io(&p, e))?;
                out.extend_from_slice(&(bytes.len() as u64).to_le_bytes());
                out.extend_from_slice(&bytes);
            }
        }
    }
    Ok(out)
}

/// Short hex digest of the options alone (to tell whether shard summaries agree).
pub fn options_hash(fingerprint: &[u8]) -> String {
    hex(&Sha256::digest(fingerprint))[..16].to_string()
}

/// The input files of a scene, sorted by their path relative to the scene folder. A sample folder
/// is read as `metadata.json` + `object_*.glb` (all the loader reads). A manifest may reference
/// any file inside its folder (meshes, MTL, textures, glTF buffers), so every file below the
/// folder counts: a change to an unrelated file costs a recomputation, never a stale output.
pub fn input_files(entry: &SceneEntry) -> Result<Vec<(String, PathBuf)>> {
    let mut files = Vec::new();
    match entry.kind {
        SceneKind::Sample => {
            for e in std::fs::read_dir(&entry.dir).map_err(|e| Error::io(&entry.dir, e))? {
                let e = e.map_err(|e| Error::io(&entry.dir, e))?;
                let name = e.file_name().to_string_lossy().into_owned();
                if name == "metadata.json"
                    || (name.starts_with("object_") && name.ends_with(".glb"))
                {
                    files.push((name, e.path()));
                }
            }
        }
        SceneKind::Manifest => {
            let mut seen = std::collections::HashSet::new();
            walk(&entry.dir, "", &mut seen, &mut files)?
        }
    }
    files.sort();
    Ok(files)
}

/// Every file below `dir`; links to folders are followed once (a link back up is not a loop).
fn walk(
    dir: &Path,
    rel: &str,
    seen: &mut std::collections::HashSet<PathBuf>,
    out: &mut Vec<(String, PathBuf)>,
) -> Result<()> {
    if !seen.insert(dir.canonicalize().map_err(|e| Error::io(dir, e))?) {
        return Ok(());
    }
    for e in std::fs::read_dir(dir).map_err(|e| Error::io(dir, e))? {
        let e = e.map_err(|e| Error::io(dir, e))?;
        let name = e.file_name().to_string_lossy().into_owned();
        let r = if rel.is_empty() {
            name
        } else {
            format!("{rel}/{name}")
        };
        let p = e.path();
        if p.is_dir() {
            walk(&p, &r, seen, out)?;
        } else if p.is_file() {
            out.push((r, p));
        }
    }
    Ok(())
}

/// The scene's hash (hex SHA-256).
pub fn scene_hash(entry: &SceneEntry, fingerprint: &[u8]) -> Result<String> {
    let mut h = Sha256::new();
    h.update((fingerprint.len() as u64).to_le_bytes());
    h.update(fingerprint);
    h.update((entry.rel.len() as u64).to_le_bytes());
    h.update(entry.rel.as_bytes());
    let mut buf = vec![0u8; 1 << 16];
    for (name, path) in input_files(entry)? {
        h.update((name.len() as u64).to_le_bytes());
        h.update(name.as_bytes());
        let mut f = std::fs::File::open(&path).map_err(|e| Error::io(&path, e))?;
        let len = f.metadata().map_err(|e| Error::io(&path, e))?.len();
        h.update(len.to_le_bytes());
        let mut read = 0u64;
        loop {
            let n = f.read(&mut buf).map_err(|e| Error::io(&path, e))?;
            if n == 0 {
                break;
            }
            read += n as u64;
            h.update(&buf[..n]);
        }
        if read != len {
            return Err(Error::input(&path, "file changed while being read"));
        }
    }
    Ok(hex(&h.finalize()))
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hash_follows_inputs_and_options_only() {
        let t = tempfile::tempdir().unwrap();
        let d = t.path().join("cat/00001_x");
        std::fs::create_dir_all(&d).unwrap();
        std::fs::write(d.join("metadata.json"), b"{}").unwrap();
        std::fs::write(d.join("object_a.glb"), b"aaaa").unwrap();
        std::fs::write(d.join("README.md"), b"notes").unwrap();
        let e = SceneEntry {
            rel: "cat/00001_x".into(),
            dir: d.clone(),
            kind: SceneKind::Sample,
        };
        let job = ExportJob::default();
        let fp = options_fingerprint(&job).unwrap();
        let h0 = scene_hash(&e, &fp).unwrap();
        assert_eq!(h0, scene_hash(&e, &fp).unwrap());
        // Files the loader does not read do not count.
        std::fs::write(d.join("README.md"), b"other notes").unwrap();
        assert_eq!(h0, scene_hash(&e, &fp).unwrap());
        std::fs::write(d.join("object_a.glb"), b"aaab").unwrap();
        let h1 = scene_hash(&e, &fp).unwrap();
        assert_ne!(h0, h1);
        let mut job2 = job.clone();
        job2.build.decompose.max_hulls += 1;
        assert_ne!(
            h1,
            scene_hash(&e, &options_fingerprint(&job2).unwrap()).unwrap()
        );
        let mut job3 = job.clone();
        job3.export.force = true;
        assert_eq!(
            h1,
            scene_hash(&e, &options_fingerprint(&job3).unwrap()).unwrap()
        );
    }
}
