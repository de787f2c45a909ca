//! Why the XR mode could not start or went down.

use super::lifecycle::{ExitReason, FrameOrderError};
use super::manifest::ActiveRuntime;
use crate::error::RenderError;

/// An XR failure. The first four mean "no usable OpenXR runtime here" (the app exits 2
/// with advice); the rest are failures of a runtime that was found.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum XrError {
    /// The OpenXR loader library could not be opened.
    #[error("the OpenXR loader (libopenxr_loader) could not be opened: {0}")]
    LoaderMissing(String),
    /// The loader found no active runtime, or could not load the one the manifest names.
    #[error("the OpenXR loader found no usable runtime ({detail}; {})", manifest.describe())]
    RuntimeUnavailable {
        /// The loader's answer.
        detail: String,
        /// The manifest the loader read, if any.
        manifest: ActiveRuntime,
    },
    /// `xrCreateInstance` failed on a runtime the loader found and loaded.
    #[error("{}", create_instance_text(*result, manifest))]
    CreateInstance {
        /// The runtime's result code.
        result: ::openxr::sys::Result,
        /// The manifest of the runtime that failed.
        manifest: ActiveRuntime,
    },
    /// The runtime cannot render with Vulkan (`XR_KHR_vulkan_enable2` missing).
    #[error("the OpenXR runtime {runtime} does not offer XR_KHR_vulkan_enable2 (Vulkan rendering)")]
    NoVulkan {
        /// Runtime name and version.
        runtime: String,
    },
    /// The runtime has no headset connected.
    #[error("the OpenXR runtime {runtime} reports no headset ({detail})")]
    NoHeadset {
        /// Runtime name and version.
        runtime: String,
        /// The runtime's answer.
        detail: String,
    },
    /// An OpenXR call failed.
    #[error("{call} failed: {result} ({result:?})")]
    Xr {
        /// The call.
        call: &'static str,
        /// The runtime's result code.
        result: ::openxr::sys::Result,
    },
    /// A Vulkan call made through the runtime failed.
    #[error("{call} failed: Vulkan error {code}")]
    Vulkan {
        /// The call.
        call: &'static str,
        /// `VkResult`.
        code: i32,
    },
    /// Opening wgpu on the runtime's Vulkan device failed.
    #[error("wrapping the runtime's Vulkan device into wgpu failed: {0}")]
    Gpu(String),
    /// Rendering failed.
    #[error(transparent)]
    Render(#[from] RenderError),
    /// The frame loop called the runtime out of order.
    #[error(transparent)]
    FrameOrder(#[from] FrameOrderError),
}

impl XrError {
    /// Whether this means no usable runtime or headset (as opposed to a failure of one).
    pub fn is_unavailable(&self) -> bool {
        matches!(
            self,
            XrError::LoaderMissing(_)
                | XrError::RuntimeUnavailable { .. }
                | XrError::NoVulkan { .. }
                | XrError::NoHeadset { .. }
        )
    }

    /// `call` failed with `XR_ERROR_SESSION_LOST`.
    pub fn session_lost(call: &'static str) -> XrError {
        XrError::Xr {
            call,
            result: ::openxr::sys::Result::ERROR_SESSION_LOST,
        }
    }

    /// `call` failed with `XR_ERROR_RUNTIME_FAILURE`.
    pub fn runtime_failure(call: &'static str) -> XrError {
        XrError::Xr {
            call,
            result: ::openxr::sys::Result::ERROR_RUNTIME_FAILURE,
        }
    }

    /// The session's end this error means, when a call failed because the runtime lost
    /// the session (`XR_ERROR_SESSION_LOST`) or is going away (`XR_ERROR_INSTANCE_LOST`):
    /// the app then shuts down as on a LOSS_PENDING event instead of failing.
    pub fn lost(&self) -> Option<ExitReason> {
        match self {
            XrError::Xr { result, .. } if *result == ::openxr::sys::Result::ERROR_SESSION_LOST => {
                Some(ExitReason::SessionLost)
            }
            XrError::Xr { result, .. } if *result == ::openxr::sys::Result::ERROR_INSTANCE_LOST => {
                Some(ExitReason::InstanceLost)
            }
            _ => None,
        }
    }
}

/// What an `xrCreateInstance` failure of a found runtime means and what to do about it.
fn create_instance_text(result: ::openxr::sys::Result, manifest: &ActiveRuntime) -> String {
    use ::openxr::sys::Result as R;
    let why = match result {
        R::ERROR_RUNTIME_FAILURE => {
            "the runtime failed inside xrCreateInstance; its own log (above) says why. \
             Restart the runtime (Meta Quest Link, WiVRn, monado-service) and try again"
        }
        R::ERROR_INITIALIZATION_FAILED => {
            "the runtime could not initialise: its service may not be running or it found \
             no headset or GPU. Start the runtime (Meta Quest Link, WiVRn, monado-service), \
             connect the headset and try again"
        }
        R::ERROR_INSTANCE_LOST => {
            "the runtime is shutting down or restarting. Wait until it is running again and \
             try again"
        }
        R::ERROR_OUT_OF_MEMORY => {
            "the runtime ran out of memory. Close other VR applications and try again"
        }
        R::ERROR_API_VERSION_UNSUPPORTED => {
            "the runtime does not support OpenXR 1.0, which incise asks for. Update the runtime"
        }
        _ => "the runtime refused the instance incise asks for (XR_KHR_vulkan_enable2)",
    };
    format!(
        "the OpenXR runtime ({}) was found, but creating an instance on it failed with XR_{result:?} ({result}): {why}",
        manifest.describe()
    )
}

/// `map_err` helper: name the OpenXR call that failed.
pub(crate) fn xr_call(call: &'static str) -> impl Fn(::openxr::sys::Result) -> XrError {
    move |result| XrError::Xr { call, result }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lost_session_and_instance_errors_end_the_session_others_do_not() {
        let err = |result| XrError::Xr {
            call: "xrWaitFrame",
            result,
        };
        assert_eq!(
            err(::openxr::sys::Result::ERROR_SESSION_LOST).lost(),
            Some(ExitReason::SessionLost)
        );
        assert_eq!(
            err(::openxr::sys::Result::ERROR_INSTANCE_LOST).lost(),
            Some(ExitReason::InstanceLost)
        );
        assert_eq!(
            err(::openxr::sys::Result::ERROR_RUNTIME_FAILURE).lost(),
            None
        );
        assert_eq!(XrError::Gpu("x".into()).lost(), None);
    }

    #[test]
    fn each_create_instance_failure_says_the_runtime_was_found_and_what_to_do() {
        use ::openxr::sys::Result as R;
        let manifest = ActiveRuntime::Env {
            path: "/tmp/monado.json".into(),
            exists: true,
        };
        let cases = [
            (R::ERROR_RUNTIME_FAILURE, "failed inside xrCreateInstance"),
            (R::ERROR_INITIALIZATION_FAILED, "could not initialise"),
            (R::ERROR_INSTANCE_LOST, "shutting down or restarting"),
            (R::ERROR_OUT_OF_MEMORY, "ran out of memory"),
        ];
        for (result, what) in cases {
            let e = XrError::CreateInstance {
                result,
                manifest: manifest.clone(),
            };
            assert!(!e.is_unavailable());
            let m = e.to_string();
            assert!(m.contains(what), "{m}");
            assert!(m.contains("XR_RUNTIME_JSON=/tmp/monado.json") && m.contains("was found"));
            assert!(m.contains(&format!("{result:?}")), "{m}");
            assert!(!m.contains("registered"), "{m}");
        }
    }
}
