//! The haptic-rate loop (PHYSICS.md §2.6: 1000 Hz haptic, 100 Hz visual): the localised
//! mass-spring simulation runs on its own thread at a fixed rate, couples the tool to the
//! node nearest it with a virtual spring, and publishes the tool force every loop and a
//! position snapshot for rendering at a lower rate.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use glam::DVec3;

use super::{LocalLoop, LocalLoopParams, MassSpringModel, SystemClock};

/// Settings of the haptic loop.
#[derive(Debug, Clone, PartialEq)]
pub struct HapticConfig {
    /// Loop rate, Hz (1000 for a haptic device).
    pub rate_hz: f64,
    /// Rate of the position snapshots for rendering, Hz (60–100).
    pub publish_hz: f64,
    /// Localisation of each loop.
    pub local: LocalLoopParams,
    /// Stiffness of the virtual spring between the tool tip and the nearest node, N/m.
    pub coupling: f64,
    /// The tool touches the tissue when its tip is within this distance of a node, m.
    pub contact_radius: f64,
}

impl Default for HapticConfig {
    fn default() -> Self {
        HapticConfig {
            rate_hz: 1000.0,
            publish_hz: 100.0,
            local: LocalLoopParams::default(),
            coupling: 50.0,
            contact_radius: 0.005,
        }
    }
}

/// What the haptic thread last published.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct HapticFrame {
    /// Force on the tool (the reaction of the tissue), N.
    pub tool_force: DVec3,
    /// Loops run so far.
    pub loops: u64,
    /// Loops that overran their period.
    pub overruns: u64,
    /// Simulated time, s.
    pub sim_time: f64,
    /// Free nodes in the last loop.
    pub free_nodes: usize,
    /// Node positions at the last snapshot (rendering rate), m.
    pub positions: Vec<DVec3>,
    /// Snapshots published so far.
    pub snapshots: u64,
}

struct Shared {
    tool: Mutex<Option<DVec3>>,
    frame: Mutex<HapticFrame>,
    stop: AtomicBool,
}

/// The running haptic thread; [`HapticLoop::stop`] returns the model.
pub struct HapticLoop {
    shared: Arc<Shared>,
    handle: JoinHandle<MassSpringModel>,
}

impl HapticLoop {
    /// Start the loop on its own thread, owning `model`.
    pub fn spawn(model: MassSpringModel, config: HapticConfig) -> HapticLoop {
        let shared = Arc::new(Shared {
            tool: Mutex::new(None),
            frame: Mutex::new(HapticFrame::default()),
            stop: AtomicBool::new(false),
        });
        let s = Arc::clone(&shared);
        let handle = std::thread::spawn(move || run(model, config, &s));
        HapticLoop { shared, handle }
    }

    /// Move the tool tip (`None`: tool lifted).
    pub fn set_tool(&self, tip: Option<DVec3>) {
        if let Ok(mut t) = self.shared.tool.lock() {
            *t = tip;
        }
    }

    /// A copy of the latest published frame.
    pub fn latest(&self) -> HapticFrame {
        self.shared
            .frame
            .lock()
            .map(|f| f.clone())
            .unwrap_or_default()
    }

    /// Stop the thread and return the model.
    pub fn stop(self) -> std::thread::Result<MassSpringModel> {
        self.shared.stop.store(true, Ordering::Release);
        self.handle.join()
    }
}

fn run(mut model: MassSpringModel, config: HapticConfig, shared: &Shared) -> MassSpringModel {
    let period = Duration::from_secs_f64(1.0 / config.rate_hz.max(1.0));
    let publish_every = (config.rate_hz / config.publish_hz.max(1e-3))
        .round()
        .max(1.0) as u64;
    let mut local = LocalLoop::new(config.local.clone(), SystemClock::default());
    let mut next = Instant::now() + period;
    let (mut loops, mut overruns, mut snapshots) = (0u64, 0u64, 0u64);
    while !shared.stop.load(Ordering::Acquire) {
        let tip = shared.tool.lock().ok().and_then(|t| *t);
        let h = period.as_secs_f64();
        let substeps = (h / model.stable_dt()).ceil().max(1.0) as u32;
        let dt = h / substeps as f64;
        let mut force = DVec3::ZERO;
        let mut free = 0;
        match tip {
            Some(tip) => {
                let node = local.hierarchy().nearest_node(&model, tip);
                let touching = node.filter(|&n| {
                    (model.positions()[n as usize] - tip).length() <= config.contact_radius
                });
                for _ in 0..substeps {
                    if let Some(n) = touching {
                        let f = config.coupling * (tip - model.positions()[n as usize]);
                        model.set_external_force(n, f);
                        force = -f;
                    }
                    free = local.step(&mut model, tip, dt).free_nodes;
                }
                model.clear_external_forces();
            }
            None => {
                for _ in 0..substeps {
                    model.step(dt);
                }
                free = model.node_count();
            }
        }
        loops += 1;
        let publish = loops % publish_every == 0;
        if let Ok(mut f) = shared.frame.lock() {
            f.tool_force = force;
            f.loops = loops;
            f.overruns = overruns;
            f.sim_time = model.time();
            f.free_nodes = free;
            if publish {
                snapshots += 1;
                f.positions.clear();
                f.positions.extend_from_slice(model.positions());
                f.snapshots = snapshots;
            }
        }
        let now = Instant::now();
        if now < next {
            std::thread::sleep(next - now);
            next += period;
        } else {
            overruns += 1;
            next = now + period;
        }
    }
    model
}

#[cfg(test)]
mod tests {
    use glam::{UVec3, Vec3};

    use super::*;
    use crate::generate::block;
    use crate::mass_spring::{AxisMask, MassSpringParams};
    use crate::mesh::TetMesh;

    #[test]
    fn haptic_thread_runs_publishes_and_pushes_back() {
        let (mesh, _) = TetMesh::from_raw(block(
            Vec3::ZERO,
            Vec3::new(0.04, 0.04, 0.01),
            UVec3::new(4, 4, 1),
        ))
        .unwrap();
        let mut m = MassSpringModel::new(
            &mesh,
            MassSpringParams {
                gravity: DVec3::ZERO,
                ..MassSpringParams::default()
            },
        )
        .unwrap();
        let rim: Vec<u32> = (0..m.node_count() as u32)
            .filter(|&i| {
                let p = m.positions()[i as usize];
                p.x < 1e-6 || p.x > 0.04 - 1e-6
            })
            .collect();
        m.fix(&rim, AxisMask::ALL).unwrap();
        let haptic = HapticLoop::spawn(m, HapticConfig::default());
        // Press the middle of the top surface 2 mm down.
        haptic.set_tool(Some(DVec3::new(0.02, 0.02, 0.008)));
        std::thread::sleep(Duration::from_millis(300));
        let frame = haptic.latest();
        let model = haptic.stop().unwrap();
        // Loose bounds: the machine may be busy; a 1 kHz loop runs ≈ 300 loops here.
        assert!(frame.loops >= 30, "{} loops", frame.loops);
        assert!(frame.snapshots >= 1 && frame.positions.len() == model.node_count());
        // The tissue pushes the tool back up.
        assert!(frame.tool_force.z > 0.0, "{}", frame.tool_force);
        assert!((model.time() - frame.sim_time).abs() < 0.1);
        assert!(frame.sim_time > 0.0);
    }
}
