//! Where the files a model names (`urdf("...")`) are looked for.
//!
//! A relative path is looked up first from the directory of the crate's
//! `Cargo.toml` (`CARGO_MANIFEST_DIR`), as the model language has always
//! read it, then beside the source file that holds the model, as
//! `include_str!` reads it. The second place makes a model independent of
//! where cargo builds it: trybuild, for one, compiles a test's source in a
//! crate of its own under the target directory.

use std::path::{Component, Path, PathBuf};

/// The directories a relative path in a model starts from, in the order
/// they are tried.
///
/// ```
/// use appell_codegen::FileRoots;
/// use std::path::Path;
///
/// let roots = FileRoots::new(Some(Path::new("/crate")), Some(Path::new("/crate/tests")));
/// // Neither candidate exists here, so the first is the one reported.
/// assert_eq!(roots.candidates("robot.urdf")[0], Path::new("/crate/robot.urdf"));
/// assert_eq!(roots.candidates("../robot.urdf")[1], Path::new("/crate/robot.urdf"));
/// ```
#[derive(Debug, Clone, Default)]
pub struct FileRoots {
    /// The crate's directory, `CARGO_MANIFEST_DIR`.
    pub manifest_dir: Option<PathBuf>,
    /// The directory of the source file the model is written in.
    pub source_dir: Option<PathBuf>,
}

impl FileRoots {
    /// Roots from a crate directory and a source file's directory.
    pub fn new(manifest_dir: Option<&Path>, source_dir: Option<&Path>) -> FileRoots {
        FileRoots {
            manifest_dir: manifest_dir.map(Path::to_path_buf),
            source_dir: source_dir.map(Path::to_path_buf),
        }
    }

    /// The crate directory in the environment's `CARGO_MANIFEST_DIR`, and
    /// no source directory.
    pub fn from_env() -> FileRoots {
        let dir = std::env::var_os("CARGO_MANIFEST_DIR").map(PathBuf::from);
        FileRoots::new(dir.as_deref(), None)
    }

    /// These roots with the directory of `source_file` as the second.
    pub fn beside(mut self, source_file: Option<&Path>) -> FileRoots {
        self.source_dir = source_file.and_then(Path::parent).map(Path::to_path_buf);
        self
    }

    /// Whether any root is known (without one a relative path has nowhere
    /// to start).
    pub fn is_empty(&self) -> bool {
        self.manifest_dir.is_none() && self.source_dir.is_none()
    }

    /// The paths `written` may name, in the order they are tried (an
    /// absolute path names itself, with or without roots).
    pub fn candidates(&self, written: &str) -> Vec<PathBuf> {
        if Path::new(written).is_absolute() {
            return vec![normalized(Path::new(written))];
        }
        [&self.manifest_dir, &self.source_dir]
            .into_iter()
            .flatten()
            .map(|dir| normalized(&dir.join(written)))
            .collect()
    }

    /// The first candidate that exists, or the reason none does.
    pub(crate) fn find(&self, written: &str) -> Result<PathBuf, String> {
        let candidates = self.candidates(written);
        if let Some(found) = candidates.iter().find(|p| p.is_file()) {
            return Ok(found.clone());
        }
        if Path::new(written).is_absolute() {
            return Err(format!("cannot find the URDF file `{written}`"));
        }
        Err(match (&self.manifest_dir, &self.source_dir) {
            (_, Some(_)) => format!(
                "cannot find the URDF file `{written}`: it is neither under the crate's directory \
                 (CARGO_MANIFEST_DIR) nor at `{}`, beside this source file",
                candidates.last().expect("a source root").display()
            ),
            (Some(_), None) => format!(
                "cannot find the URDF file `{}` (a relative path is taken from the directory of \
                 the crate's Cargo.toml)",
                candidates[0].display()
            ),
            (None, None) => "cannot find the URDF: CARGO_MANIFEST_DIR, the directory a relative \
                             path starts from, is not set"
                .to_string(),
        })
    }
}

/// `path` with `.` and `..` taken out by the names alone (so the path need
/// not pass through directories that exist).
fn normalized(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for part in path.components() {
        match part {
            Component::CurDir => {}
            Component::ParentDir => {
                if !out.pop() {
                    out.push("..");
                }
            }
            other => out.push(other),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dot_dot_is_taken_out_by_name() {
        let p = normalized(&Path::new("/a/b/target/x").join("../../c/./d.urdf"));
        assert_eq!(p, Path::new("/a/b/c/d.urdf"));
        let absolute = FileRoots::new(Some(Path::new("/a")), None).candidates("/e/f.urdf");
        assert_eq!(absolute, [Path::new("/e/f.urdf")]);
    }

    #[test]
    fn a_file_beside_the_source_is_found_when_the_crate_has_none() {
        let dir = std::env::temp_dir().join(format!("appell-roots-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("src")).unwrap();
        std::fs::write(dir.join("src/r.urdf"), "<robot/>").unwrap();
        let roots = FileRoots::new(Some(&dir.join("elsewhere")), None)
            .beside(Some(&dir.join("src/model.rs")));
        assert_eq!(roots.find("r.urdf").unwrap(), dir.join("src/r.urdf"));
        let missing = roots.find("s.urdf").unwrap_err();
        assert!(missing.contains("beside this source file"), "{missing}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn the_crate_directory_is_tried_first() {
        let dir = std::env::temp_dir().join(format!("appell-roots-first-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("src")).unwrap();
        std::fs::write(dir.join("r.urdf"), "<robot/>").unwrap();
        std::fs::write(dir.join("src/r.urdf"), "<robot/>").unwrap();
        let roots = FileRoots::new(Some(&dir), Some(&dir.join("src")));
        assert_eq!(roots.find("r.urdf").unwrap(), dir.join("r.urdf"));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn without_roots_the_error_names_the_missing_variable() {
        let e = FileRoots::default().find("r.urdf").unwrap_err();
        assert!(e.contains("CARGO_MANIFEST_DIR"), "{e}");
    }

    #[test]
    fn an_absolute_path_needs_no_root() {
        let dir = std::env::temp_dir().join(format!("appell-roots-abs-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("r.urdf");
        std::fs::write(&file, "<robot/>").unwrap();
        let written = file.to_str().unwrap();
        assert_eq!(FileRoots::default().find(written).unwrap(), file);
        let e = FileRoots::default()
            .find(dir.join("s.urdf").to_str().unwrap())
            .unwrap_err();
        assert!(
            e.contains("s.urdf") && !e.contains("CARGO_MANIFEST_DIR"),
            "{e}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
