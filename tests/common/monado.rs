//! Running `incise xr` against Monado (scripts/monado.sh builds it from ../shared/monado):
//! headless, with the null compositor and the simulated HMD and controllers, through the
//! Khronos loader, the OpenXR core validation layer and the Vulkan validation layer on
//! (each where installed; both required under CI).
//!
//! Where the XR runtime is required (`INCISE_REQUIRE_XR=1`, or `CI` set with it unset;
//! crates/test-gate), a Monado that cannot be built or run fails the test; elsewhere the
//! test is skipped with the reason on stderr.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use incise_test_gate::{Need, required, skip_or_fail};
use serde_json::Value;

use super::text;

/// The OpenXR core validation layer's manifest (Debian `openxr-layer-corevalidation`).
const XR_VALIDATION: &str =
    "/usr/share/openxr/1/api_layers/explicit.d/XrApiLayer_core_validation.x86_64-linux-gnu.json";
/// The Vulkan validation layer's manifest (Debian `vulkan-validationlayers`).
const VK_VALIDATION: &str = "/usr/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json";

/// Monado's runtime manifest: `INCISE_MONADO_MANIFEST`, else what `scripts/monado.sh`
/// builds (or finds in its cache).
fn build() -> Result<PathBuf, String> {
    if let Some(m) = std::env::var_os("INCISE_MONADO_MANIFEST") {
        let m = PathBuf::from(m);
        return if m.is_file() {
            Ok(m)
        } else {
            Err(format!(
                "INCISE_MONADO_MANIFEST={} does not exist",
                m.display()
            ))
        };
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let o = Command::new("bash")
        .arg(root.join("scripts/monado.sh"))
        .current_dir(root)
        .stderr(Stdio::inherit())
        .output()
        .map_err(|e| format!("running scripts/monado.sh: {e}"))?;
    if !o.status.success() {
        return Err(format!("scripts/monado.sh failed ({})", o.status));
    }
    let manifest = PathBuf::from(text(&o.stdout).trim());
    if !manifest.is_file() {
        return Err(format!(
            "scripts/monado.sh printed {}, which is not a file",
            manifest.display()
        ));
    }
    Ok(manifest)
}

/// Monado's manifest, built once per test process; `None` (after saying why) when it
/// cannot be had and none is required; a panic when it is.
pub fn monado() -> Option<&'static Path> {
    static MONADO: OnceLock<Result<PathBuf, String>> = OnceLock::new();
    let found = MONADO.get_or_init(build).as_ref().map(PathBuf::as_path);
    found.map_err(|why| skip_or_fail(Need::Xr, why)).ok()
}

/// The OpenXR headers Monado bundles (its source tree beside the build in the cache).
pub fn openxr_includes(manifest: &Path) -> PathBuf {
    let cache = manifest
        .parent()
        .and_then(Path::parent)
        .expect("the manifest is in <cache>/build");
    cache.join("monado/src/external/openxr_includes")
}

/// Which validation layers a run switches on.
#[derive(Debug, Clone, Copy)]
pub struct Validation {
    /// The OpenXR core validation layer.
    pub xr: bool,
    /// The Vulkan validation layer.
    pub vulkan: bool,
}

/// The validation layers installed here; both must be where the XR runtime is required.
pub fn validation() -> Validation {
    let v = Validation {
        xr: Path::new(XR_VALIDATION).is_file(),
        vulkan: Path::new(VK_VALIDATION).is_file(),
    };
    if required(Need::Xr) {
        assert!(
            v.xr && v.vulkan,
            "CI runs the XR tests with both validation layers: {XR_VALIDATION} and {VK_VALIDATION} (scripts/monado.sh installs them)"
        );
    }
    if !v.xr || !v.vulkan {
        eprintln!("validation layers installed: {v:?} (scripts/monado.sh installs both)");
    }
    v
}

/// `incise xr ARGS` against Monado at `manifest`, its scratch (Monado's config folder,
/// the Vulkan layer's settings and log) in `scratch`, with `layers` on.
pub fn command(manifest: &Path, scratch: &Path, args: &[&str], layers: Validation) -> Command {
    std::fs::create_dir_all(scratch).unwrap();
    let mut c = super::incise_command(args);
    c.env("XR_RUNTIME_JSON", manifest)
        .env("XRT_COMPOSITOR_NULL", "1")
        .env("SIMULATED_ENABLE", "1")
        .env("SIMULATED_LEFT", "simple")
        .env("SIMULATED_RIGHT", "simple")
        .env("XRT_LOG", "error")
        .env("XDG_CONFIG_HOME", scratch.join("config"))
        // The loader says on stdout which API layers it loaded.
        .env("XR_LOADER_DEBUG", "info")
        .env_remove("XR_ENABLE_API_LAYERS")
        .env_remove("VK_INSTANCE_LAYERS");
    if layers.xr {
        c.env("XR_ENABLE_API_LAYERS", "XR_APILAYER_LUNARG_core_validation");
    }
    if layers.vulkan {
        let settings = format!(
            "khronos_validation.debug_action = VK_DBG_LAYER_ACTION_LOG_MSG\n\
             khronos_validation.log_filename = {}\n\
             khronos_validation.report_flags = error\n",
            scratch.join("vk_validation.log").display()
        );
        std::fs::write(scratch.join("vk_layer_settings.txt"), settings).unwrap();
        c.env("VK_INSTANCE_LAYERS", "VK_LAYER_KHRONOS_validation")
            .env("VK_LAYER_SETTINGS_PATH", scratch)
            // The Vulkan loader says on stderr which layers it inserted.
            .env("VK_LOADER_DEBUG", "layer");
    }
    c
}

/// The validation layers that were on were loaded and reported no error; panics naming
/// the first errors otherwise.
pub fn assert_validation_clean(o: &Output, scratch: &Path, layers: Validation) {
    let (stdout, stderr) = (text(&o.stdout), text(&o.stderr));
    if layers.xr {
        assert!(
            stdout.contains("succeeded loading layer XR_APILAYER_LUNARG_core_validation"),
            "the OpenXR core validation layer was not loaded:\n{stdout}"
        );
        // Core validation writes its findings to stdout, each with its severity
        // (VALID_ERROR, VALID_WARNING, …).
        let errors: Vec<&str> = stdout
            .lines()
            .filter(|l| l.contains("VALID_ERROR"))
            .take(5)
            .collect();
        assert!(
            errors.is_empty(),
            "OpenXR validation errors:\n{}",
            errors.join("\n")
        );
    }
    if layers.vulkan {
        assert!(
            stderr.contains("Insert instance layer \"VK_LAYER_KHRONOS_validation\""),
            "the Vulkan validation layer was not loaded"
        );
        let log = std::fs::read_to_string(scratch.join("vk_validation.log")).unwrap_or_default();
        let errors: Vec<&str> = log
            .lines()
            .filter(|l| l.contains("Validation Error"))
            .take(5)
            .collect();
        assert!(
            errors.is_empty(),
            "Vulkan validation errors:\n{}",
            errors.join("\n")
        );
    }
}

/// `command(…).output()`.
pub fn run(manifest: &Path, scratch: &Path, args: &[&str], layers: Validation) -> Output {
    command(manifest, scratch, args, layers)
        .output()
        .expect("incise runs")
}

/// The output folder's xr_report.json.
pub fn report(out: &Path, o: &Output) -> Value {
    let path = out.join("xr_report.json");
    let s = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("no {} ({e}); stderr:\n{}", path.display(), text(&o.stderr)));
    serde_json::from_str(&s).unwrap()
}

/// A spawned `incise xr` whose stderr is read line by line (to wait for a state).
pub struct Spawned {
    /// The process.
    pub child: Child,
    lines: std::sync::mpsc::Receiver<String>,
    /// Every stderr line read so far.
    pub stderr: Vec<String>,
}

impl Spawned {
    /// Spawn `c` with stderr piped.
    pub fn new(mut c: Command) -> Spawned {
        let mut child = c
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .expect("incise starts");
        let err = child.stderr.take().unwrap();
        let (tx, lines) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            use std::io::BufRead;
            for l in std::io::BufReader::new(err).lines().map_while(Result::ok) {
                if tx.send(l).is_err() {
                    break;
                }
            }
        });
        Spawned {
            child,
            lines,
            stderr: Vec::new(),
        }
    }

    /// Wait up to `timeout` for a stderr line containing `what`.
    pub fn wait_for(&mut self, what: &str, timeout: Duration) -> bool {
        let end = Instant::now() + timeout;
        while let Some(left) = end.checked_duration_since(Instant::now()) {
            match self.lines.recv_timeout(left) {
                Ok(l) => {
                    let hit = l.contains(what);
                    self.stderr.push(l);
                    if hit {
                        return true;
                    }
                }
                Err(_) => return false,
            }
        }
        false
    }

    /// Send SIGINT (Ctrl-C).
    pub fn interrupt(&self) {
        let ok = Command::new("kill")
            .args(["-INT", &self.child.id().to_string()])
            .status()
            .expect("kill runs")
            .success();
        assert!(ok, "kill -INT failed");
    }

    /// Wait up to `timeout` for the exit; its code (`None`: still running, then killed).
    pub fn exit_within(&mut self, timeout: Duration) -> Option<i32> {
        let end = Instant::now() + timeout;
        while Instant::now() < end {
            if let Some(s) = self.child.try_wait().unwrap() {
                self.drain();
                return s.code();
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        let _ = self.child.kill();
        let _ = self.child.wait();
        self.drain();
        None
    }

    fn drain(&mut self) {
        while let Ok(l) = self.lines.recv_timeout(Duration::from_millis(200)) {
            self.stderr.push(l);
        }
    }
}
