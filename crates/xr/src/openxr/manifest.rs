//! Which runtime manifest the OpenXR loader reads on Linux (the loader's own search order:
//! `XR_RUNTIME_JSON`, then `openxr/1/active_runtime.json` under `$XDG_CONFIG_HOME`
//! (`~/.config`), each of `$XDG_CONFIG_DIRS` (`/etc/xdg`), and `/etc`), so a failure to
//! start can say whether a runtime was registered at all and where.

use std::path::{Path, PathBuf};

/// The manifest naming the active runtime, as the loader looks for it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ActiveRuntime {
    /// `XR_RUNTIME_JSON` names this file (which may not exist).
    Env {
        /// The file named.
        path: PathBuf,
        /// Whether it exists.
        exists: bool,
    },
    /// The first `active_runtime.json` found in the loader's folders.
    Registered(PathBuf),
    /// No manifest anywhere the loader looks.
    None,
}

/// The file under `openxr/1/` the loader reads in each configuration folder.
const ACTIVE_RUNTIME: &str = "openxr/1/active_runtime.json";

impl ActiveRuntime {
    /// Look the manifest up from the process environment.
    pub fn find() -> ActiveRuntime {
        let var = |k: &str| std::env::var_os(k).filter(|v| !v.is_empty());
        Self::find_with(
            var("XR_RUNTIME_JSON").map(PathBuf::from),
            var("XDG_CONFIG_HOME").map(PathBuf::from),
            var("HOME").map(PathBuf::from),
            var("XDG_CONFIG_DIRS").map(|v| v.to_string_lossy().into_owned()),
        )
    }

    /// Look the manifest up from these environment values.
    pub fn find_with(
        runtime_json: Option<PathBuf>,
        config_home: Option<PathBuf>,
        home: Option<PathBuf>,
        config_dirs: Option<String>,
    ) -> ActiveRuntime {
        if let Some(path) = runtime_json {
            let exists = path.is_file();
            return ActiveRuntime::Env { path, exists };
        }
        let home_dir = config_home.or_else(|| home.map(|h| h.join(".config")));
        let dirs = config_dirs.unwrap_or_else(|| "/etc/xdg".into());
        home_dir
            .into_iter()
            .chain(dirs.split(':').filter(|d| !d.is_empty()).map(PathBuf::from))
            .chain([PathBuf::from("/etc")])
            .map(|d| d.join(ACTIVE_RUNTIME))
            .find(|p| p.is_file())
            .map_or(ActiveRuntime::None, ActiveRuntime::Registered)
    }

    /// The manifest file, when there is one.
    pub fn path(&self) -> Option<&Path> {
        match self {
            ActiveRuntime::Env { path, exists: true } | ActiveRuntime::Registered(path) => {
                Some(path)
            }
            _ => None,
        }
    }

    /// How the manifest was chosen, for messages ("XR_RUNTIME_JSON=…", the file, or
    /// "no runtime manifest").
    pub fn describe(&self) -> String {
        match self {
            ActiveRuntime::Env { path, .. } => format!("XR_RUNTIME_JSON={}", path.display()),
            ActiveRuntime::Registered(path) => path.display().to_string(),
            ActiveRuntime::None => "no runtime manifest".into(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_environment_variable_wins_then_the_first_existing_active_runtime_file() {
        let dir = std::env::temp_dir().join(format!("incise-manifest-{}", std::process::id()));
        let (home, etc) = (dir.join("home"), dir.join("etc"));
        std::fs::create_dir_all(etc.join("openxr/1")).unwrap();
        std::fs::create_dir_all(&home).unwrap();
        let registered = etc.join(ACTIVE_RUNTIME);
        std::fs::write(&registered, "{}").unwrap();
        let dirs = Some(etc.display().to_string());

        let missing = dir.join("nowhere.json");
        let env = ActiveRuntime::find_with(Some(missing.clone()), None, None, dirs.clone());
        assert_eq!(
            env,
            ActiveRuntime::Env {
                path: missing,
                exists: false
            }
        );
        assert_eq!(env.path(), None);
        assert!(env.describe().starts_with("XR_RUNTIME_JSON="));

        let found = ActiveRuntime::find_with(None, Some(home.clone()), None, dirs);
        assert_eq!(found, ActiveRuntime::Registered(registered.clone()));
        assert_eq!(found.path(), Some(registered.as_path()));

        // The user's own file comes first.
        std::fs::create_dir_all(home.join("openxr/1")).unwrap();
        std::fs::write(home.join(ACTIVE_RUNTIME), "{}").unwrap();
        let mine = ActiveRuntime::find_with(None, Some(home.clone()), None, None);
        assert_eq!(mine, ActiveRuntime::Registered(home.join(ACTIVE_RUNTIME)));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
