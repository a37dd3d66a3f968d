//! Finding the scenes of a dataset: every folder under ROOT holding a `metadata.json` (an
//! Interact3D sample folder) or a `scene.json` (a manifest), in a stable order, filtered by
//! globs and by shard.

use crate::error::{Error, Result};
use globset::{Glob, GlobSet, GlobSetBuilder};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// What kind of scene a folder holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SceneKind {
    /// `metadata.json` + `object_*.glb`.
    Sample,
    /// `scene.json` and the meshes it references (inside the folder).
    Manifest,
}

/// One scene found under ROOT.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SceneEntry {
    /// Path relative to ROOT with `/` separators (the key of everything: output folder, shard,
    /// summary order).
    pub rel: String,
    /// The scene folder.
    pub dir: PathBuf,
    pub kind: SceneKind,
}

impl SceneEntry {
    /// The folder's name (`<id>_<slug>` in the Interact3D layout).
    pub fn name(&self) -> &str {
        self.rel.rsplit('/').next().unwrap_or(&self.rel)
    }

    /// The parent folder's name (`outputs/<category>/<id>_<slug>`), or "" at the top level.
    pub fn category(&self) -> &str {
        let mut it = self.rel.rsplit('/');
        it.next();
        it.next().unwrap_or("")
    }

    /// The numeric prefix of `<id>_<slug>`, or the whole folder name when there is none.
    pub fn id(&self) -> &str {
        let n = self.name();
        match n.split_once('_') {
            Some((id, _)) if !id.is_empty() && id.bytes().all(|b| b.is_ascii_digit()) => id,
            _ => n,
        }
    }
}

/// A shard `index`/`count` (1-based), as in `--shard 2/3`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

impl std::str::FromStr for Shard {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        let (i, n) = s
            .split_once('/')
            .ok_or_else(|| format!("{s:?}: expected I/N, e.g. 2/8"))?;
        let parse = |x: &str| {
            x.trim()
                .parse::<usize>()
                .map_err(|_| format!("{s:?}: {x:?} is not a whole number"))
        };
        let (index, count) = (parse(i)?, parse(n)?);
        if count == 0 || index == 0 || index > count {
            return Err(format!("{s:?}: need 1 <= I <= N"));
        }
        Ok(Shard { index, count })
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl Shard {
    /// Whether the scene at `rel` belongs to this shard. Depends only on the relative path, so
    /// every machine computes the same partition without talking to the others, and adding or
    /// removing a scene never moves another one to a different shard.
    pub fn contains(&self, rel: &str) -> bool {
        shard_key(rel) % self.count as u64 == (self.index - 1) as u64
    }
}

/// The first 8 bytes of SHA-256 of the relative path, as a number.
pub fn shard_key(rel: &str) -> u64 {
    let d = Sha256::digest(rel.as_bytes());
    u64::from_be_bytes(d[..8].try_into().expect("8 bytes"))
}

/// Compile `--include`/`--exclude` patterns (matched against the relative path with `/`).
pub fn globset(patterns: &[String]) -> Result<Option<GlobSet>> {
    if patterns.is_empty() {
        return Ok(None);
    }
    let mut b = GlobSetBuilder::new();
    for p in patterns {
        let g = Glob::new(p).map_err(|e| Error::Usage(format!("bad glob {p:?}: {e}")))?;
        b.add(g);
    }
    b.build()
        .map(Some)
        .map_err(|e| Error::Usage(format!("bad globs: {e}")))
}

/// The scene folders under `root`, sorted by relative path. Folders whose name starts with `.`
/// and the folders in `skip` (e.g. the output folder when it lies inside ROOT) are not entered;
/// a scene folder is not searched further. Links to folders are followed once.
pub fn discover(root: &Path, skip: &[PathBuf]) -> Result<Vec<SceneEntry>> {
    if !root.is_dir() {
        return Err(Error::input(root, "not a folder"));
    }
    let skip: Vec<PathBuf> = skip.iter().filter_map(|p| p.canonicalize().ok()).collect();
    let mut seen = std::collections::HashSet::new();
    let mut found = Vec::new();
    let mut stack = vec![(root.to_path_buf(), String::new())];
    while let Some((dir, rel)) = stack.pop() {
        let canon = dir.canonicalize().map_err(|e| Error::io(&dir, e))?;
        if skip.contains(&canon) || !seen.insert(canon) {
            continue;
        }
        let kind = if dir.join("scene.json").is_file() {
            Some(SceneKind::Manifest)
        } else if dir.join("metadata.json").is_file() {
            Some(SceneKind::Sample)
        } else {
            None
        };
        if let Some(kind) = kind {
            let rel = if rel.is_empty() {
                // ROOT itself is a scene: name it by its folder.
                canon_name(&dir)
            } else {
                rel
            };
            found.push(SceneEntry { rel, dir, kind });
            continue;
        }
        let mut children = Vec::new();
        for e in std::fs::read_dir(&dir).map_err(|e| Error::io(&dir, e))? {
            let e = e.map_err(|e| Error::io(&dir, e))?;
            let name = e.file_name();
            let Some(name) = name.to_str() else {
                return Err(Error::input(
                    e.path(),
                    "file name is not valid UTF-8; rename it",
                ));
            };
            if name.starts_with('.') {
                continue;
            }
            let path = e.path();
            // is_dir follows links.
            if path.is_dir() {
                let child_rel = if rel.is_empty() {
                    name.to_string()
                } else {
                    format!("{rel}/{name}")
                };
                children.push((path, child_rel));
            }
        }
        children.sort_by(|a, b| b.1.cmp(&a.1));
        stack.extend(children);
    }
    found.sort_by(|a, b| a.rel.cmp(&b.rel));
    Ok(found)
}

fn canon_name(dir: &Path) -> String {
    dir.canonicalize()
        .ok()
        .and_then(|d| d.file_name().map(|n| n.to_string_lossy().into_owned()))
        .unwrap_or_else(|| "scene".into())
}

/// Keep the entries matching `include` (any; all when empty), not matching `exclude`, and in
/// `shard`.
pub fn select(
    entries: Vec<SceneEntry>,
    include: &[String],
    exclude: &[String],
    shard: Option<Shard>,
) -> Result<Vec<SceneEntry>> {
    let inc = globset(include)?;
    let exc = globset(exclude)?;
    Ok(entries
        .into_iter()
        .filter(|e| inc.as_ref().is_none_or(|g| g.is_match(&e.rel)))
        .filter(|e| exc.as_ref().is_none_or(|g| !g.is_match(&e.rel)))
        .filter(|e| shard.is_none_or(|s| s.contains(&e.rel)))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn touch(p: &Path) {
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, b"{}").unwrap();
    }

    #[test]
    fn finds_sample_folders_and_manifests_in_order_and_not_inside_scenes() {
        let t = tempfile::tempdir().unwrap();
        let r = t.path();
        touch(&r.join("outputs/food/00002_b/metadata.json"));
        touch(&r.join("outputs/food/00001_a/metadata.json"));
        touch(&r.join("outputs/food/00001_a/nested/metadata.json"));
        touch(&r.join("outputs/toys/00003_c/scene.json"));
        touch(&r.join("outputs/.hidden/00004_d/metadata.json"));
        touch(&r.join("out/x/metadata.json"));
        std::fs::create_dir_all(r.join("empty")).unwrap();
        let found = discover(r, &[r.join("out")]).unwrap();
        let rels: Vec<&str> = found.iter().map(|e| e.rel.as_str()).collect();
        assert_eq!(
            rels,
            [
                "outputs/food/00001_a",
                "outputs/food/00002_b",
                "outputs/toys/00003_c"
            ]
        );
        assert_eq!(found[2].kind, SceneKind::Manifest);
        assert_eq!(found[0].category(), "food");
        assert_eq!(found[0].id(), "00001");
        let only_food = select(found.clone(), &["**/food/**".into()], &[], None).unwrap();
        assert_eq!(only_food.len(), 2);
        let no_b = select(found, &[], &["*/*/00002_*".into()], None).unwrap();
        assert_eq!(no_b.len(), 2);
    }

    #[test]
    fn shards_partition_and_parse() {
        let rels: Vec<String> = (0..1000).map(|i| format!("c{}/{i:05}_x", i % 9)).collect();
        let n = 7;
        let mut counts = vec![0; n];
        for r in &rels {
            let owners: Vec<usize> = (1..=n)
                .filter(|&i| Shard { index: i, count: n }.contains(r))
                .collect();
            assert_eq!(owners.len(), 1, "{r}");
            counts[owners[0] - 1] += 1;
        }
        assert!(counts.iter().all(|&c| c > 100), "{counts:?}");
        assert_eq!(
            "2/3".parse::<Shard>().unwrap(),
            Shard { index: 2, count: 3 }
        );
        for bad in ["0/3", "4/3", "1/0", "x/3", "3"] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
    }
}
