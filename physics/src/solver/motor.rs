//! The thesis's body motor (thesis §4.4): a torque couple on one body that ramps up while the
//! body turns slower than its target and switches off when it gets there (bang-bang).

/// Why a motor cannot be added.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MotorError {
    #[error("the motor's body does not exist")]
    MissingBody,
    #[error("motor {0} must be a finite number, got {1}")]
    NonFinite(&'static str, f64),
    #[error("motor {0} must not be negative, got {1}")]
    Negative(&'static str, f64),
    /// A number beyond its limit in `crate::limits`: what, value, limit.
    #[error("motor {0} {1:e} is beyond ±{2:e}")]
    Beyond(&'static str, f64, f64),
}

/// A body motor with the XML `<force>` fields. Times count steps; `angular` is radians per
/// step and its sign gives the direction (thesis §4.4 Rec).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyMotor {
    pub time0: u64,
    pub time1: u64,
    pub angular: f64,
    pub start_torque: f64,
    pub max_torque: f64,
    /// Fraction of the start torque added per step while below target.
    pub increase: f64,
    /// The torque magnitude of the current ramp (0 when off).
    pub current: f64,
}

impl BodyMotor {
    pub fn new(
        time0: u64,
        time1: u64,
        angular: f64,
        start_torque: f64,
        max_torque: f64,
        increase: f64,
    ) -> Self {
        Self {
            time0,
            time1,
            angular,
            start_torque,
            max_torque,
            increase,
            current: 0.0,
        }
    }

    /// Refuses what would put a non-finite torque into the world: every number must be
    /// finite and the torques and their increase non-negative.
    pub(crate) fn validate(&self) -> Result<(), MotorError> {
        let fields = [
            ("angular", self.angular),
            ("start torque", self.start_torque),
            ("max torque", self.max_torque),
            ("increase", self.increase),
        ];
        for (name, value) in fields {
            if !value.is_finite() {
                return Err(MotorError::NonFinite(name, value));
            }
        }
        for (name, value) in &fields[1..] {
            if *value < 0.0 {
                return Err(MotorError::Negative(name, *value));
            }
        }
        let limits = [
            crate::limits::ANGULAR,
            crate::limits::TORQUE,
            crate::limits::TORQUE,
            crate::limits::INCREASE,
        ];
        let numbers = fields.iter().zip(limits).map(|(&(n, v), l)| (n, v, l));
        if let Some((what, value, limit)) = crate::limits::first_beyond(numbers) {
            return Err(MotorError::Beyond(what, value, limit));
        }
        Ok(())
    }

    /// Whether step `step` lies in the motor's window `time0 ≤ t < time1`.
    pub(crate) fn is_on(&self, step: u64) -> bool {
        (self.time0..self.time1).contains(&step)
    }

    /// The signed torque for step `step` given the body's angular velocity `omega` (rad/s)
    /// and the step `dt`, advancing the ramp.
    pub(crate) fn torque(&mut self, step: u64, omega: f64, dt: f64) -> f64 {
        if !self.is_on(step) {
            self.current = 0.0;
            return 0.0;
        }
        let direction = if self.angular < 0.0 { -1.0 } else { 1.0 };
        if direction * omega * dt >= self.angular.abs() {
            self.current = 0.0; // at target: off for this step, restart from startTorque later
            return 0.0;
        }
        let start = self.start_torque.abs();
        self.current = if self.current == 0.0 {
            start
        } else {
            self.current + self.increase * start
        };
        self.current = self.current.min(self.max_torque.abs());
        direction * self.current
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ramps_from_start_torque_to_the_cap() {
        let mut m = BodyMotor::new(0, 1000, 0.3, 1e6, 2e6, 0.25);
        let torques: Vec<f64> = (0..6).map(|t| m.torque(t, 0.0, 0.05)).collect();
        assert_eq!(torques, vec![1e6, 1.25e6, 1.5e6, 1.75e6, 2e6, 2e6]);
    }

    #[test]
    fn switches_off_at_target_and_restarts_from_start() {
        let mut m = BodyMotor::new(0, 1000, 0.3, 1e6, 2e6, 0.5);
        m.torque(0, 0.0, 0.05);
        m.torque(1, 0.0, 0.05);
        // 0.3 rad/step at h = 0.05 s is 6 rad/s.
        assert_eq!(m.torque(2, 6.0, 0.05), 0.0);
        assert_eq!(m.torque(3, 5.9, 0.05), 1e6);
    }

    #[test]
    fn negative_angular_drives_backwards_and_window_is_half_open() {
        let mut m = BodyMotor::new(10, 20, -0.3, 1e6, 2e6, 0.0);
        assert_eq!(m.torque(9, 0.0, 0.05), 0.0);
        assert_eq!(m.torque(10, 0.0, 0.05), -1e6);
        assert_eq!(m.torque(19, -5.0, 0.05), -1e6);
        assert_eq!(m.torque(20, 0.0, 0.05), 0.0);
    }
}
