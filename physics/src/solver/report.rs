//! What the solvers report of a step: how each island was solved (`IslandReport`), and
//! what the steps so far did, counted (`StepStats`). Every solver writes them and the
//! world reads them, so they stand on neutral ground, below both.

/// How an island's constraints were solved.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IslandMethod {
    /// `exact`/`thesis`: the dense LCP by pivoting (up to `StepSettings::dense_row_limit`
    /// rows).
    Pivoting,
    /// `exact`/`thesis` above the row limit: projected Gauss–Seidel row by row.
    GaussSeidel,
    /// `soft`: a small contact island of different masses, one LCP per pass (its normals;
    /// its friction too where the masses differ 100-fold).
    SoftLcp,
    /// `soft`: contacts point by point (two-point manifolds as a 2 × 2 block).
    SoftPointByPoint,
    /// `soft`: an island of pins, solved as one linear system per pass.
    SoftPinBlock,
    /// `soft`: pins one by one (a lone pin, or an island above the block limit, whose
    /// pins go colour by colour, eight at a time, each lane as if alone: `soft::pins`).
    SoftPinByPin,
}

/// What happened in one island during the last step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IslandReport {
    pub contacts: usize,
    pub joints: usize,
    pub rows: usize,
    pub method: IslandMethod,
    /// Pivots made, or Gauss–Seidel sweeps (0 for the soft step's islands).
    pub pivots: usize,
    /// Whether the exact solve stopped at its pivot budget (`lcp::LcpStats::over_budget`):
    /// its last round stands, and under `auto` the island goes to the soft step for a
    /// while.
    pub over_budget: bool,
    /// The LCP's complementarity residual (NaN for Gauss–Seidel row by row, which never
    /// forms the matrix the residual is measured against).
    pub residual: f64,
}

/// Counts of what a world's steps did since it was made: how often each shortcut was taken
/// and how much work the step lists did, for profiling and for tests that check a
/// shortcut really is taken. Read-only: [`World::stats`](crate::World::stats) gathers
/// them from the stages that count them.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct StepStats {
    /// Substeps the impulse stage list (`sequential`, `thesis`, `exact`, and `auto`'s
    /// exact islands) ran, counting those of steps taken again finer.
    pub impulse_substeps: u64,
    /// Times `auto` took its split of the islands from the last step's, because what the
    /// split is made from had not changed.
    pub auto_splits_kept: u64,
    /// Soft steps that left contact points unwritten: their manifolds went straight into
    /// the kept plan's lanes.
    pub soft_steps_skipping_points: u64,
    /// Of those, the steps that built every point again after all (the plan changed, or
    /// something bounces).
    pub soft_steps_rebuilding_points: u64,
    /// Soft steps that made their plan (colours and batches) from the contacts before
    /// building the points.
    pub soft_steps_planned_first: u64,
    /// Factorisations of a pin island's matrix by the soft step: one per pass whose arms
    /// turned since the last.
    pub soft_pin_factorisations: u64,
}

impl StepStats {
    /// These counts and `other`'s added up: each stage counts only its own.
    pub(crate) fn merged(&self, other: &StepStats) -> StepStats {
        StepStats {
            impulse_substeps: self.impulse_substeps + other.impulse_substeps,
            auto_splits_kept: self.auto_splits_kept + other.auto_splits_kept,
            soft_steps_skipping_points: self.soft_steps_skipping_points
                + other.soft_steps_skipping_points,
            soft_steps_rebuilding_points: self.soft_steps_rebuilding_points
                + other.soft_steps_rebuilding_points,
            soft_steps_planned_first: self.soft_steps_planned_first
                + other.soft_steps_planned_first,
            soft_pin_factorisations: self.soft_pin_factorisations + other.soft_pin_factorisations,
        }
    }
}
