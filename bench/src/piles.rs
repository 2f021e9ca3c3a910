//! The big scenes (piles, the joint grid, the smash): pe soft and the peers alone, taking
//! turns round after round; and pe soft with the narrow phase's manifold reuse on and off.

use crate::format::{pretty, ratio_range, time_ratio};
use crate::harness::interleaved;
use crate::scene::{H, PYRAMIDS, joint_grid, smash};
use crate::{Job, Outcome, box2d_scenes, pe_scenes, rapier_scenes};
use pe::ContactSolver;
use pe_scenes::PeConfig;

/// The scenes of `pile`: every pile, the joint grid and the smash.
pub fn pile_scenes() -> Vec<&'static str> {
    let mut names: Vec<&str> = PYRAMIDS.iter().map(|p| p.name).collect();
    names.extend([joint_grid::NAME, smash::NAME]);
    names
}

/// pe `soft`, rapier2d and Box2D v3 on one of `pile_scenes`, in that order, as jobs for
/// `interleaved`; `None` for another scene.
pub fn pile_jobs(scene: &str) -> Option<Vec<Job<'static>>> {
    let pe = PeConfig::new(ContactSolver::Soft);
    if let Some(spec) = PYRAMIDS.iter().find(|p| p.name == scene) {
        Some(vec![
            Box::new(move || pe_scenes::pyramid(pe, spec, H)),
            Box::new(move || rapier_scenes::pyramid(spec, H, rapier_scenes::ITERATIONS)),
            Box::new(move || box2d_scenes::pyramid(spec, H, box2d_scenes::SUBSTEPS)),
        ])
    } else if scene == joint_grid::NAME {
        Some(vec![
            Box::new(move || pe_scenes::joint_grid(pe)),
            Box::new(rapier_scenes::joint_grid),
            Box::new(box2d_scenes::joint_grid),
        ])
    } else if scene == smash::NAME {
        Some(vec![
            Box::new(move || pe_scenes::smash(pe)),
            Box::new(rapier_scenes::smash),
            Box::new(box2d_scenes::smash),
        ])
    } else {
        None
    }
}

/// One round of `pile_jobs`: pe soft, rapier2d and Box2D v3 taking turns.
pub struct PileRound {
    pub pe: Outcome,
    pub rapier: Outcome,
    pub box2d: Outcome,
}

impl PileRound {
    fn run(scene: &str) -> Option<Self> {
        let [pe, rapier, box2d] =
            <[Outcome; 3]>::try_from(interleaved(pile_jobs(scene)?)).expect("three engines");
        Some(Self { pe, rapier, box2d })
    }

    /// pe's median over rapier2d's and over Box2D v3's.
    pub fn ratios(&self) -> (f64, f64) {
        let of = |peer: &Outcome| time_ratio(self.pe.timing.median, peer.timing.median);
        (of(&self.rapier), of(&self.box2d))
    }
}

/// `pile <scene> [rounds]`: pe soft, rapier2d and Box2D v3 on one pile (or the joint grid,
/// or the smash), taking turns (`interleaved`), for a few rounds, printing each round's
/// medians and the ratios (a quick check while working on the soft step).
pub fn run_pile_with_peers() {
    let scene = std::env::args()
        .nth(2)
        .unwrap_or_else(|| "pyramid20".into());
    let rounds: usize = std::env::args()
        .nth(3)
        .and_then(|r| r.parse().ok())
        .unwrap_or(3);
    let mut done = Vec::with_capacity(rounds);
    for round in 1..=rounds {
        let Some(r) = PileRound::run(&scene) else {
            eprintln!(
                "unknown scene {scene:?}: one of {}",
                pile_scenes().join(", ")
            );
            std::process::exit(2);
        };
        let (to_rapier, to_box2d) = r.ratios();
        println!(
            "{scene} round {round}: pe soft {} ({}), rapier2d {} ({}), Box2D v3 {} ({}); \
             pe ÷ rapier2d {to_rapier:.2}, pe ÷ Box2D v3 {to_box2d:.2}",
            pretty(r.pe.timing.median),
            r.pe.metric,
            pretty(r.rapier.timing.median),
            r.rapier.metric,
            pretty(r.box2d.timing.median),
            r.box2d.metric,
        );
        done.push(r);
    }
    println!(
        "{scene} over {rounds} rounds: pe ÷ rapier2d {}, pe ÷ Box2D v3 {}",
        ratio_range(done.iter().map(|r| r.ratios().0)),
        ratio_range(done.iter().map(|r| r.ratios().1))
    );
}

/// The main run's closing rounds: pe `soft` and the two peers alone on each of
/// `pile_scenes`, `PILE_ROUNDS` times.
pub const PILE_ROUNDS: usize = 3;

pub fn pile_rows() -> Vec<(&'static str, Vec<PileRound>)> {
    pile_scenes()
        .into_iter()
        .map(|scene| {
            eprintln!("{scene}: pe soft, rapier2d, Box2D v3 taking turns, {PILE_ROUNDS} rounds…");
            let rounds = (0..PILE_ROUNDS)
                .map(|_| PileRound::run(scene).expect("a pile scene"))
                .collect();
            (scene, rounds)
        })
        .collect()
}

/// pe soft with the narrow phase's manifold reuse on and off, on the scenes of many
/// resting contacts, taking turns (`interleaved`) so that both see the machine in the
/// same states.
pub struct NarrowRow {
    pub scene: String,
    pub reuse: Outcome,
    pub fresh: Outcome,
}

pub fn narrow_phase_rows() -> Vec<NarrowRow> {
    let reuse = PeConfig::new(ContactSolver::Soft);
    let fresh = PeConfig {
        reuse_manifolds: false,
        ..reuse
    };
    let both = |scene: &str, run: &(dyn Fn(PeConfig) -> Outcome + Sync)| {
        eprintln!("{scene}: pe soft with and without manifold reuse, taking turns…");
        let [reuse, fresh] = <[Outcome; 2]>::try_from(interleaved(vec![
            Box::new(move || run(reuse)) as Job<'_>,
            Box::new(move || run(fresh)),
        ]))
        .expect("two runs");
        NarrowRow {
            scene: scene.to_string(),
            reuse,
            fresh,
        }
    };
    let mut out: Vec<NarrowRow> = PYRAMIDS
        .iter()
        .map(|spec| both(spec.name, &|c| pe_scenes::pyramid(c, spec, H)))
        .collect();
    out.push(both(smash::NAME, &pe_scenes::smash));
    out
}
