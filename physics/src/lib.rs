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

pub mod body;
pub mod collide;
pub mod limits;
pub mod math;
pub mod shape;
pub mod solver;
pub mod stage_clock;
pub mod world;

pub use body::{Body, BodyDef, BodyError, BodyHandle};
pub use collide::{ContactPoint, FeatureId, Manifold};
pub use math::{Rot, Vec2};
pub use shape::{ConvexPolygon, MassProperties, ShapeError, convex_hull};
pub use solver::ContactSolver;
pub use solver::contact::Contact;
pub use solver::joint::{Joint, JointHandle, JointMotor};
pub use solver::motor::{BodyMotor, MotorError};
pub use world::{FALL_PER_STEP, Integrator, JointDef, JointError, StepError, StepSettings, World};
