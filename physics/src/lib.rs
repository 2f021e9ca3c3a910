//! `pe` — a deterministic 2D rigid-body engine for convex polygons, pin joints and motors:
//! the libPE pipeline of the thesis (SAT contacts, simultaneous contact impulses as an LCP,
//! impulse joints, motors), rebuilt. No GUI, no files.
//!
//! ```
//! use pe::{BodyDef, ConvexPolygon, Vec2, World};
//! let mut world = World::new(Vec2::new(0.0, 9.81)); // y points down, as on screen
//! let floor = ConvexPolygon::rectangle(20.0, 1.0).unwrap();
//! world.add_body(BodyDef::new(floor, 0.0).at(Vec2::new(0.0, 5.0), 0.0)).unwrap();
//! let crate_ = ConvexPolygon::rectangle(1.0, 1.0).unwrap();
//! let box_ = world.add_body(BodyDef::new(crate_, 1.0)).unwrap();
//! for _ in 0..240 {
//!     world.step(1.0 / 60.0);
//! }
//! let y = world.body(box_).unwrap().position.y;
//! assert!((y - 4.0).abs() < 0.05, "the box rests on the floor: {y}");
//! ```
//!
//! Everything public is re-exported here, at the crate root; the modules behind it are
//! private, so that the engine's internals can change without breaking a user.
//!
//! - Building a world: a [`World`], bodies from a [`BodyDef`] of a [`ConvexPolygon`], pins
//!   from a [`JointDef`] (driven by a [`JointMotor`] or not), and the thesis's body motors
//!   ([`BodyMotor`]). Each is checked as it is added ([`BodyError`], [`JointError`],
//!   [`MotorError`], [`ShapeError`]), against the [`limits`] among others.
//! - Stepping: [`World::step`], or [`World::try_step`] for the reason a step is refused
//!   ([`StepError`]), as the world's [`StepSettings`] say ([`ContactSolver`],
//!   [`Integrator`]).
//! - Reading the results: each [`Body`] by its [`BodyHandle`], each [`Joint`] by its
//!   [`JointHandle`], the last step's [`Contact`]s and [`Manifold`]s, and how each island
//!   was solved ([`IslandReport`]); what the steps so far did, counted ([`StepStats`]).
//! - Geometry: [`Vec2`] (nalgebra's), [`Aabb`], [`convex_hull`], and the separating-axis
//!   test the step finds contacts by, on polygons placed in the world ([`collide_polygons`]
//!   on [`WorldPolygon`]s), by which the benchmark judges every engine's overlaps.
//! - Profiling: the cycles each [`Stage`] of a world's last step took
//!   ([`World::profile`], a [`StepProfile`], turned into time by
//!   [`ticks_per_microsecond`]; counted with the feature `stage-clock` only) and the SIMD
//!   path the soft step takes ([`lane_path_name`]).

mod body;
mod collide;
pub mod limits;
mod math;
mod shape;
mod solver;
mod stage_clock;
mod world;

pub use crate::{
    body::{Body, BodyDef, BodyError, BodyHandle},
    collide::{Aabb, ContactPoint, FeatureId, Manifold, WorldPolygon, sat::collide_polygons},
    math::Vec2,
    shape::{ConvexPolygon, MassProperties, ShapeError, convex_hull},
    solver::{
        ContactSolver,
        contact::Contact,
        joint::{Joint, JointHandle, JointLimits, JointMotor, JointSpring},
        motor::{BodyMotor, MotorError},
        report::{IslandMethod, IslandReport, StepStats},
        soft::lane_path_name,
    },
    stage_clock::{Stage, StepProfile, ticks_per_microsecond},
    world::{
        FALL_PER_STEP, JointDef, JointError, StepError, World,
        settings::{Integrator, StepSettings},
    },
};
