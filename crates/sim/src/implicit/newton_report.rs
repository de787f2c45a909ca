//! What one implicit step cost: Newton iterations, products, line-search halvings and
//! the coarse level's refreshes.

/// What the last implicit step cost.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct NewtonReport {
    /// Newton iterations taken.
    pub iterations: u32,
    /// Hessian–vector products over all iterations.
    pub cg_products: u32,
    /// Iterations whose conjugate gradient met non-positive curvature.
    pub negative_curvature: u32,
    /// Step halvings of the line search.
    pub halvings: u32,
    /// `|∇G|` where the last iteration started (or where the gradient stop ended the step)
    /// over `|∇G|` at the step's first iterate (free nodes, 2-norm).
    pub gradient_ratio: f32,
    /// Whether the coarse matrix was re-assembled from the current tangents this step.
    pub coarse_refreshed: bool,
    /// Whether that refresh was not positive definite (the previous factor was kept).
    pub coarse_refresh_failed: bool,
    /// Coarse nodes after the step: more than the whole body's once a cut has split the
    /// grid (docs/physics-notes.md, "The coarse level after a cut").
    pub coarse_nodes: u32,
}

/// What a frame's implicit steps cost, summed over its steps (what the frame's stats
/// report).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct FrameCost {
    /// Newton iterations.
    pub iterations: u32,
    /// Hessian–vector products.
    pub cg_products: u32,
    /// Iterations whose conjugate gradient met non-positive curvature.
    pub negative_curvature: u32,
    /// Step halvings of the line search.
    pub halvings: u32,
    /// Steps that re-assembled the coarse matrix.
    pub coarse_refreshes: u32,
    /// Times the frame under the blade was taken back and run again at twice the steps
    /// (more live tets inverted after it than before).
    pub split_frames: u32,
}

impl FrameCost {
    /// Add one step's report.
    pub fn add(&mut self, r: &NewtonReport) {
        self.iterations += r.iterations;
        self.cg_products += r.cg_products;
        self.negative_curvature += r.negative_curvature;
        self.halvings += r.halvings;
        self.coarse_refreshes += u32::from(r.coarse_refreshed);
    }
}
