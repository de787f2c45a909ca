//! One localised simulation loop (PHYSICS.md §2.5): find the node nearest the tool, build
//! the hierarchy to level d (or to the refresh-rate manager's node count), integrate the
//! free nodes only, and feed the time of the force computation back to the manager. Each
//! phase is timed apart (localise, force, integrate), as the paper's Figs. 15–17 split it.
//! A recorded run's free-node counts can be replayed in place of the manager's choices
//! ([`LocalLoop::replay`]): the manager picks them from wall time, so only a replay of
//! them reproduces a budgeted run bit for bit.

use std::collections::VecDeque;
use std::time::Instant;

use glam::DVec3;

use super::{MassSpringModel, NodeHierarchy, RefreshRateManager};

/// A source of time, so that the loop can be tested with a scripted clock.
pub trait Clock {
    /// Seconds since an arbitrary origin, non-decreasing.
    fn now(&self) -> f64;
}

/// The system's monotonic clock.
#[derive(Debug, Clone, Copy)]
pub struct SystemClock {
    origin: Instant,
}

impl Default for SystemClock {
    fn default() -> Self {
        SystemClock {
            origin: Instant::now(),
        }
    }
}

impl Clock for SystemClock {
    fn now(&self) -> f64 {
        self.origin.elapsed().as_secs_f64()
    }
}

/// Settings of the local loop.
#[derive(Debug, Clone, PartialEq)]
pub struct LocalLoopParams {
    /// Propagation depth d: nodes deeper than this level are frozen.
    pub max_level: u32,
    /// Time budget per loop for the refresh-rate manager, ms; `None`: fixed depth only.
    pub budget_ms: Option<f64>,
    /// Fewest free nodes the manager may choose.
    pub min_nodes: usize,
    /// Most free nodes the manager may choose.
    pub max_nodes: usize,
}

impl Default for LocalLoopParams {
    fn default() -> Self {
        LocalLoopParams {
            max_level: 4,
            budget_ms: None,
            min_nodes: 16,
            max_nodes: usize::MAX,
        }
    }
}

/// What one loop did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoopStats {
    /// The node nearest the tool.
    pub root: u32,
    /// Free (integrated) nodes.
    pub free_nodes: usize,
    /// Hierarchy levels built (level 0 is the root; the last may be partial).
    pub levels: usize,
    /// Loop time (hierarchy + forces + integration), ms, by the loop's clock.
    pub ms: f64,
    /// Nearest node, hierarchy and stopping the nodes that left the free set, ms.
    pub localise_ms: f64,
    /// Spring and external forces on the free nodes, summed over the steps, ms.
    pub force_ms: f64,
    /// Velocity and position updates of the free nodes, summed over the steps, ms.
    pub integrate_ms: f64,
}

impl LoopStats {
    /// The deepest level the loop reached: the localisation level chosen (0: the root only).
    pub fn level(&self) -> u32 {
        self.levels.saturating_sub(1) as u32
    }
}

/// The localised loop with its hierarchy, optional refresh-rate manager and clock.
#[derive(Debug, Clone)]
pub struct LocalLoop<C: Clock = SystemClock> {
    params: LocalLoopParams,
    hierarchy: NodeHierarchy,
    manager: Option<RefreshRateManager>,
    previous: Vec<u32>,
    forces: Vec<DVec3>,
    /// Free-node counts of a recorded run for the next loops, first first.
    replay: VecDeque<usize>,
    clock: C,
}

impl<C: Clock> LocalLoop<C> {
    /// A loop with `params`, timed by `clock`.
    pub fn new(params: LocalLoopParams, clock: C) -> Self {
        let manager = params.budget_ms.map(|b| {
            RefreshRateManager::new(
                b,
                params.min_nodes.max(64),
                params.min_nodes,
                params.max_nodes,
            )
        });
        LocalLoop {
            params,
            hierarchy: NodeHierarchy::new(),
            manager,
            previous: Vec::new(),
            forces: Vec::new(),
            replay: VecDeque::new(),
            clock,
        }
    }

    /// The hierarchy of the last loop.
    pub fn hierarchy(&self) -> &NodeHierarchy {
        &self.hierarchy
    }

    /// The refresh-rate manager, when a budget is set.
    pub fn manager(&self) -> Option<&RefreshRateManager> {
        self.manager.as_ref()
    }

    /// Build the next loops' hierarchies with these free-node counts (a recorded run's
    /// [`LoopStats::free_nodes`], loop by loop) instead of the manager's or the fixed
    /// level's; once they run out, the loop chooses again. The manager still measures.
    pub fn replay(&mut self, free_nodes: impl IntoIterator<Item = usize>) {
        self.replay = free_nodes.into_iter().collect();
    }

    /// One loop of `dt` with the tool at `tip`. Nodes that left the free set stop.
    pub fn step(&mut self, model: &mut MassSpringModel, tip: DVec3, dt: f64) -> LoopStats {
        self.frame(model, tip, dt, 1)
    }

    /// One loop that localises once around `tip` and then takes `steps` steps of `dt` on
    /// the free nodes (a visual frame of several explicit steps). The manager, when set,
    /// sees the force + integration time (the paper's "time used for the mechanical
    /// computation") and picks the next loop's free-node count, hence its level.
    pub fn frame(
        &mut self,
        model: &mut MassSpringModel,
        tip: DVec3,
        dt: f64,
        steps: u32,
    ) -> LoopStats {
        let t0 = self.clock.now();
        let root = self.hierarchy.nearest_node(model, tip).unwrap_or(0);
        let (level, cap) = match &self.manager {
            Some(m) => (u32::MAX, m.free_nodes()),
            None => (self.params.max_level, self.params.max_nodes),
        };
        // A recorded count k rebuilds the recorded free set: the breadth-first order is
        // the same, and a build that ended below its cap with k nodes had no more to add.
        let cap = self.replay.pop_front().unwrap_or(cap);
        self.hierarchy.build(model, root, level, cap);
        let left: Vec<u32> = self
            .previous
            .iter()
            .copied()
            .filter(|&v| !self.hierarchy.is_free(v))
            .collect();
        model.stop_nodes(&left);
        let t1 = self.clock.now();
        let (mut force_ms, mut integrate_ms) = (0.0, 0.0);
        for _ in 0..steps.max(1) {
            let a = self.clock.now();
            model.gather_forces(self.hierarchy.free_nodes(), &mut self.forces);
            let b = self.clock.now();
            model.integrate_nodes(dt, self.hierarchy.free_nodes(), &self.forces);
            let c = self.clock.now();
            force_ms += (b - a) * 1e3;
            integrate_ms += (c - b) * 1e3;
        }
        let ms = (self.clock.now() - t0) * 1e3;
        if let Some(m) = &mut self.manager {
            m.update(force_ms + integrate_ms);
        }
        self.previous.clear();
        self.previous.extend_from_slice(self.hierarchy.free_nodes());
        LoopStats {
            root,
            free_nodes: self.hierarchy.free_nodes().len(),
            levels: self.hierarchy.levels(),
            ms,
            localise_ms: (t1 - t0) * 1e3,
            force_ms,
            integrate_ms,
        }
    }
}
