//! The largest magnitude each kind of number may have in a world. They are far beyond
//! anything a robot or a benchmark needs (issue 9's extreme-but-legal input: coordinates
//! of 1e6, density ratios of 1e6, torques of 1e12) and far below where a step overflows:
//! a finite gravitation of 1e308 or motor torque of 1e300 turns the first step to
//! infinity, so finiteness alone is not enough. Bodies, joints, motors and
//! steps beyond them are refused with an error naming the number.

/// Positions, anchors and polygon vertices (length units).
pub const COORDINATE: f64 = 1e9;
/// Body angles (radians).
pub const ANGLE: f64 = 1e6;
/// Mass per unit area.
pub const DENSITY: f64 = 1e12;
/// Friction coefficients, of bodies and of the world: μ times an impulse must not overflow.
pub const FRICTION: f64 = 1e6;
/// Each component of gravity (length units / s²).
pub const GRAVITY: f64 = 1e9;
/// Motor torques.
pub const TORQUE: f64 = 1e15;
/// The force and the torque a body is given by hand (`Body::force`, `Body::torque`): far
/// above what a mouse spring puts on the heaviest legal body (a density of 1e12 over
/// 1e4 square units, pulled 100 units at 10 rad/s: 1e20), far below where a step
/// overflows.
pub const FORCE: f64 = 1e30;
/// Body velocities (length units / s).
pub const SPEED: f64 = 1e9;
/// Body spins and joint motor speeds (radians / s): a body motor's fastest speed per step
/// ([`ANGULAR`]) at a step of 1e-4 s.
pub const SPIN: f64 = 1e10;
/// A motor's speed, radians per step (thesis §4.4): half a turn. Faster, a step could not
/// show the turn (it would look like turning the other way) and no solver could follow it:
/// a pin driven so fast tears open in one step.
pub const ANGULAR: f64 = std::f64::consts::PI;
/// A body motor's torque ramp, fraction of its start torque per step.
pub const INCREASE: f64 = 1e6;

/// `Some((what, value, limit))` for the first `(what, value, limit)` whose value is beyond
/// its limit in magnitude (NaN counts as beyond).
pub(crate) fn first_beyond(
    numbers: impl IntoIterator<Item = (&'static str, f64, f64)>,
) -> Option<(&'static str, f64, f64)> {
    numbers
        .into_iter()
        .find(|&(_, value, limit)| value.is_nan() || value.abs() > limit)
}
