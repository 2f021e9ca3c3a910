//! RoboSim: design 2D robots from rigid convex polygons and watch them move.
//!
//! `model` and `db` hold the three-file XML database, `sim` turns a scene into a running
//! `pe::World`, `app` is the editor. Dependencies point one way: app → sim → pe.
//! The editor is the default feature `app`; without it the crate builds headless.

pub use pe;

pub mod animation;
#[cfg(feature = "app")]
pub mod app;
pub mod cli;
pub mod db;
pub mod model;
pub mod paths;
pub mod sim;
