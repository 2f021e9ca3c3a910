//! The soft step's tuning (`SoftSettings`, after Box2D v3, scaled by the world's length
//! scale), its soft constraints' spring–damper scaling (`Softness`) and each contact
//! pass's settings made from them.

use super::batch::PassSettings;

/// Tuning of the soft step; defaults after Box2D v3, scaled by the world's length scale.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SoftSettings {
    pub substeps: usize,
    /// Contact stiffness (Hz), capped at a quarter of the substep rate for stability;
    /// twice as stiff against a fixed body (as Box2D v3), which holds a pile up from
    /// below: a jammed pile creeps twenty times less (docs/bench/profile.md).
    pub contact_hertz: f64,
    pub contact_damping_ratio: f64,
    pub joint_hertz: f64,
    pub joint_damping_ratio: f64,
    /// The fastest a soft contact pushes overlapping bodies apart (length units / s).
    pub max_push_speed: f64,
    /// The deepest a soft contact lets its bodies sink in one substep's biased pass
    /// (length units): see `sinking_floor`.
    pub max_soft_depth: f64,
    /// The fastest a soft pin pulls its anchors together (length units / s).
    pub joint_push_speed: f64,
    /// Whether every other pair of substeps sweeps the colours backwards (`SweepOrder`).
    pub alternating_sweeps: bool,
}

impl SoftSettings {
    pub(crate) fn for_length_scale(length_scale: f64) -> Self {
        Self {
            substeps: 4,
            contact_hertz: 30.0,
            contact_damping_ratio: 10.0,
            joint_hertz: 60.0,
            joint_damping_ratio: 2.0,
            max_push_speed: 3.0 * length_scale,
            max_soft_depth: 0.1 * length_scale,
            // Far faster than contacts: a loaded net of pins capped at the contacts'
            // push speed opens wide (docs/bench/profile.md).
            joint_push_speed: 100.0 * length_scale,
            alternating_sweeps: true,
        }
    }
}

/// Mass and impulse scaling of a soft constraint (Box2D's b2Softness): a spring–damper of
/// the given frequency and damping ratio, made implicit over the substep.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(super) struct Softness {
    pub(super) bias_rate: f64,
    pub(super) mass_scale: f64,
    pub(super) impulse_scale: f64,
}

impl Softness {
    pub(super) fn new(hertz: f64, zeta: f64, h: f64) -> Self {
        if hertz == 0.0 {
            return Self {
                bias_rate: 0.0,
                mass_scale: 1.0,
                impulse_scale: 0.0,
            };
        }
        let omega = std::f64::consts::TAU * hertz;
        let a1 = 2.0 * zeta + h * omega;
        let a2 = h * omega * a1;
        let a3 = 1.0 / (1.0 + a2);
        Self {
            bias_rate: omega / a1,
            mass_scale: a2 * a3,
            impulse_scale: a3,
        }
    }
}

/// The most a body may turn in one substep (radians).
pub(super) const MAX_TURN_PER_SUBSTEP: f64 = 0.25 * std::f64::consts::PI;

/// Soft constraints are capped at a quarter of the substep rate for stability.
pub(super) const MAX_HERTZ_PER_SUBSTEP_RATE: f64 = 0.25;

/// A contact pass's settings for substeps of `h`.
pub(super) fn contact_pass(
    h: f64,
    soft: &Softness,
    settings: &SoftSettings,
    use_bias: bool,
) -> PassSettings {
    PassSettings {
        inv_h: 1.0 / h,
        soft: *soft,
        static_soft: Softness::new(
            (2.0 * settings.contact_hertz).min(MAX_HERTZ_PER_SUBSTEP_RATE / h),
            settings.contact_damping_ratio,
            h,
        ),
        max_push: settings.max_push_speed,
        max_depth: settings.max_soft_depth,
        use_bias,
    }
}
