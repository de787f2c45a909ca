//! The seed's press-and-release of a 3-D block (Figs. 3–6): a flat indenter presses the
//! top, holds and lifts off; the top centre's depth is recorded until the block settles.

use glam::DVec3;

use super::error::RheologyError;
use super::indenter::{FlatIndenter, PressSchedule};
use super::material::RheologyMaterial;
use super::specimen::{Specimen, SpecimenMesh};

/// How a press-and-release run is done.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PressProtocol {
    /// The block.
    pub specimen: Specimen,
    /// Indenter depth over time.
    pub schedule: PressSchedule,
    /// Half extents of the indenter face in x, y, m (centred on the top face).
    pub indenter_half_size: [f64; 2],
    /// Time simulated after lift-off, s.
    pub recovery: f64,
    /// Gravitational acceleration along −z, m/s² (0: none).
    pub gravity: f64,
    /// Time between recorded samples, s.
    pub sample_interval: f64,
}

impl PressProtocol {
    /// The experiment's protocol: `specimen` pressed to 20 % of its height by a face a third
    /// of its width across (padded by 0.5 % of the width to take the nodes on its rim) in
    /// 0.5 s, held `hold` s, lifted in 0.1 s, then 2 s of recovery, sampled every 5 ms; no
    /// gravity (gravity is the force-dependent damper's test, see `sag.rs`).
    pub fn standard(specimen: Specimen, hold: f64) -> Self {
        let half = specimen.size.x * (1.0 / 6.0 + 0.005);
        PressProtocol {
            specimen,
            schedule: PressSchedule {
                depth: 0.2 * specimen.size.z,
                press: 0.5,
                hold,
                lift: 0.1,
            },
            indenter_half_size: [half, half],
            recovery: 2.0,
            gravity: 0.0,
            sample_interval: 0.005,
        }
    }

    /// Total simulated time, s.
    pub fn duration(&self) -> f64 {
        self.schedule.end() + self.recovery
    }
}

/// What a press-and-release run recorded.
#[derive(Debug, Clone)]
pub struct PressOutcome {
    /// The block and its node sets.
    pub specimen: SpecimenMesh,
    /// Sample times, s.
    pub times: Vec<f64>,
    /// Depth of the top centre below its rest height at each sample, m.
    pub depth: Vec<f64>,
    /// Indenter face depth at each sample, m (0 once lifted off).
    pub indenter_depth: Vec<f64>,
    /// Node positions at the end of the hold (full press), m.
    pub at_full_press: Vec<DVec3>,
    /// Node positions at the end of the run, m.
    pub after_recovery: Vec<DVec3>,
    /// The RK4 substep used, s.
    pub substep: f64,
    /// RK4 steps taken.
    pub steps: usize,
}

impl PressOutcome {
    /// Largest recorded depth, m.
    pub fn max_depth(&self) -> f64 {
        self.depth.iter().cloned().fold(0.0, f64::max)
    }

    /// Depth at the end of the run, m.
    pub fn residual_depth(&self) -> f64 {
        *self
            .depth
            .last()
            .expect("a run records at least one sample")
    }

    /// Residual depth as a fraction of the largest.
    pub fn residual_fraction(&self) -> f64 {
        self.residual_depth() / self.max_depth()
    }
}

/// Press `material`'s block by `protocol` and record the top centre's depth.
pub fn press_and_release(
    material: &RheologyMaterial,
    protocol: &PressProtocol,
) -> Result<PressOutcome, RheologyError> {
    let specimen = protocol.specimen.mesh()?;
    let mut body = specimen.body(*material, protocol.gravity)?;
    let size = protocol.specimen.size;
    body.set_indenter(Some(FlatIndenter {
        centre: [0.0, 0.0],
        half_size: protocol.indenter_half_size,
        rest_top: size.z,
        schedule: protocol.schedule,
        candidates: specimen.top.clone(),
    }));
    let full_press = protocol.schedule.press + protocol.schedule.hold;
    let samples = (protocol.duration() / protocol.sample_interval).round() as usize;
    let mut times = vec![0.0];
    let mut depth = vec![0.0];
    let mut indenter_depth = vec![0.0];
    let mut at_full_press = None;
    let mut steps = 0;
    let mut substep = 0.0;
    for k in 1..=samples {
        let target = k as f64 * protocol.sample_interval;
        if at_full_press.is_none() && target >= full_press - 1e-12 {
            let n = body.advance(full_press - body.time())?;
            steps += n;
            at_full_press = Some(body.positions());
        }
        let dt = target - body.time();
        if dt > 1e-12 {
            let n = body.advance(dt)?;
            substep = dt / n as f64;
            steps += n;
        }
        times.push(target);
        depth.push(specimen.centre_depth(&body));
        indenter_depth.push(protocol.schedule.depth_at(target).0);
    }
    Ok(PressOutcome {
        at_full_press: at_full_press.unwrap_or_else(|| body.positions()),
        after_recovery: body.positions(),
        specimen,
        times,
        depth,
        indenter_depth,
        substep,
        steps,
    })
}
