//! Where the shipped scene meshes are found, at run time: the folder named by `--scenes`,
//! else the one in the `DUALSPLIT_SCENES` environment variable, else `shared/scenes` beside
//! a checkout (`<checkout>/../shared/scenes`, the checkout being the nearest folder with a
//! `Cargo.toml` above the current directory or above the executable). And which of the
//! paper's scenes it holds ([`PAPER_FILES`]), so the report can say what it found and what
//! it did not.

use crate::ReportError;
use crate::paper::PaperScene;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The environment variable naming the scenes folder.
pub const ENV_VAR: &str = "DUALSPLIT_SCENES";

/// The meshes that stand for scenes of the paper: file name, paper scene, and whether it is
/// the paper's own scene (the Dragon Box is reconstructed: the paper's dragon in a box the
/// paper does not describe). `crytek_sponza.gltf` (with its `Sponza.bin`) is the Khronos glTF
/// sample's Crytek Sponza as `scripts/get-scenes.sh` saves it.
pub const PAPER_FILES: [(&str, PaperScene, bool); 3] = [
    ("dragon_box.ply.gz", PaperScene::DragonBox, true),
    ("dragon_sponza.ply.gz", PaperScene::DragonSponza, false),
    ("crytek_sponza.gltf", PaperScene::CrytekSponza, true),
];

/// How the scenes folder was found.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Source {
    /// `--scenes DIR`.
    Flag,
    /// The `DUALSPLIT_SCENES` environment variable.
    Env,
    /// `shared/scenes` beside the checkout holding the current directory.
    BesideCheckout,
    /// `shared/scenes` beside the checkout holding the executable.
    BesideExecutable,
}

impl Source {
    /// How it was found, in words.
    pub fn describe(self) -> &'static str {
        match self {
            Source::Flag => "given by --scenes",
            Source::Env => "given by DUALSPLIT_SCENES",
            Source::BesideCheckout => "beside the checkout holding the current directory",
            Source::BesideExecutable => "beside the checkout holding the executable",
        }
    }
}

/// A scenes folder and how it was found.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ScenesDir {
    /// The folder.
    pub path: PathBuf,
    /// How it was found.
    pub source: Source,
}

/// `<checkout>/../shared/scenes` for the nearest checkout (a folder with a `Cargo.toml`)
/// at or above `start` that has one.
fn beside_checkout(start: &Path) -> Option<PathBuf> {
    start.ancestors().find_map(|a| {
        let dir = a.parent()?.join("shared").join("scenes");
        (a.join("Cargo.toml").is_file() && dir.is_dir()).then_some(dir)
    })
}

/// Finds the scenes folder: `flag`, else `env` (the variable's value, if set and not
/// empty), else beside the checkout holding `cwd`, else beside the one holding `exe`.
/// A folder named by `flag` or `env` must exist; `None` when no folder is found otherwise.
pub fn find(
    flag: Option<&Path>,
    env: Option<&std::ffi::OsStr>,
    cwd: &Path,
    exe: Option<&Path>,
) -> Result<Option<ScenesDir>, ReportError> {
    let named = |path: &Path, source: Source, what: &str| {
        if path.is_dir() {
            Ok(Some(ScenesDir {
                path: path.to_path_buf(),
                source,
            }))
        } else {
            Err(ReportError::ScenesDir {
                path: path.to_path_buf(),
                what: what.to_string(),
            })
        }
    };
    if let Some(p) = flag {
        return named(p, Source::Flag, "--scenes");
    }
    if let Some(v) = env.filter(|v| !v.is_empty()) {
        return named(Path::new(v), Source::Env, ENV_VAR);
    }
    if let Some(path) = beside_checkout(cwd) {
        return Ok(Some(ScenesDir {
            path,
            source: Source::BesideCheckout,
        }));
    }
    Ok(exe
        .and_then(|e| beside_checkout(e.parent()?))
        .map(|path| ScenesDir {
            path,
            source: Source::BesideExecutable,
        }))
}

/// [`find`] with this process's current directory, executable and environment.
pub fn find_here(flag: Option<&Path>) -> Result<Option<ScenesDir>, ReportError> {
    let cwd = std::env::current_dir().unwrap_or_else(|_| PathBuf::from("."));
    let exe = std::env::current_exe().ok();
    find(
        flag,
        std::env::var_os(ENV_VAR).as_deref(),
        &cwd,
        exe.as_deref(),
    )
}

/// One of [`PAPER_FILES`], looked for.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PaperFile {
    /// File name.
    pub file: String,
    /// The paper scene it stands for.
    pub scene: PaperScene,
    /// Whether it is the paper's own scene, as far as it can be had (else a stand-in).
    pub same_mesh: bool,
    /// Its path when found.
    pub path: Option<String>,
}

impl PaperFile {
    /// "Dragon Box (dragon_box.ply.gz, the paper's scene as SimTRaX ships it, or …)",
    /// "Crytek Sponza (crytek_sponza.gltf, the paper's mesh)" or "… (…, a stand-in)".
    pub fn describe(&self) -> String {
        let kind = if !self.same_mesh {
            "a stand-in"
        } else if self.scene == PaperScene::DragonBox {
            "the paper's scene as SimTRaX ships it, or our earlier reconstruction: the scene \
             table says which"
        } else {
            "the paper's mesh"
        };
        format!("{} ({}, {kind})", self.scene.label(), self.file)
    }
}

/// Where the report looked for the paper's meshes and what it found.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SceneFiles {
    /// The scenes folder, if one was found.
    pub dir: Option<String>,
    /// How it was found.
    pub source: Option<Source>,
    /// Every file of [`PAPER_FILES`], found or not.
    pub files: Vec<PaperFile>,
}

impl SceneFiles {
    /// Looks for every file of [`PAPER_FILES`] in `dir`.
    pub fn scan(dir: Option<&ScenesDir>) -> Self {
        let files = PAPER_FILES
            .iter()
            .map(|&(file, scene, same_mesh)| PaperFile {
                file: file.to_string(),
                scene,
                same_mesh,
                path: dir
                    .map(|d| d.path.join(file))
                    .filter(|p| p.is_file())
                    .map(|p| p.display().to_string()),
            })
            .collect();
        Self {
            dir: dir.map(|d| d.path.display().to_string()),
            source: dir.map(|d| d.source),
            files,
        }
    }

    /// The path of the shipped mesh standing for `scene`, if found.
    pub fn path_of(&self, scene: PaperScene) -> Option<&str> {
        self.files
            .iter()
            .find(|f| f.scene == scene)
            .and_then(|f| f.path.as_deref())
    }

    /// One paragraph: the folder and how it was found (or where the report looked), and
    /// which of the paper's meshes were found and which not.
    pub fn describe(&self) -> String {
        let list = |found: bool| {
            let v: Vec<String> = self
                .files
                .iter()
                .filter(|f| f.path.is_some() == found)
                .map(PaperFile::describe)
                .collect();
            if v.is_empty() {
                "none".to_string()
            } else {
                v.join(", ")
            }
        };
        match (&self.dir, self.source) {
            (Some(dir), Some(source)) => format!(
                "Scenes folder {dir} ({}). Paper meshes found: {}. Not found: {}.",
                source.describe(),
                list(true),
                list(false)
            ),
            _ => format!(
                "No scenes folder found (looked for --scenes DIR, then {ENV_VAR}, then shared/scenes beside the checkout), so these paper meshes are not available: {}.",
                list(false)
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `root/checkout/Cargo.toml`, `root/checkout/sub/`, `root/shared/scenes/dragon_box.ply.gz`.
    fn layout() -> (tempfile::TempDir, PathBuf, PathBuf) {
        let root = tempfile::tempdir().unwrap();
        let checkout = root.path().join("checkout");
        std::fs::create_dir_all(checkout.join("sub")).unwrap();
        std::fs::write(checkout.join("Cargo.toml"), "").unwrap();
        let scenes = root.path().join("shared/scenes");
        std::fs::create_dir_all(&scenes).unwrap();
        std::fs::write(scenes.join("dragon_box.ply.gz"), "").unwrap();
        (root, checkout, scenes)
    }

    #[test]
    fn the_flag_then_the_variable_then_beside_the_checkout() {
        let (root, checkout, scenes) = layout();
        let other = root.path().join("other");
        std::fs::create_dir_all(&other).unwrap();
        let cwd = checkout.join("sub");

        let d = find(Some(&other), Some(scenes.as_os_str()), &cwd, None)
            .unwrap()
            .unwrap();
        assert_eq!(
            (d.path.as_path(), d.source),
            (other.as_path(), Source::Flag)
        );
        let d = find(None, Some(other.as_os_str()), &cwd, None)
            .unwrap()
            .unwrap();
        assert_eq!((d.path.as_path(), d.source), (other.as_path(), Source::Env));
        let d = find(None, Some("".as_ref()), &cwd, None).unwrap().unwrap();
        assert_eq!(
            (d.path.as_path(), d.source),
            (scenes.as_path(), Source::BesideCheckout)
        );
        // Outside any checkout: beside the executable's checkout, else nothing.
        let exe = checkout.join("target/release/dualsplit");
        let d = find(None, None, &other, Some(&exe)).unwrap().unwrap();
        assert_eq!(d.source, Source::BesideExecutable);
        assert_eq!(
            find(None, None, &other, Some(&other.join("x"))).unwrap(),
            None
        );

        // A folder that is named must exist.
        let missing = root.path().join("missing");
        let e = find(Some(&missing), None, &cwd, None).unwrap_err();
        assert!(e.to_string().contains("--scenes"), "{e}");
        let e = find(None, Some(missing.as_os_str()), &cwd, None).unwrap_err();
        assert!(e.to_string().contains(ENV_VAR), "{e}");
    }

    #[test]
    fn found_and_missing_paper_meshes_are_listed() {
        let (_root, checkout, _scenes) = layout();
        let dir = find(None, None, &checkout, None).unwrap();
        let files = SceneFiles::scan(dir.as_ref());
        assert!(files.path_of(PaperScene::DragonBox).is_some());
        assert_eq!(files.path_of(PaperScene::DragonSponza), None);
        let text = files.describe();
        assert!(
            text.contains(
                "found: Dragon Box (dragon_box.ply.gz, the paper's scene as SimTRaX ships it, or our earlier reconstruction: the scene table says which). Not found: Dragon Sponza"
            ),
            "{text}"
        );
        assert_eq!(files.path_of(PaperScene::CrytekSponza), None);
        assert!(
            text.contains("Crytek Sponza (crytek_sponza.gltf, the paper's mesh)"),
            "{text}"
        );
        let none = SceneFiles::scan(None).describe();
        assert!(none.starts_with("No scenes folder found"), "{none}");
        assert!(
            none.contains("Dragon Box") && none.contains("Dragon Sponza"),
            "{none}"
        );
    }
}
