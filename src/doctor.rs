//! `incise doctor` (issue 34 item 5): what this machine offers the trainer, each item ok
//! or missing with the fix — the GPU adapters and which one `--device auto` picks and why,
//! the Vulkan loader, the OpenXR loader and active runtime, whether that runtime offers a
//! head-mounted display with Vulkan rendering (`XR_KHR_vulkan_enable2`), and a display for
//! the preview. The exit status is non-zero when the headset path cannot work.

use incise_xr::openxr::XrError;
use incise_xr::openxr::manifest::ActiveRuntime;
use incise_xr::openxr::runtime::open_runtime;

use crate::preview::display::missing_display;
use crate::sim_body::xpbd_device::auto_device;

/// One finding.
#[derive(Debug, Clone, PartialEq)]
pub struct Check {
    /// What was checked.
    pub item: &'static str,
    /// Whether it is there and usable.
    pub ok: bool,
    /// What was found.
    pub found: String,
    /// How to get it when it is missing (empty when ok).
    pub fix: String,
    /// Whether the headset path needs it (a missing one fails the command).
    pub headset_needs: bool,
}

impl Check {
    fn ok(item: &'static str, found: String, headset_needs: bool) -> Check {
        Check {
            item,
            ok: true,
            found,
            fix: String::new(),
            headset_needs,
        }
    }

    fn missing(item: &'static str, found: String, fix: &str, headset_needs: bool) -> Check {
        Check {
            item,
            ok: false,
            found,
            fix: fix.into(),
            headset_needs,
        }
    }
}

/// Every check, in the order printed.
pub fn checks() -> Vec<Check> {
    vec![gpu(), vulkan(), runtime_manifest(), headset(), display()]
}

/// The report's lines: `ok`/`missing`, the item, what was found and the fix.
pub fn report(checks: &[Check]) -> String {
    let mut out = String::new();
    for c in checks {
        let mark = if c.ok { "ok     " } else { "missing" };
        out += &format!("{mark}  {:<16} {}\n", c.item, c.found);
        if !c.ok {
            out += &format!("         {:<16} fix: {}\n", "", c.fix);
        }
    }
    out += if headset_ready(checks) {
        "the headset path can work here (incise xr)\n"
    } else {
        "the headset path cannot work here: see the fixes above and docs/quest3.md\n"
    };
    out
}

/// Whether the headset path can work with these findings.
pub fn headset_ready(checks: &[Check]) -> bool {
    checks.iter().all(|c| c.ok || !c.headset_needs)
}

fn gpu() -> Check {
    match incise_xr::RenderDevice::headless() {
        Ok(dev) => {
            let (_, why) = auto_device(&dev.info);
            Check::ok("GPU adapter", format!("{}; {why}", dev.describe()), true)
        }
        Err(e) => Check::missing(
            "GPU adapter",
            e.to_string(),
            "install a Vulkan driver: the GPU vendor's, or Mesa's software one \
             (`sudo apt install mesa-vulkan-drivers`, lavapipe)",
            true,
        ),
    }
}

fn vulkan() -> Check {
    match incise_xr::vulkan_instance::loader_version() {
        Some(v) => Check::ok("Vulkan loader", format!("instance version {v}"), true),
        None => Check::missing(
            "Vulkan loader",
            "no Vulkan loader (libvulkan.so.1 / vulkan-1.dll) could be loaded".into(),
            "`sudo apt install libvulkan1` (Linux); on Windows it comes with the GPU driver",
            true,
        ),
    }
}

fn headset() -> Check {
    const ITEM: &str = "OpenXR headset";
    match open_runtime() {
        Ok(rt) => Check::ok(
            ITEM,
            format!(
                "runtime {} offers a head-mounted display with Vulkan rendering (XR_KHR_vulkan_enable2)",
                rt.name
            ),
            true,
        ),
        Err(e) => {
            let fix = match &e {
                XrError::LoaderMissing(_) => {
                    "install the OpenXR loader: `sudo apt install libopenxr-loader1` (Linux); \
                     on Windows it comes with the runtime (Meta Quest Link)"
                }
                XrError::RuntimeUnavailable { .. } | XrError::CreateInstance { .. } => {
                    "start an OpenXR runtime and make it the active one: Meta Quest Link \
                     (Windows), WiVRn or Monado (Linux); XR_RUNTIME_JSON names a manifest"
                }
                XrError::NoVulkan { .. } => {
                    "use a runtime with Vulkan rendering (XR_KHR_vulkan_enable2): Meta Quest \
                     Link, WiVRn or Monado"
                }
                XrError::NoHeadset { .. } => {
                    "connect the headset and start Link (or the runtime's headset \
                     connection) before running incise xr"
                }
                _ => "see docs/quest3.md, troubleshooting",
            };
            Check::missing(ITEM, e.to_string(), fix, true)
        }
    }
}

fn runtime_manifest() -> Check {
    let active = ActiveRuntime::find();
    if cfg!(windows) && active.path().is_none() {
        // The loader reads the active runtime from the registry there
        // (HKLM\SOFTWARE\Khronos\OpenXR\1\ActiveRuntime); the headset check opens it.
        return Check::ok(
            "runtime manifest",
            "registered in the Windows registry (the OpenXR headset line says whether it loads)"
                .into(),
            false,
        );
    }
    match active.path() {
        Some(p) if p.exists() => Check::ok("runtime manifest", active.describe(), false),
        _ => Check::missing(
            "runtime manifest",
            active.describe(),
            "register the runtime (its installer does; or export XR_RUNTIME_JSON=PATH to \
             its manifest, e.g. scripts/monado.sh prints Monado's)",
            false,
        ),
    }
}

fn display() -> Check {
    match missing_display() {
        None => Check::ok("preview display", "a display is set".into(), false),
        Some(why) => Check::missing(
            "preview display",
            why.into(),
            "run on a desktop session, or `xvfb-run incise preview` (headless: `incise run`)",
            false,
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_item_the_headset_needs_fails_the_report() {
        let ok = Check::ok("a", "x".into(), true);
        let no_display = Check::missing("display", "none".into(), "fix it", false);
        assert!(headset_ready(&[ok.clone(), no_display.clone()]));
        let no_runtime = Check::missing("runtime", "none".into(), "start one", true);
        let checks = [ok, no_display, no_runtime];
        assert!(!headset_ready(&checks));
        let text = report(&checks);
        assert!(text.contains("missing  runtime"), "{text}");
        assert!(text.contains("fix: start one"), "{text}");
        assert!(text.contains("cannot work here"), "{text}");
    }
}
