//! The one-paragraph message of `incise xr` when no OpenXR runtime or headset can be
//! used here (exit code 2): what was found, what is missing, how to start Quest Link,
//! and the desktop preview as the way to go on.

use std::path::Path;

use incise_xr::openxr::XrError;
use incise_xr::openxr::manifest::ActiveRuntime;

/// `incise xr` could not find a usable runtime or headset; main exits 2 with this text.
#[derive(Debug)]
pub struct XrUnavailable(pub String);

impl std::fmt::Display for XrUnavailable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for XrUnavailable {}

/// The message for `error` (one for which `is_unavailable` holds) and `scene`.
pub fn message(error: &XrError, scene: &Path) -> String {
    let found = match error {
        XrError::LoaderMissing(detail) => format!(
            "the OpenXR loader library (libopenxr_loader.so.1 on Linux, openxr_loader.dll on Windows) is not installed, so no runtime could be looked for ({detail}); on Debian or Ubuntu install it with `sudo apt install libopenxr-loader1`, on Windows it comes with the runtime"
        ),
        XrError::RuntimeUnavailable { detail, manifest } => match manifest {
            ActiveRuntime::None => format!(
                "the OpenXR loader is installed but no active OpenXR runtime is registered ({detail})"
            ),
            ActiveRuntime::Env {
                path,
                exists: false,
            } => format!(
                "XR_RUNTIME_JSON names the runtime manifest {}, which does not exist ({detail})",
                path.display()
            ),
            found => format!(
                "the runtime manifest {} was found but the OpenXR loader could not load the runtime it names ({detail}; the loader's message above says why)",
                found.describe()
            ),
        },
        XrError::NoVulkan { runtime } => format!(
            "the active OpenXR runtime is {runtime}, but it cannot render with Vulkan (it lacks XR_KHR_vulkan_enable2, which incise needs)"
        ),
        XrError::NoHeadset { runtime, detail } => format!(
            "the active OpenXR runtime is {runtime}, but it reports no headset ({detail}); is the Quest on, connected and in Link?"
        ),
        other => other.to_string(),
    };
    format!(
        "incise xr needs an OpenXR runtime with a headset and cannot start: {found}. \
         On Windows, install the Meta Quest Link app, connect the Quest 3 by USB-C cable \
         (or Air Link), make Meta Quest Link the active runtime (Meta Quest Link app → \
         Settings → General → OpenXR Runtime → Set Meta Quest Link as active), start Link \
         from the headset's quick settings and run `incise xr` again; on Linux, start \
         WiVRn (or Monado) and connect the headset first. Step by step: docs/quest3.md. \
         Without a headset, `incise preview {}` opens the same scene on the desktop.",
        scene.display()
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_missing_piece_is_named_with_the_way_forward() {
        let scene = Path::new("config/plate_cut.ron");
        let cases = [
            (
                XrError::LoaderMissing(
                    "libopenxr_loader.so.1: cannot open shared object file".into(),
                ),
                "loader library",
            ),
            (
                XrError::RuntimeUnavailable {
                    detail: "XR_ERROR_RUNTIME_UNAVAILABLE".into(),
                    manifest: ActiveRuntime::None,
                },
                "no active OpenXR runtime",
            ),
            (
                XrError::RuntimeUnavailable {
                    detail: "XR_ERROR_RUNTIME_UNAVAILABLE".into(),
                    manifest: ActiveRuntime::Env {
                        path: "/opt/monado.json".into(),
                        exists: false,
                    },
                },
                "XR_RUNTIME_JSON names the runtime manifest /opt/monado.json, which does not exist",
            ),
            (
                XrError::RuntimeUnavailable {
                    detail: "XR_ERROR_RUNTIME_UNAVAILABLE".into(),
                    manifest: ActiveRuntime::Registered(
                        "/etc/xdg/openxr/1/active_runtime.json".into(),
                    ),
                },
                "manifest /etc/xdg/openxr/1/active_runtime.json was found but the OpenXR loader could not load",
            ),
            (
                XrError::NoVulkan {
                    runtime: "Monado 21.0".into(),
                },
                "Monado 21.0",
            ),
            (
                XrError::NoHeadset {
                    runtime: "Oculus 1.95".into(),
                    detail: "XR_ERROR_FORM_FACTOR_UNAVAILABLE".into(),
                },
                "reports no headset",
            ),
        ];
        for (e, what) in cases {
            assert!(e.is_unavailable());
            let m = message(&e, scene);
            assert!(m.contains(what), "{m}");
            assert!(m.contains("Meta Quest Link") && m.contains("WiVRn"), "{m}");
            assert!(m.contains("incise preview config/plate_cut.ron"), "{m}");
            assert!(!m.contains('\n'), "one paragraph: {m}");
        }
    }
}
