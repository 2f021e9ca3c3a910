//! Time of impact (issue 9): how far along its step a moving polygon may go before it
//! touches a static one, by conservative advancement on the SAT separation.

use super::WorldPolygon;
use super::sat::max_separation;
use crate::math::{Rot, Vec2};

/// The SAT separation of two convex polygons: the largest gap along any edge normal of
/// either. It is positive exactly when they are apart, and never more than their distance
/// (a projection does not lengthen), so advancing by it cannot step past a contact.
pub(crate) fn separation(p: &WorldPolygon, q: &WorldPolygon) -> f64 {
    max_separation(p, q).1.max(max_separation(q, p).1)
}

/// A body's straight-line motion over one step: centroid and angle at the start and end.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Sweep {
    pub start: (Vec2, f64),
    pub end: (Vec2, f64),
}

impl Sweep {
    pub(crate) fn at(&self, t: f64) -> (Vec2, f64) {
        (
            self.start.0 + (self.end.0 - self.start.0) * t,
            self.start.1 + (self.end.1 - self.start.1) * t,
        )
    }

    /// An upper bound on how fast (per unit of t) any point within `radius` of the
    /// centroid moves: translation plus rotation at the rim.
    fn speed_bound(&self, radius: f64) -> f64 {
        (self.end.0 - self.start.0).norm() + (self.end.1 - self.start.1).abs() * radius
    }
}

/// Places `local` (vertices about the centroid) at `pose`.
pub(crate) fn place(polygon: &mut WorldPolygon, local: &[Vec2], (centre, angle): (Vec2, f64)) {
    let rot = Rot::new(angle);
    polygon.set_vertices(local.iter().map(|v| centre + rot.apply(*v)));
}

/// The first t in (0, 1] at which the swept polygon comes within `target` of `obstacle`
/// (to within `tolerance`), or `None` if it does not, or if it already is at t = 0 (then
/// the two are in contact and the contact solver owns them). `radius` bounds the
/// polygon's vertices about its centroid; `scratch` is a buffer.
pub(crate) fn time_of_impact(
    local: &[Vec2],
    radius: f64,
    sweep: &Sweep,
    obstacle: &WorldPolygon,
    target: f64,
    tolerance: f64,
    scratch: &mut WorldPolygon,
) -> Option<f64> {
    const MAX_ITERATIONS: usize = 50;
    let speed = sweep.speed_bound(radius);
    if speed <= 0.0 {
        return None;
    }
    let mut t = 0.0;
    for iteration in 0..MAX_ITERATIONS {
        place(scratch, local, sweep.at(t));
        let gap = separation(scratch, obstacle);
        if gap <= target + tolerance {
            return (iteration > 0).then_some(t);
        }
        t += (gap - target) / speed;
        if t >= 1.0 {
            return None;
        }
    }
    // Still apart after the cap (a vertex sliding past a vertex, where the SAT bound is
    // weakest): stop where the advancement got, which is still short of the contact.
    Some(t)
}

/// For a polygon that starts the sweep in contact with `obstacle` (no deeper than `depth`)
/// and ends deeper: the last t, found by bisection to within `tolerance` of motion, at
/// which it is still no deeper than `depth`. This is where a contact solver that failed
/// to hold it (a body dragged into a wall by something else) should have left it.
/// `None` if it starts deeper than `depth`, or does not end deeper.
pub(crate) fn time_of_sinking(
    local: &[Vec2],
    radius: f64,
    sweep: &Sweep,
    obstacle: &WorldPolygon,
    depth: f64,
    tolerance: f64,
    scratch: &mut WorldPolygon,
) -> Option<f64> {
    let mut gap_at = |t: f64| {
        place(scratch, local, sweep.at(t));
        separation(scratch, obstacle)
    };
    if gap_at(0.0) < -depth || gap_at(1.0) >= -depth {
        return None;
    }
    let speed = sweep.speed_bound(radius);
    let (mut shallow, mut deep) = (0.0, 1.0);
    while (deep - shallow) * speed > tolerance {
        let t = 0.5 * (shallow + deep);
        if gap_at(t) >= -depth {
            shallow = t;
        } else {
            deep = t;
        }
    }
    Some(shallow)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(centre: Vec2, half: f64) -> WorldPolygon {
        let local = [
            Vec2::new(-half, -half),
            Vec2::new(half, -half),
            Vec2::new(half, half),
            Vec2::new(-half, half),
        ];
        let mut p = WorldPolygon::default();
        place(&mut p, &local, (centre, 0.0));
        p
    }

    #[test]
    fn a_box_flying_at_a_wall_stops_at_the_target_gap() {
        // A unit box (half 0.5) from x = −10 to x = +10 through a wall 0.02 thick at x = 0:
        // its right face meets the wall's left face (x = −0.01) when the centre is at
        // −0.51, i.e. t = (10 − 0.51) / 20; with a target gap of 0.005, at −0.515.
        let wall = {
            let local = [
                Vec2::new(-0.01, -5.0),
                Vec2::new(0.01, -5.0),
                Vec2::new(0.01, 5.0),
                Vec2::new(-0.01, 5.0),
            ];
            let mut p = WorldPolygon::default();
            place(&mut p, &local, (Vec2::zeros(), 0.0));
            p
        };
        let local = square(Vec2::zeros(), 0.5).vertices;
        let sweep = Sweep {
            start: (Vec2::new(-10.0, 0.0), 0.0),
            end: (Vec2::new(10.0, 0.0), 0.0),
        };
        let mut scratch = WorldPolygon::default();
        let t = time_of_impact(&local, 0.75, &sweep, &wall, 0.005, 1e-6, &mut scratch)
            .expect("it hits");
        let x = sweep.at(t).0.x;
        assert!((x - -0.515).abs() < 2e-6, "stopped at x = {x}");
    }

    #[test]
    fn no_impact_when_the_sweep_stays_clear_or_starts_touching() {
        let wall = square(Vec2::new(0.0, 0.0), 1.0);
        let local = square(Vec2::zeros(), 0.5).vertices;
        let mut scratch = WorldPolygon::default();
        let clear = Sweep {
            start: (Vec2::new(-5.0, 3.0), 0.0),
            end: (Vec2::new(5.0, 3.0), 0.0),
        };
        assert_eq!(
            time_of_impact(&local, 0.75, &clear, &wall, 0.005, 1e-6, &mut scratch),
            None
        );
        // Resting on top of it and sliding along: the contact solver's business.
        let sliding = Sweep {
            start: (Vec2::new(-0.5, -1.5), 0.0),
            end: (Vec2::new(0.5, -1.5), 0.0),
        };
        assert_eq!(
            time_of_impact(&local, 0.75, &sliding, &wall, 0.005, 1e-6, &mut scratch),
            None
        );
    }

    #[test]
    fn a_box_pushed_into_a_wall_from_contact_stops_at_the_allowed_depth() {
        // The unit box touches the wall (right face at x = −0.01) and is pushed 0.3 into
        // it: allowed 0.002 deep, it stops with its centre at −0.508.
        let wall = square(Vec2::zeros(), 0.01);
        let local = square(Vec2::zeros(), 0.5).vertices;
        let sweep = Sweep {
            start: (Vec2::new(-0.51, 0.0), 0.0),
            end: (Vec2::new(-0.21, 0.0), 0.0),
        };
        let mut scratch = WorldPolygon::default();
        let t = time_of_sinking(&local, 0.75, &sweep, &wall, 0.002, 1e-9, &mut scratch)
            .expect("it sinks");
        let x = sweep.at(t).0.x;
        assert!((x - -0.508).abs() < 1e-9, "stopped at x = {x}");
        // Deeper than allowed at the start, or not deeper at the end: not its business.
        let from_deep = Sweep {
            start: (Vec2::new(-0.4, 0.0), 0.0),
            end: (Vec2::new(-0.3, 0.0), 0.0),
        };
        let leaving = Sweep {
            start: (Vec2::new(-0.51, 0.0), 0.0),
            end: (Vec2::new(-0.9, 0.0), 0.0),
        };
        for sweep in [from_deep, leaving] {
            let t = time_of_sinking(&local, 0.75, &sweep, &wall, 0.002, 1e-9, &mut scratch);
            assert_eq!(t, None);
        }
    }
}
