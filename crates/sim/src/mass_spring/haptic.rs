//! The haptic-rate loop (PHYSICS.md §2.6: 1000 Hz haptic, 100 Hz visual): the localised
//! mass-spring simulation runs on its own thread at a fixed rate, couples the tool to the
//! node nearest it with a virtual spring, and publishes the tool force every loop and a
//! position snapshot for rendering at a lower rate. A blade pose handed to it is cut in
//! the same thread (PHYSICS.md §2.3–2.4), before the loop's integration, whenever it moves.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use glam::DVec3;

use super::tool_coupling::{HapticContact, ToolCoupling};
use super::{LocalLoop, LocalLoopParams, MassSpringModel, SystemClock};
use crate::nakao_cut::{BladePose, CutParams, Cutter};

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
    /// The tool touches the tissue when its tip is within this distance of a node, m
    /// ([`HapticContact::NearestNode`] only).
    pub contact_radius: f64,
    /// How the tool point is coupled to the tissue.
    pub contact: HapticContact,
    /// Settings of the cutter that cuts along the blade poses (see [`HapticLoop::set_blade`]).
    pub cut: CutParams,
}

impl HapticConfig {
    /// The tool's coupling these settings make: their contact, spring stiffness and
    /// contact radius.
    pub fn tool_coupling(&self) -> ToolCoupling {
        ToolCoupling::new(self.contact, self.coupling, self.contact_radius)
    }
}

impl Default for HapticConfig {
    fn default() -> Self {
        HapticConfig {
            rate_hz: 1000.0,
            publish_hz: 100.0,
            local: LocalLoopParams::default(),
            coupling: 50.0,
            contact_radius: 0.005,
            contact: HapticContact::default(),
            cut: CutParams::default(),
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
    /// Blade advances cut so far (each one a swept region between two poses).
    pub cut_advances: u64,
    /// Node count at the last snapshot (grows as the blade cuts).
    pub nodes: usize,
    /// Tet count at the last snapshot.
    pub tets: usize,
    /// Current tet volume over reference volume at the last snapshot.
    pub volume_ratio: f64,
    /// Kinetic energy at the last snapshot, J.
    pub kinetic_energy: f64,
    /// Largest node displacement from the reference position at the last snapshot, m.
    pub max_displacement: f64,
}

struct Shared {
    tool: Mutex<Option<DVec3>>,
    blade: Mutex<Option<BladePose>>,
    frame: Mutex<HapticFrame>,
    stop: AtomicBool,
}

/// The running haptic thread; [`HapticLoop::stop`] returns the model (dropping the loop
/// stops the thread too).
pub struct HapticLoop {
    shared: Arc<Shared>,
    handle: Option<JoinHandle<MassSpringModel>>,
}

impl HapticLoop {
    /// Start the loop on its own thread, owning `model`.
    pub fn spawn(model: MassSpringModel, config: HapticConfig) -> HapticLoop {
        let shared = Arc::new(Shared {
            tool: Mutex::new(None),
            blade: Mutex::new(None),
            frame: Mutex::new(HapticFrame::default()),
            stop: AtomicBool::new(false),
        });
        let s = Arc::clone(&shared);
        let handle = Some(std::thread::spawn(move || run(model, config, &s)));
        HapticLoop { shared, handle }
    }

    /// Move the tool tip (`None`: tool lifted).
    pub fn set_tool(&self, tip: Option<DVec3>) {
        if let Ok(mut t) = self.shared.tool.lock() {
            *t = tip;
        }
    }

    /// Move the blade's cutting edge (`None`: blade lifted, the stroke ends). The haptic
    /// thread cuts what the edge swept since the pose it last saw; the first pose after a
    /// lift only places the blade.
    pub fn set_blade(&self, pose: Option<BladePose>) {
        if let Ok(mut b) = self.shared.blade.lock() {
            *b = pose;
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
    pub fn stop(mut self) -> std::thread::Result<MassSpringModel> {
        self.shared.stop.store(true, Ordering::Release);
        match self.handle.take() {
            Some(h) => h.join(),
            None => Err(Box::new("the haptic thread was already joined")),
        }
    }
}

impl Drop for HapticLoop {
    /// A loop dropped without [`HapticLoop::stop`] (its body dropped mid-run) stops its
    /// thread rather than leave it spinning at the haptic rate.
    fn drop(&mut self) {
        self.shared.stop.store(true, Ordering::Release);
        if let Some(h) = self.handle.take() {
            let _ = h.join();
        }
    }
}

fn run(mut model: MassSpringModel, config: HapticConfig, shared: &Shared) -> MassSpringModel {
    let period = Duration::from_secs_f64(1.0 / config.rate_hz.max(1.0));
    let publish_every = (config.rate_hz / config.publish_hz.max(1e-3))
        .round()
        .max(1.0) as u64;
    let mut local = LocalLoop::new(config.local.clone(), SystemClock::default());
    let mut cutter = Cutter::new(config.cut.clone());
    let mut blade_seen: Option<BladePose> = None;
    let mut couple = config.tool_coupling();
    let mut next = Instant::now() + period;
    let (mut loops, mut overruns, mut snapshots, mut cuts) = (0u64, 0u64, 0u64, 0u64);
    while !shared.stop.load(Ordering::Acquire) {
        let tip = shared.tool.lock().ok().and_then(|t| *t);
        let blade = shared.blade.lock().ok().and_then(|b| *b);
        match (blade, blade_seen) {
            (Some(pose), Some(seen)) if pose == seen => {}
            (Some(pose), seen) => {
                // The first pose of a stroke only places the blade.
                cutter.advance(&mut model, pose);
                cuts += u64::from(seen.is_some());
            }
            (None, Some(_)) => cutter.end(),
            (None, None) => {}
        }
        blade_seen = blade;
        let h = period.as_secs_f64();
        let substeps = (h / model.stable_dt()).ceil().max(1.0) as u32;
        let dt = h / substeps as f64;
        let (force, free) = match tip {
            Some(tip) => couple.haptic_loop(&mut model, &mut local, tip, substeps, dt),
            None => {
                for _ in 0..substeps {
                    model.step(dt);
                }
                (DVec3::ZERO, model.node_count())
            }
        };
        loops += 1;
        let publish = loops % publish_every == 0;
        if let Ok(mut f) = shared.frame.lock() {
            f.tool_force = force;
            f.loops = loops;
            f.overruns = overruns;
            f.sim_time = model.time();
            f.free_nodes = free;
            f.cut_advances = cuts;
            if publish {
                snapshots += 1;
                f.positions.clear();
                f.positions.extend_from_slice(model.positions());
                f.snapshots = snapshots;
                f.nodes = model.node_count();
                f.tets = model.tet_count();
                let (mut now, mut reference) = (0.0, 0.0);
                for t in 0..model.tet_count() {
                    now += model.current_volume(t);
                    reference += model.reference_volume(t);
                }
                f.volume_ratio = now / reference;
                f.kinetic_energy = model.kinetic_energy();
                f.max_displacement = model
                    .positions()
                    .iter()
                    .zip(model.reference_positions())
                    .map(|(p, r)| (*p - *r).length())
                    .fold(0.0, f64::max);
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

    /// A 4 × 4 × 1 cm slab without gravity, held at its two x ends.
    fn held_slab() -> MassSpringModel {
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
        m
    }

    /// A loop dropped without `stop` (its body dropped mid-run) stops and joins its thread:
    /// nothing holds the shared state afterwards.
    #[test]
    fn a_dropped_loop_stops_its_thread() {
        let h = HapticLoop::spawn(held_slab(), HapticConfig::default());
        let shared = Arc::downgrade(&h.shared);
        std::thread::sleep(Duration::from_millis(5));
        drop(h);
        assert_eq!(shared.strong_count(), 0, "the haptic thread still runs");
    }

    /// The tool's path in 1 kHz loops, run through [`ToolCoupling::haptic_loop`] without a thread:
    /// the force on the tool each loop.
    fn drive(m: &mut MassSpringModel, contact: HapticContact, path: &[DVec3]) -> Vec<DVec3> {
        let config = HapticConfig {
            contact,
            ..HapticConfig::default()
        };
        let mut couple = config.tool_coupling();
        let mut local = LocalLoop::new(config.local.clone(), SystemClock::default());
        let h = 1.0 / config.rate_hz;
        let substeps = (h / m.stable_dt()).ceil().max(1.0) as u32;
        path.iter()
            .map(|&tip| {
                couple
                    .haptic_loop(m, &mut local, tip, substeps, h / substeps as f64)
                    .0
            })
            .collect()
    }

    /// The device at the slab's centre (x, y = 2.1, 1.9 cm) and height `z`, cm.
    fn over_centre(z: f64) -> DVec3 {
        DVec3::new(0.021, 0.019, z * 0.01)
    }

    /// A probe lowered into the slab, on through it and below it, held, and lifted: the god
    /// object pushes the tool back up all the way (the proxy stays on the top face, so even
    /// below the slab the force points up) and never pulls; the nearest-node coupling pulls
    /// the tool down as it is lifted off, and lets go once the tool is below the slab.
    #[test]
    fn god_object_pushes_back_through_the_whole_press_and_never_pulls() {
        let down: Vec<DVec3> = (0..=400)
            .map(|k| over_centre(1.2 - 0.008 * k as f64))
            .collect();
        let hold = vec![over_centre(-2.0); 100];
        let up: Vec<DVec3> = (0..=200)
            .map(|k| over_centre(0.8 + 0.004 * k as f64))
            .collect();
        let path = [down.clone(), hold, up.clone()].concat();
        let god = drive(&mut held_slab(), HapticContact::GodObject, &path);
        let touch = (1.2 - 1.0) / 0.008;
        assert!(
            god[..touch as usize].iter().all(|f| *f == DVec3::ZERO),
            "force before touching"
        );
        assert!(
            god.iter().all(|f| f.z >= 0.0),
            "the god object pulled the tool"
        );
        let at = |depth_cm: f64| god[((1.2 - 1.0 + depth_cm) / 0.008) as usize].z;
        eprintln!(
            "god object: force on the tool at 1, 3, 10, 20 mm deep: {:.3} {:.3} {:.3} {:.3} N",
            at(0.1),
            at(0.3),
            at(1.0),
            at(2.0)
        );
        assert!(
            at(0.1) > 0.0 && at(0.3) > at(0.1) && at(1.0) > at(0.3) && at(2.0) > at(1.0),
            "force did not grow with depth: {} {} {} {} N",
            at(0.1),
            at(0.3),
            at(1.0),
            at(2.0)
        );
        assert!(
            god[500].z >= at(2.0) * 0.5,
            "lost contact below the slab: {}",
            god[500]
        );
        assert_eq!(
            *god.last().unwrap(),
            DVec3::ZERO,
            "still touching when lifted off"
        );
        let near = drive(&mut held_slab(), HapticContact::NearestNode, &path);
        assert!(
            near[450].length() == 0.0,
            "nearest node holds a tool 2 cm below the slab"
        );
        let lifted = drive(
            &mut held_slab(),
            HapticContact::NearestNode,
            &[down[..250].to_vec(), up].concat(),
        );
        assert!(
            lifted.iter().any(|f| f.z < 0.0),
            "nearest node never pulled"
        );
    }

    #[test]
    fn haptic_thread_runs_publishes_and_pushes_back() {
        let m = held_slab();
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
        assert_eq!(
            (frame.nodes, frame.tets),
            (model.node_count(), model.tet_count())
        );
        assert!(frame.volume_ratio > 0.9 && frame.volume_ratio <= 1.0 + 1e-9);
        assert_eq!(frame.cut_advances, 0);
    }

    #[test]
    fn blade_handed_to_the_haptic_thread_cuts() {
        let (mesh, _) = TetMesh::from_raw(block(
            Vec3::ZERO,
            Vec3::new(0.04, 0.04, 0.01),
            UVec3::new(4, 4, 1),
        ))
        .unwrap();
        let m = MassSpringModel::new(
            &mesh,
            MassSpringParams {
                gravity: DVec3::ZERO,
                ..MassSpringParams::default()
            },
        )
        .unwrap();
        let nodes = m.node_count();
        let haptic = HapticLoop::spawn(m, HapticConfig::default());
        // A vertical blade through the block at y = 0.021, moved along x in 5 mm steps.
        let pose = |x: f64| BladePose {
            heel: DVec3::new(x, 0.021, -0.005),
            tip: DVec3::new(x, 0.021, 0.015),
        };
        for k in 0..=6 {
            haptic.set_blade(Some(pose(-0.005 + 0.005 * k as f64)));
            // Give the thread time to see each pose (a 1 kHz loop: ≈ 20 loops).
            std::thread::sleep(Duration::from_millis(20));
        }
        haptic.set_blade(None);
        std::thread::sleep(Duration::from_millis(20));
        let frame = haptic.latest();
        let model = haptic.stop().unwrap();
        assert!(frame.cut_advances >= 1, "{} advances", frame.cut_advances);
        // The adaptive cut snaps nodes onto the cut and duplicates them to open it.
        assert!(
            model.node_count() > nodes,
            "the blade cut nothing: {} nodes",
            model.node_count()
        );
        let mass = (model.total_mass() - model.initial_mass()).abs() / model.initial_mass();
        assert!(mass < 1e-9, "mass changed by {mass}");
    }
}
