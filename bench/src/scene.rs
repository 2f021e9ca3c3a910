//! The scenes, independent of any engine: sizes and placements in metres with y pointing
//! UP (each engine module mirrors them into its own convention), their known answers, and
//! the trackers that turn a run into the scene's metric. Keeping the trackers here means
//! every engine is judged by the same code.

use std::f64::consts::PI;
use std::fmt;

/// Gravity's magnitude, m/s².
pub const G: f64 = 10.0;
/// The default step, s.
pub const H: f64 = 1.0 / 60.0;

/// Friction coefficient of every contact (the floor's too, so that every engine's
/// combination rule gives 0.6).
pub const FRICTION: f64 = 0.6;
/// Side of a pyramid box, m.
pub const BOX: f64 = 1.0;
/// Size of the static floor, m (its top face at y = 0, or at each `Pyramid::floor_tops`).
pub const FLOOR: (f64, f64) = (200.0, 1.0);

/// A peer body's motion in f64, read from its engine, so that both peers' energies and
/// momenta are computed the same way (pe has its own, in f64 already).
#[derive(Debug, Clone, Copy)]
pub struct PeerBody {
    pub mass: f64,
    pub inertia: f64,
    pub velocity: (f64, f64),
    pub omega: f64,
    /// Height of the centre of mass (y up).
    pub height: f64,
}

impl PeerBody {
    pub fn kinetic_energy(&self) -> f64 {
        let (vx, vy) = self.velocity;
        0.5 * self.mass * (vx * vx + vy * vy) + 0.5 * self.inertia * self.omega * self.omega
    }

    /// Kinetic plus gravitational energy.
    pub fn energy(&self) -> f64 {
        self.kinetic_energy() + self.mass * G * self.height
    }

    pub fn momentum(&self) -> (f64, f64) {
        (self.mass * self.velocity.0, self.mass * self.velocity.1)
    }
}

/// Total linear momentum and kinetic energy of `bodies`.
pub fn momentum_and_kinetic_energy(bodies: impl Iterator<Item = PeerBody>) -> ((f64, f64), f64) {
    bodies.fold(((0.0, 0.0), 0.0), |((px, py), e), b| {
        let (bx, by) = b.momentum();
        ((px + bx, py + by), e + b.kinetic_energy())
    })
}

/// The larger of a running worst value and a new sample, where a NaN sample (an engine
/// that blew up) counts as infinitely bad rather than being skipped as `f64::max` would.
pub fn worst(so_far: f64, sample: f64) -> f64 {
    if sample.is_nan() {
        f64::INFINITY
    } else {
        so_far.max(sample)
    }
}

/// A pyramid of unit boxes, `rows` at the base, standing on the floor; or a grid of them,
/// `grid.0` side by side on each of `grid.1` floors stacked one above the other. With
/// `stack`, a column of `rows` boxes instead. With `tiles`, each floor is that many
/// static unit tiles side by side (a terrain of many pieces) instead of one slab.
#[derive(Debug, Clone, Copy)]
pub struct Pyramid {
    pub name: &'static str,
    pub rows: usize,
    pub steps: usize,
    pub grid: (usize, usize),
    pub stack: bool,
    pub tiles: usize,
}

pub const PYRAMIDS: [Pyramid; 5] = [
    Pyramid {
        name: "pyramid20",
        rows: 20,
        steps: 600,
        grid: (1, 1),
        stack: false,
        tiles: 0,
    },
    // 820 boxes: 300 steps (5 s) keep the whole benchmark within a few minutes.
    Pyramid {
        name: "pyramid40",
        rows: 40,
        steps: 300,
        grid: (1, 1),
        stack: false,
        tiles: 0,
    },
    // Box2D's large_pyramid benchmark: base 100, 5,050 boxes, 500 steps.
    Pyramid {
        name: "large_pyramid",
        rows: 100,
        steps: 500,
        grid: (1, 1),
        stack: false,
        tiles: 0,
    },
    // After Box2D's many_pyramids: many small islands instead of one big one. 10 × 10
    // pyramids of base 10 (5,500 boxes, as many as large_pyramid), ten to a floor.
    Pyramid {
        name: "many_pyramids",
        rows: 10,
        steps: 300,
        grid: (10, 10),
        stack: false,
        tiles: 0,
    },
    // pyramid20 on a floor of 2,000 static unit tiles (a terrain of many pieces): what
    // bodies that never move cost each engine.
    Pyramid {
        name: "pyramid20_on_tiles",
        rows: 20,
        steps: 600,
        grid: (1, 1),
        stack: false,
        tiles: 2000,
    },
];

/// Stacks of 10 and 20 boxes for 10 s at `H` (the sweep sets its own step).
pub const STACKS: [Pyramid; 2] = [
    Pyramid {
        name: "stack10",
        rows: 10,
        steps: 600,
        grid: (1, 1),
        stack: true,
        tiles: 0,
    },
    Pyramid {
        name: "stack20",
        rows: 20,
        steps: 600,
        grid: (1, 1),
        stack: true,
        tiles: 0,
    },
];

impl Pyramid {
    /// Box centres, bottom row first and the top box last. The boxes touch their
    /// neighbours and the floor exactly, so nothing falls or overlaps at the start.
    /// In a grid, pyramid by pyramid, floor by floor: the top box is the last pyramid's.
    pub fn centres(&self) -> Vec<(f64, f64)> {
        let (columns, floors) = self.grid;
        let mut centres = Vec::with_capacity(columns * floors * self.rows * (self.rows + 1) / 2);
        for &base in &self.floor_tops() {
            for column in 0..columns {
                // One box of space between neighbouring pyramids.
                let middle = (column as f64 - 0.5 * (columns - 1) as f64) * (self.rows + 1) as f64;
                for row in 0..self.rows {
                    let count = if self.stack { 1 } else { self.rows - row };
                    let left = middle - 0.5 * (count - 1) as f64 * BOX;
                    for k in 0..count {
                        centres.push((left + k as f64 * BOX, base + (row as f64 + 0.5) * BOX));
                    }
                }
            }
        }
        centres
    }

    /// Each floor's pieces as (centre, size): one slab of `FLOOR`, or `tiles` unit tiles
    /// side by side, centred, their seams under the boxes' (a box on one tile each).
    pub fn floor_pieces(&self) -> Vec<((f64, f64), (f64, f64))> {
        let mut pieces = Vec::new();
        for top in self.floor_tops() {
            if self.tiles == 0 {
                pieces.push(((0.0, top - 0.5 * FLOOR.1), FLOOR));
                continue;
            }
            let left = -0.5 * self.tiles as f64 * BOX;
            for k in 0..self.tiles {
                let x = left + (k as f64 + 0.5) * BOX;
                pieces.push(((x, top - 0.5 * BOX), (BOX, BOX)));
            }
        }
        pieces
    }

    /// The height of each floor's top face: the first at 0, the next a box above the
    /// pyramids below it (plus the floor's own thickness).
    pub fn floor_tops(&self) -> Vec<f64> {
        let spacing = (self.rows + 1) as f64 * BOX + FLOOR.1;
        (0..self.grid.1).map(|k| k as f64 * spacing).collect()
    }
}

/// Follows every box of a pyramid: how far the top box slid sideways and sank, and which
/// boxes fell: moved more than half a box sideways at some point of the run. (Not height:
/// a 100-row pyramid of soft contacts sags by more than half a box under its own weight
/// without any box leaving its place; the top box's sag is reported on its own.)
pub struct PyramidTracker {
    start: Vec<(f64, f64)>,
    fallen: Vec<bool>,
    top: (f64, f64),
    worst_sag: f64,
}

impl PyramidTracker {
    pub fn new(start: Vec<(f64, f64)>) -> Self {
        let top = start.last().copied().unwrap_or_default();
        Self {
            fallen: vec![false; start.len()],
            start,
            top,
            worst_sag: 0.0,
        }
    }

    /// Centres now, y up, in the order given to `new`.
    pub fn update(&mut self, centres: impl Iterator<Item = (f64, f64)>) {
        for (i, (x, y)) in centres.enumerate() {
            let moved = (x - self.start[i].0).abs();
            // A NaN position (the engine blew up) counts as fallen.
            self.fallen[i] |= moved.is_nan() || y.is_nan() || moved > 0.5 * BOX;
            self.top = (x, y);
        }
        let top_start = self.start.last().map_or(0.0, |c| c.1);
        self.worst_sag = worst(self.worst_sag, (top_start - self.top.1) / BOX);
    }

    pub fn finish(&self) -> Metric {
        let top_start = self.start.last().map_or(0.0, |c| c.0);
        Metric::Pyramid {
            top_drift: (self.top.0 - top_start).abs() / BOX,
            top_sag: self.worst_sag,
            fallen: self.fallen.iter().filter(|&&f| f).count(),
            boxes: self.start.len(),
        }
    }
}

/// The 90° pendulum: a small square bob on a massless pin, where the exact period is known.
#[derive(Debug, Clone, Copy)]
pub struct Pendulum {
    pub name: &'static str,
    pub h: f64,
}

pub const PENDULUMS: [Pendulum; 2] = [
    Pendulum {
        name: "pendulum90 h=1/60",
        h: 1.0 / 60.0,
    },
    Pendulum {
        name: "pendulum90 h=1/240",
        h: 1.0 / 240.0,
    },
];

/// Distance from the pivot to the bob's centre, m.
pub const PENDULUM_LENGTH: f64 = 1.0;
/// Side of the square bob, m (density 1).
pub const BOB: f64 = 0.05;
/// Release angle from the vertical.
pub const THETA0: f64 = PI / 2.0;
/// Simulated time, s: about 25 periods, so the period is averaged over many swings.
pub const PENDULUM_SECONDS: f64 = 60.0;

impl Pendulum {
    pub fn steps(&self) -> usize {
        (PENDULUM_SECONDS / self.h).round() as usize
    }

    /// Where the bob's centre starts (y up), with the pivot at the origin: θ0 from the
    /// downward vertical, towards +x.
    pub fn bob_start() -> (f64, f64) {
        (
            PENDULUM_LENGTH * THETA0.sin(),
            -PENDULUM_LENGTH * THETA0.cos(),
        )
    }

    /// The compound pendulum's exact period, T = 4 √(I_p / (m g L)) K(sin(θ0/2)), with
    /// I_p = m s²/6 + m L² the bob's moment of inertia about the pivot.
    pub fn exact_period() -> f64 {
        let m = BOB * BOB;
        let l = PENDULUM_LENGTH;
        let i_pivot = m * BOB * BOB / 6.0 + m * l * l;
        4.0 * (i_pivot / (m * G * l)).sqrt() * elliptic_k((THETA0 / 2.0).sin())
    }

    /// The energy scale m g L that drifts are measured against.
    pub fn energy_scale() -> f64 {
        BOB * BOB * G * PENDULUM_LENGTH
    }
}

/// Complete elliptic integral of the first kind K(k), by the arithmetic–geometric mean:
/// K(k) = π / (2 AGM(1, √(1 − k²))). Thirty rounds are far more than converge in f64.
pub fn elliptic_k(k: f64) -> f64 {
    let (mut a, mut b) = (1.0f64, (1.0 - k * k).sqrt());
    for _ in 0..30 {
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    PI / (2.0 * a)
}

/// Measures a pendulum's period from the times the bob crosses below the pivot moving
/// towards +x (interpolated within the step), the largest energy excursion, and the widest
/// the pin opened (a period means little if the pin let go).
pub struct PeriodTracker {
    h: f64,
    prev_x: f64,
    crossings: Vec<f64>,
    e0: f64,
    max_drift: f64,
    worst_gap: f64,
}

impl PeriodTracker {
    pub fn new(h: f64, x0: f64, e0: f64) -> Self {
        Self {
            h,
            prev_x: x0,
            crossings: Vec::new(),
            e0,
            max_drift: 0.0,
            worst_gap: 0.0,
        }
    }

    /// `steps` steps done; the bob's centre is at horizontal offset `x` from the pivot, the
    /// total energy is `energy` and the pin's anchors are `gap` apart.
    pub fn update(&mut self, steps: usize, x: f64, energy: f64, gap: f64) {
        self.worst_gap = worst(self.worst_gap, gap);
        if self.prev_x < 0.0 && x >= 0.0 {
            let fraction = self.prev_x / (self.prev_x - x);
            self.crossings
                .push((steps as f64 - 1.0 + fraction) * self.h);
        }
        self.prev_x = x;
        self.max_drift = worst(self.max_drift, (energy - self.e0).abs());
    }

    pub fn finish(&self) -> Metric {
        let exact = Pendulum::exact_period();
        let period_error = match self.crossings.as_slice() {
            [first, .., last] => {
                let period = (last - first) / (self.crossings.len() - 1) as f64;
                (period - exact) / exact
            }
            _ => f64::NAN, // fewer than two crossings: it did not swing
        };
        Metric::Pendulum {
            period_error,
            energy_drift: self.max_drift / Pendulum::energy_scale(),
            worst_gap: self.worst_gap,
        }
    }
}

/// The heavy chain: light links holding a body 500 times heavier than each.
pub mod chain {
    pub const NAME: &str = "heavychain";
    pub const LINKS: usize = 10;
    /// Link size, m: mass 0.2 kg at density 2.
    pub const LINK: (f64, f64) = (1.0, 0.1);
    pub const LINK_DENSITY: f64 = 2.0;
    /// The end body: a 1 m square of 100 kg.
    pub const END_SIZE: f64 = 1.0;
    pub const END_DENSITY: f64 = 100.0;
    pub const SECONDS: f64 = 10.0;

    /// Steps of `h` that make up the run.
    pub fn steps(h: f64) -> usize {
        (SECONDS / h).round() as usize
    }

    /// Pin `i` (0 = the one to the world) is at (i, 0): the chain lies level along +x,
    /// so it is released horizontally and swings down.
    pub fn pin(i: usize) -> (f64, f64) {
        (i as f64 * LINK.0, 0.0)
    }

    pub fn link_centre(i: usize) -> (f64, f64) {
        ((i as f64 + 0.5) * LINK.0, 0.0)
    }

    /// The end body hangs from the last pin by the middle of its left side.
    pub fn end_centre() -> (f64, f64) {
        (LINKS as f64 * LINK.0 + 0.5 * END_SIZE, 0.0)
    }
}

/// The dropped box: restitution 0.5 from 2 m should rebound to e² · 2 m = 0.5 m.
pub mod bounce {
    pub const NAME: &str = "bounce";
    pub const SIZE: f64 = 1.0;
    pub const RESTITUTION: f64 = 0.5;
    /// Height of the box's bottom above the floor at release, m.
    pub const DROP: f64 = 2.0;
    /// 2 s: the fall takes 0.63 s and the rebound rises for 0.32 s.
    pub const SECONDS: f64 = 2.0;

    /// Steps of `h` that make up the run.
    pub fn steps(h: f64) -> usize {
        (SECONDS / h).round() as usize
    }

    pub fn expected_peak() -> f64 {
        RESTITUTION * RESTITUTION * DROP
    }
}

/// Finds the first rebound's peak: the highest the body's bottom gets between the first
/// time it moves up and the first time after that it moves down again.
#[derive(Default)]
pub struct ReboundTracker {
    rising: bool,
    done: bool,
    peak: Option<f64>,
}

impl ReboundTracker {
    /// `bottom`: height of the body's bottom above the floor; `v_up`: its upward speed.
    pub fn update(&mut self, bottom: f64, v_up: f64) {
        if self.done {
            return;
        }
        if v_up > 0.0 {
            self.rising = true;
        }
        if self.rising {
            self.peak = Some(self.peak.map_or(bottom, |p| p.max(bottom)));
            if v_up <= 0.0 {
                self.done = true;
            }
        }
    }

    pub fn finish(&self) -> Metric {
        let expected = bounce::expected_peak();
        let peak = self.peak.unwrap_or(f64::NAN);
        Metric::Bounce {
            peak,
            error: (peak - expected) / expected,
        }
    }
}

/// Smash: a heavy box at 40 m/s into a block of 120 × 80 small boxes, no gravity, no
/// static body. Nothing but the bodies exchanges momentum, so the total linear momentum is
/// conserved exactly, and with restitution 0 the kinetic energy can only fall.
pub mod smash {
    pub const NAME: &str = "smash";
    pub const COLUMNS: usize = 120;
    pub const ROWS: usize = 80;
    /// Small boxes, touching: the block is 60 × 40 m with its lower left corner at (0, 0).
    pub const SMALL: f64 = 0.5;
    pub const HEAVY: f64 = 8.0;
    pub const HEAVY_DENSITY: f64 = 10.0;
    pub const SPEED: f64 = 40.0;
    pub const STEPS: usize = 300;

    pub fn small_centres() -> Vec<(f64, f64)> {
        (0..ROWS)
            .flat_map(|r| {
                (0..COLUMNS).map(move |c| ((c as f64 + 0.5) * SMALL, (r as f64 + 0.5) * SMALL))
            })
            .collect()
    }

    /// The heavy box starts 10 m left of the block, level with its middle.
    pub fn heavy_centre() -> (f64, f64) {
        (-10.0 - 0.5 * HEAVY, 0.5 * ROWS as f64 * SMALL)
    }

    /// The pose of body `index`, in the order every engine adds them (the small boxes
    /// row by row, then the heavy one), from its centre and angle (y up).
    pub fn box_pose(index: usize, centre: (f64, f64), angle: f64) -> super::BoxPose {
        let side = if index < ROWS * COLUMNS { SMALL } else { HEAVY };
        super::BoxPose::new(centre, angle, 0.5 * side)
    }
}

/// Joint grid (Box2D's benchmark): 100 × 100 bodies 1 m apart, each pinned to its right and
/// lower neighbours halfway between them, hanging from the seven middle bodies of the top
/// row, which are static. The pins should hold: their gap is the error.
pub mod joint_grid {
    pub const NAME: &str = "joint_grid";
    pub const N: usize = 100;
    /// Squares 0.8 m wide: neighbours do not touch, so only the pins act.
    pub const SIZE: f64 = 0.8;
    pub const STEPS: usize = 300;

    /// Body (row, column) centre; row 0 is the top, at y = 0.
    pub fn centre(row: usize, column: usize) -> (f64, f64) {
        (column as f64, -(row as f64))
    }

    pub fn is_static(row: usize, column: usize) -> bool {
        row == 0 && (N / 2 - 3..=N / 2 + 3).contains(&column)
    }

    /// Pins as (body index a, body index b, world point), bodies numbered row by row.
    pub fn pins() -> Vec<(usize, usize, (f64, f64))> {
        let mut pins = Vec::with_capacity(2 * N * N);
        for r in 0..N {
            for c in 0..N {
                let i = r * N + c;
                if c + 1 < N {
                    pins.push((i, i + 1, (c as f64 + 0.5, -(r as f64))));
                }
                if r + 1 < N {
                    pins.push((i, i + N, (c as f64, -(r as f64) - 0.5)));
                }
            }
        }
        pins
    }
}

/// Watches the smash: its total linear momentum and kinetic energy against their start,
/// and how deep its boxes pass into each other (`OverlapTracker`).
pub struct SmashTracker {
    start: (f64, f64),
    start_energy: f64,
    worst: f64,
    energy_ratio: f64,
    overlaps: OverlapTracker,
    boxes: Vec<BoxPose>,
}

impl SmashTracker {
    pub fn new(momentum: (f64, f64), energy: f64) -> Self {
        Self {
            start: momentum,
            start_energy: energy,
            worst: 0.0,
            energy_ratio: 1.0,
            overlaps: OverlapTracker::default(),
            boxes: Vec::new(),
        }
    }

    /// The totals now, and every box's pose.
    pub fn update(
        &mut self,
        momentum: (f64, f64),
        energy: f64,
        boxes: impl Iterator<Item = BoxPose>,
    ) {
        let size = self.start.0.hypot(self.start.1);
        let drift = (momentum.0 - self.start.0).hypot(momentum.1 - self.start.1) / size;
        self.worst = worst(self.worst, drift);
        self.energy_ratio = energy / self.start_energy;
        self.boxes.clear();
        self.boxes.extend(boxes);
        self.overlaps.update(&self.boxes);
    }

    pub fn finish(&self) -> Metric {
        Metric::Momentum {
            drift: self.worst,
            energy_ratio: self.energy_ratio,
            deepest_overlap: self.overlaps.deepest(),
        }
    }
}

/// A square box's pose: centre, edge directions and half its side, m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoxPose {
    centre: (f64, f64),
    /// The box's two edge directions, found once (the smash has 9,601 boxes a step).
    axes: [(f64, f64); 2],
    half: f64,
}

impl BoxPose {
    pub fn new(centre: (f64, f64), angle: f64, half: f64) -> Self {
        let (s, c) = angle.sin_cos();
        Self {
            centre,
            axes: [(c, s), (-s, c)],
            half,
        }
    }

    /// Half the box's extent along the unit vector `u`.
    fn radius_along(&self, u: (f64, f64)) -> f64 {
        let [e, f] = self.axes;
        self.half * ((e.0 * u.0 + e.1 * u.1).abs() + (f.0 * u.0 + f.1 * u.1).abs())
    }

    /// The radius of the circle about the centre that holds the box.
    fn circumradius(&self) -> f64 {
        self.half * std::f64::consts::SQRT_2
    }
}

/// How far two boxes overlap: the least overlap of their projections on the four edge
/// directions (the separating-axis test), negative when one of them separates them.
pub fn overlap(a: &BoxPose, b: &BoxPose) -> f64 {
    let d = (b.centre.0 - a.centre.0, b.centre.1 - a.centre.1);
    a.axes
        .into_iter()
        .chain(b.axes)
        .map(|u| a.radius_along(u) + b.radius_along(u) - (d.0 * u.0 + d.1 * u.1).abs())
        .fold(f64::INFINITY, f64::min)
}

/// Watches the deepest overlap between any two of a scene's boxes over the run: how far
/// bodies passed into each other, the same test on every engine's poses. Fast bodies that
/// an engine lets through each other show here (or pass unseen between two steps).
#[derive(Debug, Default)]
pub struct OverlapTracker {
    deepest: f64,
    /// Scratch: each small box's grid cell and index, sorted.
    cells: Vec<((i64, i64), u32)>,
    big: Vec<u32>,
}

impl OverlapTracker {
    pub fn update(&mut self, boxes: &[BoxPose]) {
        self.deepest = worst(self.deepest, self.deepest_now(boxes));
    }

    /// The deepest overlap among `boxes` now (0 if none touch). Boxes are paired by a grid
    /// of cells as wide as the smallest box's circle: two boxes of that size can overlap
    /// only in the same or neighbouring cells. Bigger boxes are tested against every box.
    fn deepest_now(&mut self, boxes: &[BoxPose]) -> f64 {
        let Some(small) = boxes.iter().map(BoxPose::circumradius).reduce(f64::min) else {
            return 0.0;
        };
        let cell = 2.0 * small;
        self.cells.clear();
        self.big.clear();
        for (i, b) in boxes.iter().enumerate() {
            if b.circumradius() > small {
                self.big.push(i as u32);
            } else {
                let at = |x: f64| (x / cell).floor() as i64;
                self.cells
                    .push(((at(b.centre.0), at(b.centre.1)), i as u32));
            }
        }
        self.cells.sort_unstable();
        let mut deepest: f64 = 0.0;
        let mut test = |i: u32, j: u32| {
            let (a, b) = (&boxes[i as usize], &boxes[j as usize]);
            let (dx, dy) = (b.centre.0 - a.centre.0, b.centre.1 - a.centre.1);
            let reach = a.circumradius() + b.circumradius();
            if dx * dx + dy * dy < reach * reach {
                deepest = worst(deepest, overlap(a, b));
            }
        };
        for (k, &big) in self.big.iter().enumerate() {
            for &(_, small) in &self.cells {
                test(big, small);
            }
            // Two big boxes meet once, from the first of them.
            for &other in &self.big[k + 1..] {
                test(big, other);
            }
        }
        // Each cell against itself (later boxes) and four of its neighbours, so that a
        // pair of cells is visited once.
        for (n, &((x, y), i)) in self.cells.iter().enumerate() {
            for (dx, dy) in [(0, 0), (1, -1), (1, 0), (1, 1), (0, 1)] {
                let key = (x + dx, y + dy);
                let from = if (dx, dy) == (0, 0) {
                    n + 1
                } else {
                    self.cells.partition_point(|&(c, _)| c < key)
                };
                for &(_, j) in self.cells[from..].iter().take_while(|&&(c, _)| c == key) {
                    test(i, j);
                }
            }
        }
        deepest
    }

    /// The deepest overlap seen, m.
    pub fn deepest(&self) -> f64 {
        self.deepest
    }
}

/// A scene's error or stability figure.
#[derive(Debug, Clone, Copy)]
pub enum Metric {
    Pyramid {
        /// Top box's sideways displacement over the run, in box widths.
        top_drift: f64,
        /// The most the top box sank below its start, in box heights.
        top_sag: f64,
        fallen: usize,
        boxes: usize,
    },
    Pendulum {
        /// (measured − exact) / exact.
        period_error: f64,
        /// max |E − E0| / (m g L).
        energy_drift: f64,
        /// Widest anchor-to-anchor distance of the pin at any step, m.
        worst_gap: f64,
    },
    Chain {
        /// Widest anchor-to-anchor distance of any joint at any step, m.
        worst_gap: f64,
    },
    Bounce {
        /// Height of the first rebound's peak, m.
        peak: f64,
        /// (peak − expected) / expected.
        error: f64,
    },
    Momentum {
        /// Largest |P − P0| / |P0| over the run.
        drift: f64,
        /// Kinetic energy at the end over at the start.
        energy_ratio: f64,
        /// The deepest any two boxes overlapped at the end of a step, m.
        deepest_overlap: f64,
    },
}

impl fmt::Display for Metric {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Metric::Pyramid {
                top_drift,
                top_sag,
                fallen,
                boxes,
            } => write!(
                f,
                "top drift {:.2}% of width, sag {:.2}; {fallen}/{boxes} fallen",
                100.0 * top_drift,
                top_sag
            ),
            Metric::Pendulum {
                period_error,
                energy_drift,
                worst_gap,
            } => write!(
                f,
                "period error {:+.3}%; energy drift {:.2}% of m g L; worst pin gap {worst_gap:.1e} m",
                100.0 * period_error,
                100.0 * energy_drift
            ),
            Metric::Chain { worst_gap } => write!(
                f,
                "worst gap {worst_gap:.2e} m = {:.2e} link lengths",
                worst_gap / chain::LINK.0
            ),
            Metric::Bounce { peak, error } => {
                write!(f, "peak {peak:.4} m, error {:+.2}%", 100.0 * error)
            }
            Metric::Momentum {
                drift,
                energy_ratio,
                deepest_overlap,
            } => write!(
                f,
                "momentum drift {drift:.1e} of P0; kinetic energy {:.1}% of the start; \
                 deepest overlap {:.0}% of a small box",
                100.0 * energy_ratio,
                100.0 * deepest_overlap / smash::SMALL
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_nan_sample_is_the_worst() {
        assert_eq!(worst(1.0, f64::NAN), f64::INFINITY);
        assert_eq!(worst(1.0, 2.0), 2.0);
    }

    #[test]
    fn elliptic_k_matches_known_values() {
        assert!((elliptic_k(0.0) - PI / 2.0).abs() < 1e-15);
        // K(sin 45°) = 1.854074677301372 (Abramowitz & Stegun table 17.1).
        assert!((elliptic_k(0.5f64.sqrt()) - 1.854_074_677_301_372).abs() < 1e-12);
    }

    #[test]
    fn pyramid_has_triangular_count_with_the_top_box_last() {
        let c = PYRAMIDS[0].centres();
        assert_eq!(c.len(), 210);
        assert_eq!(*c.last().unwrap(), (0.0, 19.5));
        assert_eq!(c[0], (-9.5, 0.5));
    }

    /// 100 pyramids of 55 boxes; no box overlaps another or a floor (all are unit boxes,
    /// so centres at least one box apart, and each box's bottom at or above a floor top
    /// with no floor cutting through it).
    #[test]
    fn many_pyramids_do_not_overlap() {
        let spec = PYRAMIDS.iter().find(|p| p.name == "many_pyramids").unwrap();
        let c = spec.centres();
        assert_eq!(c.len(), 100 * 55);
        let mut sorted = c.clone();
        sorted.sort_by(|a, b| a.0.total_cmp(&b.0));
        for (i, a) in sorted.iter().enumerate() {
            for b in sorted[i + 1..]
                .iter()
                .take_while(|b| b.0 - a.0 < BOX - 1e-9)
            {
                assert!((a.1 - b.1).abs() >= BOX - 1e-9, "{a:?} overlaps {b:?}");
            }
        }
        let tops = spec.floor_tops();
        for &(_, y) in &c {
            let bottom = y - 0.5 * BOX;
            assert!(
                tops.iter()
                    .any(|&t| (bottom - t) > -1e-9 && bottom - t < 10.0 * BOX)
            );
            assert!(
                tops.iter()
                    .all(|&t| bottom >= t - 1e-9 || y + 0.5 * BOX <= t - FLOOR.1 + 1e-9)
            );
        }
    }

    fn square(centre: (f64, f64), angle: f64, half: f64) -> BoxPose {
        BoxPose::new(centre, angle, half)
    }

    #[test]
    fn overlap_is_the_depth_of_the_shallowest_axis() {
        let a = square((0.0, 0.0), 0.0, 0.5);
        // Face to face, 0.1 m into each other; a quarter turn changes nothing.
        let b = square((0.9, 0.3), 0.0, 0.5);
        assert!((overlap(&a, &b) - 0.1).abs() < 1e-12);
        let b = square((0.9, 0.3), PI / 2.0, 0.5);
        assert!((overlap(&a, &b) - 0.1).abs() < 1e-12);
        // A corner of a box turned 45° into a's face: it reaches √2/2 from its centre.
        let b = square((1.1, 0.0), PI / 4.0, 0.5);
        let corner = 0.5 + 0.5 * 2f64.sqrt() - 1.1;
        assert!((overlap(&a, &b) - corner).abs() < 1e-12);
        assert!((overlap(&b, &a) - corner).abs() < 1e-12);
        // Apart: the gap, negative.
        let b = square((1.5, 0.0), 0.0, 0.5);
        assert!((overlap(&a, &b) + 0.5).abs() < 1e-12);
    }

    /// The grid finds the same deepest overlap as testing every pair, among small boxes
    /// scattered densely enough to overlap, and two big ones.
    #[test]
    fn overlap_tracker_matches_every_pair() {
        let mut seed: u64 = 2026;
        let mut random = || {
            seed = seed
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..20 {
            let mut boxes: Vec<BoxPose> = (0..300)
                .map(|_| square((20.0 * random(), 20.0 * random()), 7.0 * random(), 0.25))
                .collect();
            boxes.push(square((5.0, 5.0), random(), 4.0));
            boxes.push(square((12.0, 9.0), random(), 3.0));
            let mut every_pair: f64 = 0.0;
            for (i, a) in boxes.iter().enumerate() {
                for b in &boxes[i + 1..] {
                    every_pair = every_pair.max(overlap(a, b));
                }
            }
            let mut tracker = OverlapTracker::default();
            tracker.update(&boxes);
            assert!(every_pair > 0.0);
            assert_eq!(tracker.deepest(), every_pair);
        }
        // Apart, nothing: the tracker's floor is 0.
        let mut tracker = OverlapTracker::default();
        tracker.update(&[square((0.0, 0.0), 0.0, 0.5), square((2.0, 0.0), 0.0, 0.5)]);
        assert_eq!(tracker.deepest(), 0.0);
    }

    #[test]
    fn rebound_tracker_takes_the_first_peak_only() {
        let mut t = ReboundTracker::default();
        let samples = [
            (2.0, 0.0),
            (1.0, -3.0),
            (0.0, 2.0),
            (0.4, 1.0),
            (0.5, -0.1),
            (0.9, 5.0),
        ];
        for (y, v) in samples {
            t.update(y, v);
        }
        let Metric::Bounce { peak, .. } = t.finish() else {
            unreachable!()
        };
        assert_eq!(peak, 0.5);
    }
}
