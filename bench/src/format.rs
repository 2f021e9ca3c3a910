//! How the bench writes its figures: durations, ratios and ranges of ratios.

use std::time::Duration;

/// A duration with three significant figures in a readable unit.
pub fn pretty(d: Duration) -> String {
    let s = d.as_secs_f64();
    let (value, unit) = match s {
        s if s < 1e-3 => (s * 1e6, "µs"),
        s if s < 1.0 => (s * 1e3, "ms"),
        s => (s, "s"),
    };
    match value {
        v if v < 10.0 => format!("{v:.2} {unit}"),
        v if v < 100.0 => format!("{v:.1} {unit}"),
        v => format!("{v:.0} {unit}"),
    }
}

/// pe's time over a peer's.
pub fn time_ratio(pe: Duration, peer: Duration) -> f64 {
    pe.as_secs_f64() / peer.as_secs_f64()
}

/// The smallest and largest of some ratios, as "lo–hi".
pub fn ratio_range(ratios: impl Iterator<Item = f64>) -> String {
    let (lo, hi) = ratios.fold((f64::INFINITY, 0.0_f64), |(lo, hi), r| {
        (lo.min(r), hi.max(r))
    });
    format!("{lo:.2}–{hi:.2}")
}
